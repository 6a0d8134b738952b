"""A compile stops with its caller ("Trust at the new seams", item 3): SIGTERM or SIGHUP to a
process while gcc compiles for it (kill, timeout(1), a job manager) ends the process by that
signal with no gcc or cc1 left running and no build folder left in the cache; a killed
builder's lock is taken over at once and its build folder removed by the next build."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

from lagrangian.compile import compiled
from lagrangian.compile.compiler_stop import stop_with_caller

linux = pytest.mark.skipif(sys.platform != "linux", reason="/proc and Linux process trees")
needs_c = pytest.mark.skipif(not compiled.available(), reason="no C compiler / Python headers")

# C that keeps cc1 busy for seconds at -O2 (6000 of these lines: about 6 s here); the process is
# signalled as soon as cc1 exists, so the test waits for none of it
SCRIPT = textwrap.dedent("""
    import sys, threading
    from lagrangian.compile import compiled
    from lagrangian.compile.codegen import GeneratedSource

    body = "".join(f" a = a*{i}.5 + b*x[{i % 7}] - a/(b+{i}.25); b = b*a + {i}.125;\\n"
                   for i in range(8000))
    source = "double slow(double *x) { double a = x[0], b = x[1];\\n" + body + " return a+b; }\\n"
    build = lambda: compiled.load(GeneratedSource(source, (), 1, 1))
    if sys.argv[1] == "thread":
        worker = threading.Thread(target=build)
        worker.start()
        worker.join()
    else:
        build()
""")


def _stat(pid: int) -> tuple[str, str, int, int, int] | None:
    """(comm, state, ppid, pgid, sid) of a process, None once it is gone."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    comm = text[text.index("(") + 1:text.rindex(")")]
    fields = text[text.rindex(")") + 2:].split()
    return comm, fields[0], int(fields[1]), int(fields[2]), int(fields[3])


def _processes() -> dict[int, tuple[str, str, int, int, int]]:
    found = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit() and (info := _stat(int(entry))) is not None:
            found[int(entry)] = info
    return found


def _descendants(root: int) -> dict[int, tuple[str, str, int, int, int]]:
    table = _processes()
    below, todo = {}, [root]
    while todo:
        parent = todo.pop()
        for pid, info in table.items():
            if info[2] == parent and pid not in below:
                below[pid] = info
                todo.append(pid)
    return below


def _alive(pid: int) -> bool:
    info = _stat(pid)
    return info is not None and info[1] != "Z"


def _signalled_during_compile(tmp_path: Path, mode: str, send) -> tuple[
        subprocess.Popen, dict[int, tuple[str, str, int, int, int]]]:
    """Start a process compiling slow C (``mode``: "main" or "thread"), wait for its cc1, call
    ``send(process)``; the process and the compiler processes seen under it."""
    cache = tmp_path / "cache"
    process = subprocess.Popen([sys.executable, "-c", SCRIPT, mode], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, start_new_session=True,
                               env=dict(os.environ, LAGRANGIAN_CACHE=str(cache)))
    seen: dict[int, tuple[str, str, int, int, int]] = {}
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and process.poll() is None:
        seen = _descendants(process.pid)
        if any(info[0] == "cc1" for info in seen.values()):
            break
        time.sleep(0.02)
    else:
        process.kill()
        pytest.fail(f"no cc1 appeared under the compiling process: {process.communicate()}")
    send(process)
    return process, seen


def _assert_stopped(process, seen, tmp_path: Path, signum: int, clean: bool = True) -> None:
    try:
        _, err = process.communicate(timeout=5)
        assert process.returncode == -signum, err
        sessions = {info[4] for info in seen.values()} | {process.pid}
        deadline = time.monotonic() + 3
        while True:
            left = [pid for pid in seen if _alive(pid)]
            left += [pid for pid, info in _processes().items()
                     if info[4] in sessions and info[1] != "Z" and pid not in left]
            if not left or time.monotonic() > deadline:
                break
            time.sleep(0.05)
        assert not left, f"compiler processes still run: {[_stat(pid) for pid in left]}"
        builds = [p for p in (tmp_path / "cache").iterdir() if p.name.startswith(".build-")]
        if clean:
            assert not builds
        else:  # at most the one build folder, for the next build of the module to remove
            assert len(builds) <= 1
    finally:  # never leave a compiler running, whatever failed
        for pid in seen:
            if _alive(pid):
                os.kill(pid, signal.SIGKILL)


