"""The compiled-module cache trusts nothing it finds (issue 21): a planted module is never
dlopen'ed, a planted link is never written through, a truncated module is rebuilt with one
warning line instead of killing the process, two processes building one module both succeed, a
cache directory others can write to is refused in one line, and a compiler that hangs is killed
with everything it started."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from lagrangian.compile import compiled

needs_c = pytest.mark.skipif(not compiled.available(), reason="no C compiler / Python headers")

SCRIPT = textwrap.dedent("""
    import sys
    import lagrangian
    system = lagrangian.load("pendulum").numeric(backend="c")
    print(system.backend, system.rhs(0.0, [0.3, 0.0])[1])
""")


def run(cache: Path, **env) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True,
                          timeout=300, env=dict(os.environ, LAGRANGIAN_CACHE=str(cache), **env))


def pendulum_acceleration(done: subprocess.CompletedProcess) -> float:
    assert done.returncode == 0, done.stderr
    backend, value = done.stdout.split()
    assert backend == "c"
    return float(value)


def modules(cache: Path) -> list[Path]:
    return sorted(p for p in cache.iterdir() if p.name.endswith(".so") and p.name.startswith("lg_"))


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """A cache holding the pendulum's module, built by a fresh process."""
    cache = tmp_path_factory.mktemp("cache")
    cache.chmod(0o700)
    first = run(cache)
    value = pendulum_acceleration(first)
    assert value == pytest.approx(-9.81 / 0.5 * np.sin(0.3), rel=1e-14)  # theta_ddot = -g/L sin
    (module,) = modules(cache)
    return cache, module.name, value


def copy_cache(built, tmp_path) -> tuple[Path, Path, float]:
    cache, name, value = built
    target = tmp_path / "cache"
    target.mkdir(mode=0o700)
    for item in cache.iterdir():
        if item.is_file() and not item.name.startswith("."):
            (target / item.name).write_bytes(item.read_bytes())
    return target, target / name, value


def evil_module(tmp_path: Path, marker: Path) -> bytes:
    """A shared object whose constructor writes ``marker``: what an attacker would plant."""
    source = tmp_path / "evil.c"
    source.write_text('#include <stdio.h>\n__attribute__((constructor)) static void f(void) '
                      f'{{ FILE *h = fopen("{marker}", "w"); if (h) {{ fputs("ran", h); '
                      'fclose(h); } }\n')
    out = tmp_path / "evil.so"
    subprocess.run([*compiled.check_compiler(), "-shared", "-fPIC", str(source), "-o", str(out)],
                   check=True, capture_output=True)
    return out.read_bytes()


@needs_c
def test_a_planted_module_is_never_loaded_and_is_rebuilt_with_one_warning(built, tmp_path):
    cache, module, value = copy_cache(built, tmp_path)
    marker = tmp_path / "owned.txt"
    module.write_bytes(evil_module(tmp_path, marker))
    done = run(cache)
    assert pendulum_acceleration(done) == value
    assert not marker.exists(), "the planted module's constructor ran"
    assert done.stderr.count("\n") == 1 and done.stderr.startswith("warning: ")
    assert "does not match its digest" in done.stderr
    # the rebuilt module is the project's own again: the next run is silent
    again = run(cache)
    assert pendulum_acceleration(again) == value and again.stderr == ""


@needs_c
def test_a_planted_module_with_no_digest_is_not_loaded(built, tmp_path):
    cache, module, value = copy_cache(built, tmp_path)
    marker = tmp_path / "owned.txt"
    module.write_bytes(evil_module(tmp_path, marker))
    compiled._digest_path(module).unlink()
    done = run(cache)
    assert pendulum_acceleration(done) == value
    assert not marker.exists()
    assert "no digest recorded" in done.stderr


