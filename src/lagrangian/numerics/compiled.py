"""Compile generated C into a Python extension module, cached on disk by a hash of the
equations (load_keyed) or of its source (load).

The cache lives in ``$LAGRANGIAN_CACHE``, else ``$XDG_CACHE_HOME/lagrangian``, else
``~/.cache/lagrangian``; a repeat run (any process) loads the module without generating C and
without a compiler: the key is computed from the equations before any code is generated.
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
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path
from types import ModuleType

import numpy as np

from ..errors import LagrangianError
from .codegen import GeneratedSource

CFLAGS = ("-O2", "-fPIC", "-shared", "-fno-math-errno", "-w")
# Opt-in for kernels that vectorize over a batch (numerics/recursive.py): the processor's own
# vector width (AVX2 + FMA: four states per operation instead of SSE2's two) halves their time.
# Such a module only runs on this kind of processor, so its name carries a CPU fingerprint.
NATIVE_CFLAGS = ("-O3", "-march=native")

_LOADED: dict[str, ModuleType] = {}


class BackendUnavailable(LagrangianError):
    """The compiled (C) backend cannot be used here: no compiler, no headers, or a failed build."""


class CompilerMissing(BackendUnavailable):
    """No C compiler to build with: none on PATH, or $CC names a program that is not there."""


def cache_dir() -> Path:
    """Where compiled modules are kept (created on first use)."""
    if os.environ.get("LAGRANGIAN_CACHE"):
        return Path(os.environ["LAGRANGIAN_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "lagrangian"


def find_compiler() -> list[str] | None:
    """The C compiler command ($CC, Python's own CC, or cc/gcc/clang on PATH), or None.
    A $CC that names no program is None too (never silently another compiler)."""
    if os.environ.get("CC", "").strip():
        words = shlex.split(os.environ["CC"])
        found = shutil.which(words[0]) if words else None
        return [found, *words[1:]] if found else None
    candidates = [sysconfig.get_config_var("CC"), "cc", "gcc", "clang"]
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


@lru_cache(maxsize=1)
def cpu_fingerprint() -> str:
    """What a -march=native build depends on: the processor's model and instruction sets."""
    import platform

    lines = []
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as info:
            for line in info:
                key = line.split(":", 1)[0].strip()
                if key in ("vendor_id", "model name", "flags", "Features", "CPU part") \
                        and line not in lines:
                    lines.append(line)
                if not line.strip() and lines:  # the first processor describes them all
                    break
    except OSError:
        pass
    lines += [platform.machine(), platform.processor()]
    return hashlib.sha256("".join(lines).encode()).hexdigest()[:16]


def module_name(generated: GeneratedSource) -> str:
    """lg_<hash of the source, compiler flags, Python and numpy versions>."""
    digest = hashlib.sha256((_platform_key() + "\n" + generated.source).encode()).hexdigest()
    return f"lg_{digest[:24]}"


def _run_compiler(command: list[str]) -> subprocess.CompletedProcess:
    return subprocess.run(command, capture_output=True, text=True, timeout=600)


def check_compiler() -> list[str]:
    """The compiler command, or CompilerMissing saying why there is none."""
    compiler = find_compiler()
    if compiler is not None:
        return compiler
    cc = os.environ.get("CC", "").strip()
    if cc:
        raise CompilerMissing(f"CC={cc!r} names no program on PATH (unset CC, or point it at gcc "
                              "or clang)")
    raise CompilerMissing("no C compiler found (set CC, or install gcc or clang)")


def _compile(source: str, name: str, target: Path, native: bool = False) -> None:
    """Build ``target``; with ``native`` the processor's own instructions, falling back to the
    portable flags where the compiler refuses them (e.g. no -march=native for the target)."""
    if native:
        try:
            return _compile_with(source, name, target, (*CFLAGS, *NATIVE_CFLAGS))
        except BackendUnavailable:
            pass
    _compile_with(source, name, target, CFLAGS)


def _compile_with(source: str, name: str, target: Path, flags: tuple[str, ...]) -> None:
    compiler = check_compiler()
    includes = [f"-I{d}" for d in _include_dirs()]
    extra = ["-undefined", "dynamic_lookup"] if sys.platform == "darwin" else []
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=target.parent, prefix=".build-") as tmp:
        c_file = Path(tmp) / f"{name}.c"
        c_file.write_text(f"#define LG_MODULE {name}\n{source}")
        built = Path(tmp) / target.name
        command = [*compiler, *flags, *includes, str(c_file), "-o", str(built), "-lm", *extra]
        try:
            done = _run_compiler(command)
        except (OSError, subprocess.SubprocessError) as exc:
            raise BackendUnavailable(f"the C compiler could not run: {exc}") from None
        if done.returncode != 0:
            cc = os.environ.get("CC", "").strip()
            who = f"the C compiler CC={cc!r}" if cc else f"the C compiler {compiler[0]}"
            raise BackendUnavailable(f"compiling the generated C failed ({who}):\n"
                                     + (done.stderr or done.stdout or "no output")[-2000:])
        shutil.copyfile(c_file, target.with_suffix(".c"))  # kept for inspection
        os.replace(built, target)  # atomic: a concurrent process sees all or nothing


