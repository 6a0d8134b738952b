"""Writing output files atomically: a partial file never replaces a good one."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from ..errors import ModelError


def check_output_path(path: str | Path, field: str, *, inputs: tuple[Path, ...] = ()) -> Path:
    """The path of an output file, checked before any work is done: not a directory, not
    under a file, in a directory that exists (or can be created) and is writable, not a
    read-only file, and never one of ``inputs`` (the user's model)."""
    path = Path(path)
    if path.is_dir():
        raise ModelError(f"cannot write {path}: it is a directory", field=field)
    for guarded in inputs:
        if path.exists() and guarded.exists() and path.resolve() == guarded.resolve():
            raise ModelError(f"{path}: refusing to overwrite the input model file", field=field)
    folder = Path(os.path.abspath(path)).parent
    existing = folder
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if not existing.is_dir():
        raise ModelError(f"cannot write {path}: {existing} is a file, not a directory",
                         field=field)
    if not os.access(existing, os.W_OK | os.X_OK):
        where = f"the directory {existing}" if existing == folder else \
            f"{folder} cannot be created: {existing}"
        raise ModelError(f"cannot write {path}: {where} is not writable", field=field)
    if path.exists() and not os.access(path, os.W_OK):
        raise ModelError(f"cannot write {path}: the file is read-only", field=field)
    return path


def partial_path(path: str | Path) -> Path:
    """Where a partial result goes: beside an existing file (run.partial.csv), never over it."""
    path = Path(path)
    return path.with_name(f"{path.stem}.partial{path.suffix}") if path.exists() else path


def atomic_write(path: str | Path, data: bytes | str, *, protect: tuple[Path, ...] = ()) -> Path:
    """Write ``data`` to ``path`` through a temporary file and a rename.

    ``protect`` lists input files that must never be overwritten (the user's model, say).
    """
    path = Path(path)
    for guarded in protect:
        if path.exists() and guarded.exists() and path.resolve() == guarded.resolve():
            raise FileExistsError(f"{path}: refusing to overwrite an input file")
    payload = data.encode("utf-8") if isinstance(data, str) else data
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(payload)
        # mkstemp creates 0600; an output file gets the usual permissions (0666 less umask).
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(temporary, 0o666 & ~umask)
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.unlink(temporary)
        raise
    return path