@needs_c
def test_a_truncated_module_is_rebuilt_not_a_crash(built, tmp_path):
    cache, module, value = copy_cache(built, tmp_path)
    data = module.read_bytes()
    module.write_bytes(data[: len(data) // 3])
    done = run(cache)
    assert done.returncode == 0, f"exit {done.returncode}: {done.stderr}"
    assert pendulum_acceleration(done) == value
    assert "truncated or replaced" in done.stderr


@needs_c
def test_a_planted_link_is_replaced_never_written_through(built, tmp_path):
    cache, module, value = copy_cache(built, tmp_path)
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    kept_source = module.with_suffix(".c")
    for path in (module, kept_source, compiled._digest_path(module)):
        path.unlink(missing_ok=True)
    kept_source.symlink_to(victim)
    compiled._digest_path(module).symlink_to(victim)
    done = run(cache)
    assert pendulum_acceleration(done) == value
    assert victim.read_text() == "precious"
    assert not kept_source.is_symlink() and "lagrangian" in kept_source.read_text()
    assert not compiled._digest_path(module).is_symlink()


@needs_c
def test_two_processes_building_one_module_at_once_both_succeed(tmp_path):
    cache = tmp_path / "cache"
    started = [subprocess.Popen([sys.executable, "-c", SCRIPT], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True,
                                env=dict(os.environ, LAGRANGIAN_CACHE=str(cache)))
               for _ in range(2)]
    results = []
    for process in started:
        out, err = process.communicate(timeout=300)
        results.append(subprocess.CompletedProcess([], process.returncode, out, err))
    first, second = (pendulum_acceleration(r) for r in results)
    assert first == second
    assert all(r.stderr == "" for r in results)
    assert len(modules(cache)) == 1 and compiled.verify_module(modules(cache)[0]) is None


@needs_c
@pytest.mark.parametrize("mode", [0o777, 0o770, 0o722])
def test_a_cache_others_can_write_is_refused_in_one_line(tmp_path, mode):
    cache = tmp_path / "shared"
    cache.mkdir()
    cache.chmod(mode)
    done = subprocess.run([sys.executable, "-m", "lagrangian", "simulate", "pendulum",
                           "--t-end", "0.1"], capture_output=True, text=True, timeout=300,
                          env=dict(os.environ, LAGRANGIAN_CACHE=str(cache)))
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and done.stderr.startswith("error: ")
    assert "writable by other users" in done.stderr
    assert list(cache.iterdir()) == []  # nothing written there


def test_a_new_cache_directory_is_private(tmp_path, monkeypatch):
    monkeypatch.setenv("LAGRANGIAN_CACHE", str(tmp_path / "a" / "cache"))
    path = compiled.trusted_cache_dir()
    assert path.is_dir() and (path.stat().st_mode & 0o777) == 0o700


def test_a_cache_that_is_a_link_is_refused(tmp_path, monkeypatch):
    (tmp_path / "real").mkdir(mode=0o700)
    (tmp_path / "link").symlink_to(tmp_path / "real")
    monkeypatch.setenv("LAGRANGIAN_CACHE", str(tmp_path / "link"))
    with pytest.raises(compiled.CacheRefused, match="symbolic link"):
        compiled.trusted_cache_dir()


def test_cc_with_an_unbalanced_quote_is_named_not_a_traceback(monkeypatch):
    monkeypatch.setenv("CC", "gcc '")
    assert compiled.find_compiler() is None
    with pytest.raises(compiled.CompilerMissing, match="unbalanced quote"):
        compiled.check_compiler()


@pytest.mark.skipif(sys.platform == "win32", reason="process groups")
def test_a_compiler_that_hangs_is_killed_with_its_children(tmp_path, monkeypatch):
    """The driver and what it started (cc1 in real life, a sleep here) die at the timeout."""
    pid_file = tmp_path / "child.pid"
    fake = tmp_path / "fake-cc"
    fake.write_text(f"#!/bin/sh\nsleep 60 &\necho $! > {pid_file}\nwait\n")
    fake.chmod(0o755)
    monkeypatch.setattr(compiled, "COMPILE_TIMEOUT_S", 1)
    with pytest.raises(subprocess.TimeoutExpired):
        compiled._run_compiler([str(fake)])
    child = int(pid_file.read_text())
    for _ in range(50):
        try:
            os.kill(child, 0)
        except ProcessLookupError:
            break
        # a zombie of an orphan is reaped by init; /proc tells whether it still runs
        status = Path(f"/proc/{child}/status")
        if status.exists() and "State:\tZ" in status.read_text():
            break
        time.sleep(0.1)
    else:
        pytest.fail("the compiler's child process still runs after the timeout")