def load(generated: GeneratedSource) -> ModuleType:
    """The compiled module for this source: in memory, else from the cache, else built now."""
    return _load_or_build(module_name(generated), lambda: generated)


@lru_cache(maxsize=1)
def _generator_key() -> str:
    """The code generator itself (codegen.py, template.c): a new generator is a new module."""
    here = Path(__file__).parent
    return hashlib.sha256(b"".join((here / f).read_bytes() for f in ("codegen.py", "template.c"))
                          ).hexdigest()


def keyed_module_name(key: str, native: bool = False) -> str:
    """lg_<hash of the equations' key, the generator, compiler flags, Python and numpy (and,
    for a native build, the processor)>."""
    parts = [_platform_key(), _generator_key(), key]
    if native:
        parts += [" ".join(NATIVE_CFLAGS), cpu_fingerprint()]
    text = "\n".join(parts)
    return f"lg_{hashlib.sha256(text.encode()).hexdigest()[:24]}"


def load_keyed(key: str, make_source: Callable[[], GeneratedSource],
               native: bool = False) -> ModuleType:
    """The compiled module for the equations with this key: in memory, else from the on-disk
    cache (no C generated, no compiler needed), else ``make_source()`` generated and built now;
    ``native``: for this processor's instruction set (NATIVE_CFLAGS)."""
    return _load_or_build(keyed_module_name(key, native), make_source, native)


def _load_or_build(name: str, make_source: Callable[[], GeneratedSource],
                   native: bool = False) -> ModuleType:
    """The module ``name``: in memory, else the cached file, else built from ``make_source()``
    (called only then, after the compiler is found: without one the C would be wasted)."""
    if name in _LOADED:
        return _LOADED[name]
    suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
    path = cache_dir() / f"{name}{suffix}"
    if path.exists():
        try:
            module = _import(name, path)
        except ImportError:  # a stale or foreign file: built again below
            path.unlink(missing_ok=True)
        else:
            _LOADED[name] = module
            return module
    if sys.platform == "win32":
        raise BackendUnavailable("the C backend is not supported on Windows yet")
    check_compiler()
    _include_dirs()
    generated = make_source()
    try:
        _compile(generated.source, name, path, native)
    except OSError as exc:
        raise BackendUnavailable(f"cannot write the compiled-module cache {path.parent}: "
                                 f"{exc.strerror or exc} (set LAGRANGIAN_CACHE)") from None
    try:
        module = _import(name, path)
    except ImportError as exc:
        raise BackendUnavailable(f"cannot load the compiled module {path}: {exc}") from None
    _LOADED[name] = module
    return module


def _import(name: str, path: Path) -> ModuleType:
    """Import the extension module at ``path`` (ImportError if it is not one for this Python)."""
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot load {path}")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
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
