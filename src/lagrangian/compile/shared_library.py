"""A shared library built from our generated C for another program to load (an FMU's binary):
compiled with the same compiler and portable flags as the compiled backend, returned as bytes."""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

from .compiled import CFLAGS, BackendUnavailable, _run_compiler, check_compiler


def shared_library(sources: dict[str, str], name: str) -> bytes:
    """Compile ``sources`` (file name -> C text, ours only) into the shared library ``name``
    (e.g. "pendulum.so") for this platform; BackendUnavailable (CompilerMissing) says why not."""
    compiler = check_compiler()
    extra = ["-undefined", "dynamic_lookup"] if sys.platform == "darwin" else []
    with tempfile.TemporaryDirectory(prefix="lg_shared_") as tmp:
        files = []
        for file_name, text in sources.items():
            path = Path(tmp) / file_name
            path.write_text(text, encoding="utf-8")
            if path.suffix == ".c":
                files.append(str(path))
        target = Path(tmp) / name
        command = [*compiler, *CFLAGS, f"-I{tmp}", *files, "-o", str(target), "-lm", *extra]
        try:
            done = _run_compiler(command)
        except (OSError, subprocess.SubprocessError) as exc:
            raise BackendUnavailable(f"the C compiler could not run: {exc}") from None
        if done.returncode != 0:
            raise BackendUnavailable(f"compiling the generated C failed ({compiler[0]}):\n"
                                     + (done.stderr or done.stdout or "no output")[-2000:])
        return target.read_bytes()


def platform_folder() -> str:
    """The FMI 2.0 binaries folder of this platform: linux64, darwin64 or win64."""
    import platform

    bits = "64" if sys.maxsize > 2**32 else "32"
    system = {"linux": "linux", "darwin": "darwin", "win32": "win"}.get(sys.platform, "linux")
    if system == "darwin" and platform.machine() == "arm64":
        return "darwin64"
    return f"{system}{bits}"


def library_suffix() -> str:
    return {"darwin": ".dylib", "win32": ".dll"}.get(sys.platform, ".so")


__all__ = ["library_suffix", "platform_folder", "shared_library"]
