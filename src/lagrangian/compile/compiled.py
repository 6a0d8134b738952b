"""Compile generated C into a Python extension module, cached on disk by a hash of the
equations (load_keyed) or of its source (load).

The cache lives in ``$LAGRANGIAN_CACHE``, else ``$XDG_CACHE_HOME/lagrangian``, else
``~/.cache/lagrangian``; a repeat run (any process) loads the module without generating C and
without a compiler: the key is computed from the equations before any code is generated.

The cache trusts nothing it finds: the directory must be the user's own and closed to others
(created 0700), every file is written atomically (temp file + rename, which never follows a link
at the destination), and a module is loaded only when its SHA-256 matches the digest written
beside it when this project built it; anything else is rebuilt with one warning line. Builds of
one module are serialized by a lock file, so two processes never race on it.
Extension modules (not ctypes) because a ctypes call costs microseconds, METH_FASTCALL ~0.1 us.
"""

from __future__ import annotations

import errno
import hashlib
import importlib.util
import json
import os
import shlex
import shutil
import stat
import subprocess
import sys
import sysconfig
import tempfile
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from ..errors import LagrangianError
from .compiler_stop import BUILD_DIRS, RUNNING, in_main_thread, kill_compiler, stop_with_caller

if TYPE_CHECKING:  # the generator (and sympy's C printer) is loaded by a module to build only
    from .codegen import GeneratedSource

CFLAGS = ("-O2", "-fPIC", "-shared", "-fno-math-errno", "-w")
# Opt-in for kernels that vectorize over a batch (dynamics/recursive.py): the processor's own
# vector width (AVX2 + FMA: four states per operation instead of SSE2's two) halves their time.
# Such a module only runs on this kind of processor, so its name carries a CPU fingerprint.
NATIVE_CFLAGS = ("-O3", "-march=native")
# no a * b + c contracted into a fused multiply-add (which GCC and Clang do by default, in
# places that differ between a function's scalar and vector variants), nor straight-line scalar
# code packed into vectors (GCC then fuses pairs into vfmaddsub whatever -ffp-contract says):
# a module whose batch rows must equal its single calls bit for bit (the robot's tree module)
# asks for these (Clang takes the second as its -fno-slp-vectorize)
EXACT_CFLAGS = ("-ffp-contract=off", "-fno-tree-slp-vectorize")

_LOADED: dict[str, ModuleType] = {}


class BackendUnavailable(LagrangianError):
    """The compiled (C) backend cannot be used here: no compiler, no headers, or a failed build."""


class CompilerMissing(BackendUnavailable):
    """No C compiler to build with: none on PATH, or $CC names a program that is not there."""


class CacheRefused(LagrangianError):
    """The compiled-module cache directory is not safe to load code from (owned by another user,
    writable by others, or not a directory): refused, never used and never changed."""


