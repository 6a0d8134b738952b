"""A study's finished chunks kept on disk beside its output (``<out>.partial``): a fingerprint
of the study, one .npz file per chunk with a digest of its identity and numbers, checked before
anything is merged; only files the store made are ever removed."""

from __future__ import annotations

import hashlib
import io
import json
import os
import re
import tempfile
from pathlib import Path

import numpy as np

from ..analysis.study import Study, layout
from ..errors import ModelError


class PartialStore:
    """Per-chunk .npz files and the study's key in a directory: what finished, kept on disk.

    Nothing is trusted: the directory is used only when its manifest names this study, each
    chunk carries a digest of the study's key, its index and its own numbers (checked before it
    is merged), and only files this store made are ever removed."""

    MANIFEST = "study.json"

    def __init__(self, directory: Path, study: Study):
        self.directory = Path(directory)
        self.study = study

    def open(self, resume: bool) -> set[int]:
        """The chunk starts already done (resume), after checking they belong to this study;
        without ``resume`` an earlier store of this project's is cleared, anything else refused."""
        if self.directory.is_symlink() or (self.directory.exists()
                                           and not self.directory.is_dir()):
            raise ModelError(f"{self.directory} is in the way of the study's partial results "
                             "and is not a store of lagrangian's: refusing to touch it",
                             field="resume" if resume else "out")
        if resume:
            if not self.directory.exists():
                raise ModelError(f"nothing to resume: {self.directory} does not exist (run "
                                 "without resume)", field="resume")
            stored = self._manifest()
            if stored is None:
                raise ModelError(f"{self.directory} cannot be resumed: its {self.MANIFEST} is "
                                 "missing or unreadable (nothing was deleted; move it away to "
                                 "start again)", field="resume")
            if stored.get("key") != self.study.key:
                raise ModelError(f"{self.directory} holds a different study (other model, grid or "
                                 f"options); run without resume to start again", field="resume")
            return self._verified_chunks()
        if self.directory.exists():
            if self._manifest() is None or self._foreign_files():
                raise ModelError(f"{self.directory} exists and is not a store of lagrangian's "
                                 "partial results: refusing to replace it (move it away)",
                                 field="out")
            self.remove()
        self.directory.mkdir(parents=True)
        self._write_bytes(self.MANIFEST, json.dumps(
            {"key": self.study.key, "compute": self.study.compute,
             "points": self.study.size}).encode())
        return set()

    def _manifest(self) -> dict | None:
        path = self.directory / self.MANIFEST
        try:
            if path.is_symlink() or path.stat().st_size > 2**20:
                return None
            stored = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None
        return stored if isinstance(stored, dict) and isinstance(stored.get("key"), str) \
            else None

    def _ours(self, name: str) -> bool:
        return name == self.MANIFEST or bool(_CHUNK_FILE.fullmatch(name)) \
            or bool(_CHUNK_TEMPORARY.fullmatch(name))

    def _foreign_files(self) -> list[str]:
        return [p.name for p in self.directory.iterdir()
                if not self._ours(p.name) or p.is_symlink() or not p.is_file()]

    def _verified_chunks(self) -> set[int]:
        starts = {a: b for a, b in self.study.chunks}
        done = set()
        for path in sorted(self.directory.iterdir()):
            match = _CHUNK_FILE.fullmatch(path.name)
            if match is None:
                continue
            start = int(match.group(1))
            fault = None
            if start not in starts:
                fault = "its index is not a chunk of this study"
            else:
                try:
                    fault = self._check(start, starts[start], self._read_raw(start))
                except Exception:  # noqa: BLE001 - truncated, not an npz, pickled objects...
                    fault = "it cannot be read (truncated or not a chunk file)"
            if fault:
                raise ModelError(f"{path}: {fault}; nothing was merged or deleted (remove this "
                                 "file to compute its points again)", field="resume")
            done.add(start)
        return done

    def _check(self, start: int, stop: int, arrays: dict[str, np.ndarray]) -> str | None:
        digest = arrays.pop(_IDENTITY, None)
        if digest is None or str(digest) != chunk_identity(self.study.key, start, arrays):
            return "it does not belong to this study or was changed after it was written"
        names = set(layout(self.study)) | {"status"}
        if set(arrays) != names or any(len(a) != stop - start for a in arrays.values()):
            return "its arrays are not this study's"
        return None

    def write(self, start: int, arrays: dict[str, np.ndarray]) -> None:
        saved = {k: (np.asarray(v).astype(str) if k == "status" else np.asarray(v))
                 for k, v in arrays.items()}
        saved[_IDENTITY] = np.array(chunk_identity(self.study.key, start, saved))
        buffer = io.BytesIO()
        np.savez(buffer, **saved)
        self._write_bytes(f"chunk-{start}.npz", buffer.getvalue())

    def _write_bytes(self, name: str, data: bytes) -> None:
        """Through a fresh temporary file and a rename: never through a planted link."""
        handle, temporary = tempfile.mkstemp(dir=self.directory, prefix=".chunk-", suffix=".tmp")
        try:
            with os.fdopen(handle, "wb") as stream:
                stream.write(data)
            os.replace(temporary, self.directory / name)
        except BaseException:
            Path(temporary).unlink(missing_ok=True)
            raise

    def read(self, start: int) -> dict[str, np.ndarray]:
        """A chunk's arrays (checked by open(resume=True) before any is read)."""
        arrays = self._read_raw(start)
        arrays.pop(_IDENTITY, None)
        return arrays

    def _read_raw(self, start: int) -> dict[str, np.ndarray]:
        path = self.directory / f"chunk-{start}.npz"
        if path.is_symlink():
            raise OSError(f"{path} is a symbolic link")
        with np.load(path, allow_pickle=False) as data:
            return {k: data[k] for k in data.files}

    def remove(self) -> None:
        """Remove the files this store made, then the directory if nothing else is in it."""
        for path in self.directory.iterdir():
            if self._ours(path.name) and (path.is_file() or path.is_symlink()):
                path.unlink()
        try:
            self.directory.rmdir()
        except OSError:  # something that is not ours is in there: left alone
            pass


_IDENTITY = "__chunk_identity__"
_CHUNK_FILE = re.compile(r"chunk-(\d{1,12})\.npz")
_CHUNK_TEMPORARY = re.compile(r"\.chunk-\w+\.tmp")


def chunk_identity(key: str, start: int, arrays: dict[str, np.ndarray]) -> str:
    """SHA-256 of the study's key, the chunk's index and its numbers: a chunk of another study,
    of another index, or edited after it was written does not match."""
    digest = hashlib.sha256(f"{key}\n{start}\n".encode())
    for name in sorted(arrays):
        if name == _IDENTITY:
            continue
        array = np.asarray(arrays[name])
        array = array.astype(str) if array.dtype.kind in "OUS" else np.ascontiguousarray(array)
        digest.update(f"{name}|{array.dtype.str}|{array.shape}\n".encode())
        digest.update(array.tobytes())
    return digest.hexdigest()
