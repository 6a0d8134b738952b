"""The compiled-module cache is keyed on the equations, before any C is generated: a cached
module loads with no compiler and no code generation; without a compiler the fallback to numpy
is said once, in one plain line; $CC naming a missing or failing compiler is named (issue 12)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import uuid

import numpy as np
import pytest
import sympy as sp

import lagrangian
from lagrangian.compile import compiled
from lagrangian.compile import functions as functions_module
from lagrangian.compile.compiled import BackendUnavailable, CompilerMissing

needs_c = pytest.mark.skipif(not compiled.available(), reason="no C compiler / Python headers")


def pendulum(name: str) -> lagrangian.System:
    b = lagrangian.SystemBuilder(name)
    theta = b.coordinate("theta", unit="rad")
    m, length, g = b.parameter("m", 1.0), b.parameter("L", 0.5), b.parameter("g", 9.81)
    b.set_gravity(g, (0, -1))
    b.add_particle("bob", m, (length * lagrangian.sin(theta), -length * lagrangian.cos(theta)))
    return b.build()


@needs_c
def test_a_cached_module_loads_with_no_compiler_and_no_code_generation(tmp_path):
    """theta_ddot = -(g/L) sin(theta), from the module built by another process."""
    script = textwrap.dedent("""
        import lagrangian
        from lagrangian.compile import codegen
        from lagrangian.compile import compiled
        if WARM:
            def refuse(*args):
                raise AssertionError("C was generated or compiled on a cache hit")
            codegen.generate = refuse
            compiled._run_compiler = refuse
        system = lagrangian.load("double_pendulum").numeric(backend="c")
        print(system.backend, *system.rhs(0.0, [0.3, -0.2, 0.5, 0.1]))
    """)
    env = dict(os.environ, LAGRANGIAN_CACHE=str(tmp_path))
    cold = subprocess.run([sys.executable, "-c", script.replace("WARM", "False")], env=env,
                          capture_output=True, text=True, timeout=120)
    assert cold.returncode == 0, cold.stderr
    env["CC"] = "/nonexistent/bin/no-such-cc"  # and no compiler may run either
    warm = subprocess.run([sys.executable, "-c", script.replace("WARM", "True")], env=env,
                          capture_output=True, text=True, timeout=120)
    assert warm.returncode == 0, warm.stderr
    assert warm.stderr == ""  # no note: the fast path is there
    backend, *rhs = warm.stdout.split()
    assert backend == "c"
    # the same right-hand side as the numpy functions (an independent path, lambdify)
    numpy_rhs = lagrangian.load("double_pendulum").numeric(backend="numpy").rhs(
        0.0, [0.3, -0.2, 0.5, 0.1])
    assert np.array(rhs, dtype=float) == pytest.approx(numpy_rhs, rel=1e-12)


def test_a_missing_compiler_named_by_cc_is_said_once_in_one_line(monkeypatch, tmp_path, capsys):
    monkeypatch.setenv("LAGRANGIAN_CACHE", str(tmp_path))
    monkeypatch.setenv("CC", "/nonexistent/bin/no-such-cc")
    monkeypatch.setattr(functions_module, "_TOLD", set())
    with pytest.raises(CompilerMissing, match="CC='/nonexistent/bin/no-such-cc' names no program"):
        pendulum(f"pendulum {uuid.uuid4()}").numeric(backend="c")
    for _ in range(2):
        system = pendulum(f"pendulum {uuid.uuid4()}").numeric()  # auto: numpy, said once
        assert system.backend == "numpy"
        assert system.rhs(0.0, [0.3, 0.0])[1] == pytest.approx(-9.81 / 0.5 * np.sin(0.3))
    err = capsys.readouterr().err
    assert err == ("note: CC='/nonexistent/bin/no-such-cc' names no program on PATH, so the "
                   "equations run as numpy functions, 50-100x slower than compiled C; for the "
                   "fast path unset CC or point it at gcc or clang\n")


def test_no_compiler_at_all_is_said_once(monkeypatch, tmp_path, capsys):
    monkeypatch.setenv("LAGRANGIAN_CACHE", str(tmp_path))
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.setattr(compiled, "find_compiler", lambda: None)
    monkeypatch.setattr(functions_module, "_TOLD", set())
    assert pendulum(f"pendulum {uuid.uuid4()}").numeric().backend == "numpy"
    assert capsys.readouterr().err == (
        "note: no C compiler found, so the equations run as numpy functions, 50-100x slower "
        "than compiled C; for the fast path install gcc or clang (or set CC)\n")


@needs_c
def test_a_failing_compiler_named_by_cc_is_named(monkeypatch, tmp_path):
    monkeypatch.setenv("LAGRANGIAN_CACHE", str(tmp_path))
    monkeypatch.setenv("CC", "false")  # a program that exists and fails
    with pytest.raises(BackendUnavailable, match="compiling the generated C failed "
                                                 r"\(the C compiler CC='false'\)"):
        pendulum(f"pendulum {uuid.uuid4()}").numeric(backend="c")
    with pytest.warns(RuntimeWarning, match="using numpy"):
        assert pendulum(f"pendulum {uuid.uuid4()}").numeric().backend == "numpy"


def test_the_key_is_the_equations_exactly():
    """Same equations, same key (another load); a coefficient one bit apart, another key."""
    from lagrangian.compile.functions import equations_key

    def spring(k_scale: float) -> lagrangian.System:
        b = lagrangian.SystemBuilder("oscillator")
        x = b.coordinate("x", unit="m")
        m, k = b.parameter("m", 1.0), b.parameter("k", 4.0)
        b.add_particle("mass", m, (x, 0))
        b.add_potential_energy(sp.Float(k_scale) * k * x**2 / 2)
        return b.build()

    key = equations_key(lagrangian.load("double_pendulum").equations_of_motion())
    assert key == equations_key(lagrangian.load("double_pendulum").equations_of_motion())
    one, next_up = (equations_key(spring(s).equations_of_motion())
                    for s in (1.5, np.nextafter(1.5, 2.0)))
    assert one != next_up
