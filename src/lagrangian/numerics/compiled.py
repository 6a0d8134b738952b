"""Compile generated C into a Python extension module, cached on disk by a hash of its source.

The cache lives in ``$LAGRANGIAN_CACHE``, else ``$XDG_CACHE_HOME/lagrangian``, else
``~/.cache/lagrangian``; a repeat run (any process) loads the module without compiling.
Extension modules (not ctypes) because a ctypes call costs microseconds, METH_FASTCALL ~0.1 us.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import shlex
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from functools import lru_cache
from pathlib import Path
from types import ModuleType

import numpy as np

from ..errors import LagrangianError
from .codegen import GeneratedSource

CFLAGS = ("-O2", "-fPIC", "-shared", "-fno-math-errno", "-w")

_LOADED: dict[str, ModuleType] = {}


class BackendUnavailable(LagrangianError):
    """The compiled (C) backend cannot be used here: no compiler, no headers, or a failed build."""


def cache_dir() -> Path:
    """Where compiled modules are kept (created on first use)."""
    if os.environ.get("LAGRANGIAN_CACHE"):
        return Path(os.environ["LAGRANGIAN_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "lagrangian"


def find_compiler() -> list[str] | None:
    """The C compiler command ($CC, Python's own CC, or cc/gcc/clang on PATH), or None."""
    candidates = [os.environ.get("CC"), sysconfig.get_config_var("CC"), "cc", "gcc", "clang"]
    for candidate in candidates:
        if not candidate:
            continue
        words = shlex.split(candidate)
        if words and shutil.which(words[0]):
            return [shutil.which(words[0]), *words[1:]]
    return None


def _include_dirs() -> list[str]:
    dirs = [sysconfig.get_paths()["include"], np.get_include()]
    if not (Path(dirs[0]) / "Python.h").exists():
        raise BackendUnavailable(f"Python.h not found in {dirs[0]} (install the Python headers)")
    return dirs


@lru_cache(maxsize=1)
def _platform_key() -> str:
    return "|".join([sys.version, sysconfig.get_config_var("EXT_SUFFIX") or "", np.__version__,
                     " ".join(CFLAGS)])


def module_name(generated: GeneratedSource) -> str:
    """lg_<hash of the source, compiler flags, Python and numpy versions>."""
    digest = hashlib.sha256((_platform_key() + "\n" + generated.source).encode()).hexdigest()
    return f"lg_{digest[:24]}"


def _run_compiler(command: list[str]) -> subprocess.CompletedProcess:
    return subprocess.run(command, capture_output=True, text=True, timeout=600)


def _compile(source: str, name: str, target: Path) -> None:
    compiler = find_compiler()
    if compiler is None:
        raise BackendUnavailable("no C compiler found (set CC, or install gcc or clang)")
    includes = [f"-I{d}" for d in _include_dirs()]
    extra = ["-undefined", "dynamic_lookup"] if sys.platform == "darwin" else []
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=target.parent, prefix=".build-") as tmp:
        c_file = Path(tmp) / f"{name}.c"
        c_file.write_text(f"#define LG_MODULE {name}\n{source}")
        built = Path(tmp) / target.name
        command = [*compiler, *CFLAGS, *includes, str(c_file), "-o", str(built), "-lm", *extra]
        try:
            done = _run_compiler(command)
        except (OSError, subprocess.SubprocessError) as exc:
            raise BackendUnavailable(f"the C compiler could not run: {exc}") from None
        if done.returncode != 0:
            raise BackendUnavailable("compiling the generated C failed:\n"
                                     + (done.stderr or done.stdout)[-2000:])
        shutil.copyfile(c_file, target.with_suffix(".c"))  # kept for inspection
        os.replace(built, target)  # atomic: a concurrent process sees all or nothing


def load(generated: GeneratedSource) -> ModuleType:
    """The compiled module for this source: in memory, else from the cache, else built now."""
    name = module_name(generated)
    if name in _LOADED:
        return _LOADED[name]
    suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
    path = cache_dir() / f"{name}{suffix}"
    if not path.exists():
        if sys.platform == "win32":
            raise BackendUnavailable("the C backend is not supported on Windows yet")
        try:
            _compile(generated.source, name, path)
        except OSError as exc:
            raise BackendUnavailable(f"cannot write the compiled-module cache {path.parent}: "
                                     f"{exc.strerror or exc} (set LAGRANGIAN_CACHE)") from None
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise BackendUnavailable(f"cannot load {path}")
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
    except ImportError as exc:  # a stale or foreign file: rebuild once
        path.unlink(missing_ok=True)
        _compile(generated.source, name, path)
        module = importlib.util.module_from_spec(spec)
        try:
            spec.loader.exec_module(module)
        except ImportError:
            raise BackendUnavailable(f"cannot load the compiled module {path}: {exc}") from None
    _LOADED[name] = module
    return module


def available() -> bool:
    """Whether a C compiler and the Python headers are present (the build may still fail)."""
    if sys.platform == "win32" or find_compiler() is None:
        return False
    try:
        _include_dirs()
    except BackendUnavailable:
        return False
    return True