def cache_dir() -> Path:
    """Where compiled modules are kept (created on first use)."""
    if os.environ.get("LAGRANGIAN_CACHE"):
        return Path(os.environ["LAGRANGIAN_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "lagrangian"


def trusted_cache_dir() -> Path:
    """The cache directory, created 0700 where missing; CacheRefused where anyone but this user
    could have put a module there (another owner, group- or world-writable, a link)."""
    path = cache_dir()
    try:
        path.mkdir(mode=0o700, parents=True, exist_ok=True)
        info = os.lstat(path)
    except OSError as exc:
        raise BackendUnavailable(f"cannot write the compiled-module cache {path}: "
                                 f"{exc.strerror or exc} (set LAGRANGIAN_CACHE)") from None
    fault = None
    if stat.S_ISLNK(info.st_mode):
        fault = "is a symbolic link"
    elif not stat.S_ISDIR(info.st_mode):
        fault = "is not a directory"
    elif hasattr(os, "getuid") and info.st_uid != os.getuid():
        fault = f"is owned by another user (uid {info.st_uid})"
    elif info.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        fault = f"is writable by other users (mode {stat.S_IMODE(info.st_mode):o})"
    if fault:
        raise CacheRefused(f"the compiled-module cache {path} {fault}: refusing to load code "
                           "from it (chmod 700 it, or set LAGRANGIAN_CACHE to a directory of "
                           "your own)")
    return path


def find_compiler() -> list[str] | None:
    """The C compiler command ($CC, Python's own CC, or cc/gcc/clang on PATH), or None.
    A $CC that names no program is None too (never silently another compiler)."""
    if os.environ.get("CC", "").strip():
        try:
            words = shlex.split(os.environ["CC"])
        except ValueError:  # an unbalanced quote: no command at all
            return None
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


COMPILE_TIMEOUT_S = 600


def _run_compiler(command: list[str]) -> subprocess.CompletedProcess:
    """Run the compiler; on a timeout, an exception (Ctrl-C's included) or a terminating signal
    (compiler_stop.stop_with_caller) the driver dies with everything it started (cc1, as, ld).

    From the main thread it runs in its own session, hence its own process group: one killpg
    then stops the whole tree, atomically, without touching ours (the compiler need not and
    does not get a terminal's Ctrl-C itself: this process kills it). That session is also why a
    SIGTERM, SIGHUP or group kill aimed at us would not reach it, so stop_with_caller turns
    those into that killpg. Signal handlers only run in the main thread: from any other the
    compiler stays in our own process group, so whatever stops our group (timeout(1), a job
    manager, a terminal) stops it too, and a timeout kills the driver's tree found in /proc."""
    own_group = in_main_thread()
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               stdin=subprocess.DEVNULL, text=True, start_new_session=own_group)
    RUNNING[process] = own_group
    try:
        out, err = process.communicate(timeout=COMPILE_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        kill_compiler(process, own_group)
        process.communicate()
        raise subprocess.TimeoutExpired(command, COMPILE_TIMEOUT_S) from None
    except BaseException:  # Ctrl-C and Stopped included: no compiler left running
        kill_compiler(process, own_group)
        raise
    finally:
        RUNNING.pop(process, None)
    return subprocess.CompletedProcess(command, process.returncode, out, err)


def check_compiler() -> list[str]:
    """The compiler command, or CompilerMissing saying why there is none."""
    compiler = find_compiler()
    if compiler is None:
        raise missing_compiler()
    return compiler


def missing_compiler() -> CompilerMissing | None:
    """Why no C compiler can be had (a CompilerMissing to show or raise), None where one can."""
    if find_compiler() is not None:
        return None
    cc = os.environ.get("CC", "").strip()
    if cc:
        try:
            shlex.split(cc)
        except ValueError:
            return CompilerMissing(f"CC={cc!r} is not a command (unbalanced quote; unset CC, or "
                                   "point it at gcc or clang)")
        return CompilerMissing(f"CC={cc!r} names no program on PATH (unset CC, or point it at "
                               "gcc or clang)")
    return CompilerMissing("no C compiler found (set CC, or install gcc or clang)")


def ready(key: str, native: bool = False, exact: bool = False) -> bool:
    """Whether the module of this key can be had without a build (loaded, or in the verified
    cache) or built here (a compiler and Python's headers): a backend chosen up front."""
    name = keyed_module_name(key, native, exact)
    if name in _LOADED:
        return True
    suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
    if sys.platform != "win32" and _load_verified(name, trusted_cache_dir() / f"{name}{suffix}",
                                                  quiet=True) is not None:
        return True
    return available()


def _compile(source: str, name: str, target: Path, native: bool = False,
             exact: bool = False) -> None:
    """Build ``target``; with ``native`` the processor's own instructions, falling back to the
    portable flags where the compiler refuses them (e.g. no -march=native for the target);
    with ``exact``, EXACT_CFLAGS after them (then the first alone, for a compiler that knows
    no other)."""
    extras = (EXACT_CFLAGS, EXACT_CFLAGS[:1]) if exact else ((),)
    attempts = [(*CFLAGS, *NATIVE_CFLAGS, *extra) for extra in extras] if native else []
    attempts += [(*CFLAGS, *extra) for extra in extras]
    for flags in attempts[:-1]:
        try:
            return _compile_with(source, name, target, flags)
        except BackendUnavailable:
            pass
    _compile_with(source, name, target, attempts[-1])


def _compile_with(source: str, name: str, target: Path, flags: tuple[str, ...]) -> None:
    compiler = check_compiler()
    includes = [f"-I{d}" for d in _include_dirs()]
    extra = ["-undefined", "dynamic_lookup"] if sys.platform == "darwin" else []
    with tempfile.TemporaryDirectory(dir=target.parent, prefix=_build_prefix(target)) as tmp:
        BUILD_DIRS.add(tmp)  # for stop_with_caller, should a signal cut the cleanup short
        try:
            c_file = Path(tmp) / f"{name}.c"
            c_file.write_text(f"#define LG_MODULE {name}\n{source}")
            built = Path(tmp) / target.name
            command = [*compiler, *flags, *includes, str(c_file), "-o", str(built), "-lm",
                       *extra]
            try:
                done = _run_compiler(command)
            except (OSError, subprocess.SubprocessError) as exc:
                raise BackendUnavailable(f"the C compiler could not run: {exc}") from None
            if done.returncode != 0:
                cc = os.environ.get("CC", "").strip()
                who = f"the C compiler CC={cc!r}" if cc else f"the C compiler {compiler[0]}"
                raise BackendUnavailable(f"compiling the generated C failed ({who}):\n"
                                         + (done.stderr or done.stdout or "no output")[-2000:])
            # the digest first, then the module, then the source kept for inspection; each by
            # rename, which replaces a planted link rather than writing through it
            _write_atomic(_digest_path(target), json.dumps(
                {"module": target.name, "sha256": _file_digest(built)}).encode())
            os.replace(built, target)
            _write_atomic(target.with_suffix(".c"), c_file.read_bytes())
        finally:
            BUILD_DIRS.discard(tmp)


def _build_prefix(module: Path) -> str:
    return f".build-{module.name.split('.', 1)[0]}-"


def _remove_stale_builds(module: Path) -> None:
    """Remove the build folders of ``module`` that a killed process left (SIGKILL, a power cut).
    Called under the module's lock, so none is a live build's; only folders of this project's
    naming, of this user's, in the trusted (0700) cache are touched, and never through a link."""
    prefix = _build_prefix(module)
    try:
        entries = list(os.scandir(module.parent))
    except OSError:
        return
    for entry in entries:
        if not entry.name.startswith(prefix):
            continue
        try:
            info = entry.stat(follow_symlinks=False)
        except OSError:
            continue
        if stat.S_ISDIR(info.st_mode) and (not hasattr(os, "getuid")
                                           or info.st_uid == os.getuid()):
            shutil.rmtree(entry.path, ignore_errors=True)


def _write_atomic(path: Path, data: bytes) -> None:
    """Write ``data`` to a new file beside ``path`` (0600, never through a link) and rename it
    over ``path``: a reader sees the old file or the whole new one."""
    descriptor, temporary = tempfile.mkstemp(dir=path.parent, prefix=".tmp-")
    try:
        with os.fdopen(descriptor, "wb") as handle:
            handle.write(data)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def _digest_path(module: Path) -> Path:
    return module.with_name(module.name.split(".", 1)[0] + ".sha256")


def _file_digest(path: Path) -> str:
    with open(path, "rb") as handle:
        return hashlib.file_digest(handle, "sha256").hexdigest()


def verify_module(path: Path) -> str | None:
    """Why the cached module at ``path`` must not be loaded, or None when it is a regular file
    of this user's whose SHA-256 is the digest recorded when this project built it."""
    try:
        info = os.lstat(path)
    except FileNotFoundError:
        return "missing"
    if not stat.S_ISREG(info.st_mode):
        return "not a regular file"
    if hasattr(os, "getuid") and info.st_uid != os.getuid():
        return "owned by another user"
    try:
        digest_info = os.lstat(_digest_path(path))
        if not stat.S_ISREG(digest_info.st_mode) or digest_info.st_size > 4096:
            return "its digest is not a small regular file"
        recorded = json.loads(_digest_path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        return "no digest recorded beside it"
    except (OSError, ValueError):
        return "its digest cannot be read"
    if not isinstance(recorded, dict) or recorded.get("module") != path.name:
        return "its digest names another module"
    if recorded.get("sha256") != _file_digest(path):
        return "its content does not match its digest (truncated or replaced)"
    return None


def load(generated: GeneratedSource) -> ModuleType:
    """The compiled module for this source: in memory, else from the cache, else built now."""
    return _load_or_build(module_name(generated), lambda: generated)


@lru_cache(maxsize=1)
def _generator_key() -> str:
    """The code generator itself (codegen.py, the template's three parts): a new generator is a
    new module."""
    here = Path(__file__).parent
    names = ("codegen.py", "template.c", "template_ensemble.c", "template_bindings.c")
    return hashlib.sha256(b"".join((here / f).read_bytes() for f in names)).hexdigest()


def keyed_module_name(key: str, native: bool = False, exact: bool = False) -> str:
    """lg_<hash of the equations' key, the generator, compiler flags, Python and numpy (and,
    for a native build, the processor)>."""
    parts = [_platform_key(), _generator_key(), key]
    if native:
        parts += [" ".join(NATIVE_CFLAGS), cpu_fingerprint()]
    if exact:
        parts.append(" ".join(EXACT_CFLAGS))
    text = "\n".join(parts)
    return f"lg_{hashlib.sha256(text.encode()).hexdigest()[:24]}"


def load_keyed(key: str, make_source: Callable[[], GeneratedSource],
               native: bool = False, exact: bool = False) -> ModuleType:
    """The compiled module for the equations with this key: in memory, else from the on-disk
    cache (no C generated, no compiler needed), else ``make_source()`` generated and built now;
    ``native``: for this processor's instruction set (NATIVE_CFLAGS); ``exact``: without fused
    multiply-adds the compiler would choose (EXACT_CFLAGS)."""
    return _load_or_build(keyed_module_name(key, native, exact), make_source, native, exact)


def _load_or_build(name: str, make_source: Callable[[], GeneratedSource],
                   native: bool = False, exact: bool = False) -> ModuleType:
    """The module ``name``: in memory, else the cached file once verified, else built from
    ``make_source()`` (called only then, after the compiler is found: without one the C would
    be wasted). One process builds a module at a time (a lock file beside it)."""
    if name in _LOADED:
        return _LOADED[name]
    if sys.platform == "win32":
        raise BackendUnavailable("the C backend is not supported on Windows yet")
    suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
    path = trusted_cache_dir() / f"{name}{suffix}"
    module = _load_verified(name, path, quiet=True)
    if module is not None:
        return module
    check_compiler()
    _include_dirs()
    try:
        with stop_with_caller(), _build_lock(path):
            # another process may have built it while this one waited for the lock
            module = _load_verified(name, path, quiet=False)
            if module is not None:
                return module
            _remove_stale_builds(path)
            generated = make_source()
            _compile(generated.source, name, path, native, exact)
    except OSError as exc:
        raise BackendUnavailable(f"cannot write the compiled-module cache {path.parent}: "
                                 f"{exc.strerror or exc} (set LAGRANGIAN_CACHE)") from None
    if verify_module(path) is not None:  # replaced between the build and the load
        raise BackendUnavailable(f"the compiled module {path} changed after it was built")
    try:
        module = _import(name, path)
    except ImportError as exc:
        raise BackendUnavailable(f"cannot load the compiled module {path}: {exc}") from None
    _LOADED[name] = module
    return module


_WARNED: set[str] = set()


def _load_verified(name: str, path: Path, quiet: bool) -> ModuleType | None:
    """The cached module if it passes verify_module and imports; else None, with one warning
    line for a file that is there but failed (``quiet``: not yet, the caller checks again)."""
    fault = verify_module(path)
    if fault is None:
        try:
            module = _import(name, path)
        except ImportError as exc:  # built for another Python, or damaged in a verified way
            fault = f"it does not load ({str(exc).splitlines()[0] if str(exc) else 'ImportError'})"
        else:
            _LOADED[name] = module
            return module
    if fault != "missing" and not quiet and name not in _WARNED:
        _WARNED.add(name)
        print(f"warning: the cached compiled module {path.name} was not loaded ({fault}); "
              "rebuilding it", file=sys.stderr)
    return None


class _build_lock:
    """An exclusive lock on <module>.lock in the cache, so concurrent builds of one module happen
    once. A stale lock is a non-issue: an flock belongs to the open file, which the kernel closes
    when its holder dies however it dies (SIGKILL included), so the next builder takes it at
    once (it is opened O_CLOEXEC, so no compiler inherits it and outlives us holding it). The
    .lock file left behind is only a name to lock: never read, never trusted (its content means
    nothing), opened without following a link, and never removed (unlinking it while another
    process waits on it would let a third lock a new file: two builders at once). The build
    folder a killed process leaves is removed by the next build of that module
    (_remove_stale_builds)."""

    def __init__(self, module: Path):
        self.path = module.with_name(module.name.split(".", 1)[0] + ".lock")
        self.descriptor = -1

    def __enter__(self):
        import fcntl  # POSIX only, as the C backend is

        flags = os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
        try:
            self.descriptor = os.open(self.path, flags, 0o600)
        except OSError as exc:
            if exc.errno != errno.ELOOP:
                raise
            raise BackendUnavailable(f"the cache's lock file {self.path} is a symbolic link: "
                                     "refusing to use it") from None
        fcntl.flock(self.descriptor, fcntl.LOCK_EX)
        return self

    def __exit__(self, *exc_info):
        import fcntl

        fcntl.flock(self.descriptor, fcntl.LOCK_UN)
        os.close(self.descriptor)


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
