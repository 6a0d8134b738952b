"""A compile stops with its caller: a terminating signal or an exception kills the compiler with
everything it started (cc1, as, ld) and leaves no build folder (compiled.py's _run_compiler and
_load_or_build use this). tests/compile/test_compile_signals.py."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import threading

STOP_SIGNALS = tuple(getattr(signal, name) for name in ("SIGTERM", "SIGHUP", "SIGINT")
                     if hasattr(signal, name))
RUNNING: dict[subprocess.Popen, bool] = {}  # compilers not yet reaped: in their own group?
BUILD_DIRS: set[str] = set()  # build folders this process made and has not removed yet


def in_main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def kill_compiler(process: subprocess.Popen, own_group: bool) -> None:
    """SIGKILL the compiler's process group (or, in ours, the driver and its descendants),
    then reap the driver."""
    if own_group:
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            process.kill()
    else:
        try:  # stopped, the driver starts nothing more while its tree is read
            os.kill(process.pid, signal.SIGSTOP)
        except ProcessLookupError:
            pass
        for pid in descendants(process.pid):
            try:
                os.kill(pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
        process.kill()
    try:
        process.wait(timeout=5)
    except subprocess.TimeoutExpired:
        pass


def descendants(root: int) -> list[int]:
    """The processes below ``root`` (Linux /proc; elsewhere none are known)."""
    children: dict[int, list[int]] = {}
    try:
        entries = os.listdir("/proc")
    except OSError:
        return []
    for entry in entries:
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as handle:
                # pid (comm) state ppid ...: comm may hold spaces and parentheses
                parent = int(handle.read().rsplit(b")", 1)[1].split()[1])
        except (OSError, IndexError, ValueError):
            continue
        children.setdefault(parent, []).append(int(entry))
    found, todo = [], [root]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found


class Stopped(BaseException):
    """A terminating signal came during a build: raised from the handler, it unwinds through
    the cleanup (compiler killed, build folder removed, lock released) to stop_with_caller."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


class stop_with_caller:
    """For the duration of a build: a SIGTERM, SIGHUP or SIGINT whose disposition is the default
    (terminate at once, no cleanup) stops the build instead, its compiler and build folder gone,
    then the previous handler is restored and the signal re-delivered, so the process ends by it
    (exit status -15 for SIGTERM). A signal that is ignored stays ignored; one with a Python
    handler (SIGINT's KeyboardInterrupt, a caller's own) keeps it: what that raises unwinds
    through the same cleanup. Only the main thread can set handlers: elsewhere this does
    nothing (see _run_compiler)."""

    def __init__(self):
        self.previous: dict[int, object] = {}
        self.stopping: int | None = None

    def __enter__(self):
        if not in_main_thread():
            return self
        for signum in STOP_SIGNALS:
            try:
                if signal.getsignal(signum) is signal.SIG_DFL:
                    signal.signal(signum, self._handler)
                    self.previous[signum] = signal.SIG_DFL
            except (OSError, ValueError):  # not the main interpreter, or not settable here
                pass
        return self

    def _handler(self, signum, frame):
        if self.stopping is None:  # once: a second signal must not break the cleanup
            self.stopping = signum
            raise Stopped(signum)

    def __exit__(self, *exc_info):
        if self.stopping is not None:  # the unwinding cleaned up; this catches what it missed
            for process, own_group in list(RUNNING.items()):
                kill_compiler(process, own_group)
            for folder in list(BUILD_DIRS):
                shutil.rmtree(folder, ignore_errors=True)
        for signum, previous in self.previous.items():
            signal.signal(signum, previous)
        if self.stopping is not None:
            os.kill(os.getpid(), self.stopping)
            # still here (the signal blocked in this thread): end as the signal would have
            if self.stopping == getattr(signal, "SIGINT", None):
                raise KeyboardInterrupt from None
            raise SystemExit(128 + self.stopping) from None
        return False