@linux
@needs_c
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_to_the_caller_stops_its_compiler(tmp_path, signum):
    """kill PID: only the caller gets the signal; its handler kills the compiler's group."""
    process, seen = _signalled_during_compile(
        tmp_path, "main", lambda p: os.kill(p.pid, signum))
    assert {info[4] for info in seen.values()} != {process.pid}  # its own session, as built
    _assert_stopped(process, seen, tmp_path, signum)


@linux
@needs_c
def test_a_compile_in_a_thread_stops_with_its_process_group(tmp_path):
    """timeout(1) or a job manager signals the whole group: from a thread, where no handler
    can be set, the compiler is in that group and stops with it (the process ends at once, so
    its build folder is left to the next build of the module: _remove_stale_builds)."""
    process, seen = _signalled_during_compile(
        tmp_path, "thread", lambda p: os.killpg(p.pid, signal.SIGTERM))
    assert {info[3] for info in seen.values()} == {process.pid}
    _assert_stopped(process, seen, tmp_path, signal.SIGTERM, clean=False)


@linux
def test_a_thread_timeout_kills_the_compilers_children(tmp_path, monkeypatch):
    """Off the main thread the compiler shares our group; a timeout kills its tree (/proc)."""
    pid_file = tmp_path / "child.pid"
    fake = tmp_path / "fake-cc"
    fake.write_text(f"#!/bin/sh\nsleep 60 &\necho $! > {pid_file}\nwait\n")
    fake.chmod(0o755)
    monkeypatch.setattr(compiled, "COMPILE_TIMEOUT_S", 1)
    raised = []

    def run():
        try:
            compiled._run_compiler([str(fake)])
        except subprocess.TimeoutExpired as exc:
            raised.append(exc)

    worker = threading.Thread(target=run)
    worker.start()
    worker.join(timeout=10)
    assert raised
    child = int(pid_file.read_text())
    for _ in range(30):
        if not _alive(child):
            break
        time.sleep(0.1)
    else:
        os.kill(child, signal.SIGKILL)
        pytest.fail("the compiler's child still runs after the timeout")


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_handlers_are_set_only_for_default_signals_and_restored():
    previous = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGHUP)}
    try:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        signal.signal(signal.SIGHUP, signal.SIG_IGN)  # nohup: stays ignored
        with stop_with_caller():
            assert signal.getsignal(signal.SIGTERM) not in (signal.SIG_DFL, signal.SIG_IGN)
            assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL
        assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


@pytest.mark.skipif(sys.platform == "win32", reason="flock")
def test_a_killed_builders_lock_is_taken_over_and_its_lock_file_not_trusted(tmp_path):
    module = tmp_path / "lg_x.so"
    lock = tmp_path / "lg_x.lock"
    holder = subprocess.Popen([sys.executable, "-c", textwrap.dedent(f"""
        import fcntl, os, sys, time
        fd = os.open({str(lock)!r}, os.O_RDWR | os.O_CREAT, 0o600)
        os.write(fd, b"pid 1, do not touch")
        fcntl.flock(fd, fcntl.LOCK_EX)
        print("locked", flush=True)
        time.sleep(60)
    """)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
    finally:
        holder.kill()  # SIGKILL: no cleanup of its own
        holder.wait()
    assert lock.exists()
    start = time.monotonic()
    with compiled._build_lock(module):
        pass
    assert time.monotonic() - start < 2


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX permissions")
def test_only_this_modules_own_leftover_build_folders_are_removed(tmp_path):
    module = tmp_path / "lg_abc.cpython-311-x86_64-linux-gnu.so"
    stale = tmp_path / ".build-lg_abc-k3j2"
    (stale / "sub").mkdir(parents=True)
    (stale / "sub" / "lg_abc.c").write_text("int x;")
    other = tmp_path / ".build-lg_other-aaaa"  # another module's: maybe a live build
    other.mkdir()
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "keep").write_text("not ours")
    (tmp_path / ".build-lg_abc-link").symlink_to(outside)
    (tmp_path / ".build-lg_abc-file").write_text("a file, not a build folder")
    compiled._remove_stale_builds(module)
    assert not stale.exists()
    assert other.is_dir()
    assert (outside / "keep").read_text() == "not ours"
    assert (tmp_path / ".build-lg_abc-link").is_symlink()
    assert (tmp_path / ".build-lg_abc-file").exists()
