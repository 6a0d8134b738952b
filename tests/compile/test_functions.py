"""Numeric functions: the C backend against the numpy backend and closed forms, batches,
fresh arrays, the compiled-module cache and the fallback without a compiler."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap
import uuid

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lagrangian
from lagrangian.compile import compiled
from lagrangian.compile import functions as functions_module
from lagrangian.compile.compiled import BackendUnavailable
from lagrangian.compile.functions import numeric
from lagrangian.model.examples import example_names

needs_c = pytest.mark.skipif(not compiled.available(), reason="no C compiler / Python headers")


def pendulum(name: str | None = None, L: float = 0.5) -> lagrangian.System:
    b = lagrangian.SystemBuilder(name or "pendulum")
    theta = b.coordinate("theta", unit="rad")
    m, length, g = b.parameter("m", 1.0), b.parameter("L", L), b.parameter("g", 9.81)
    b.set_gravity(g, (0, -1))
    b.add_particle("bob", m, (length * lagrangian.sin(theta), -length * lagrangian.cos(theta)))
    return b.build()


def runnable_examples():
    for name in example_names():
        system = lagrangian.load(name)
        if all(value is not None for value in system.parameters.values()):
            yield name


@needs_c
@pytest.mark.parametrize("name", list(runnable_examples()))
def test_c_backend_agrees_with_numpy_on_every_example(name):
    system = lagrangian.load(name)
    fast, slow = system.numeric(backend="c"), system.numeric(backend="numpy")
    # compiled: generated C, or a tree's recursions on the engine (one module for every tree)
    assert (fast.backend in ("c", "compact"), slow.backend) == (True, "numpy")
    rng = np.random.default_rng(7)
    q, q_dot, t = rng.uniform(-1, 1, (4, 3, fast.n)), rng.uniform(-1, 1, (4, 3, fast.n)), 0.7
    for function in ("mass_matrix", "forcing", "constraint_jacobian", "acceleration_rhs",
                     "constraint_residual", "energy"):
        a, b = getattr(fast, function)(q, q_dot, t), getattr(slow, function)(q, q_dot, t)
        assert a.shape == b.shape
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12, err_msg=function)
    for a, b in zip(fast.accelerations_and_multipliers(q, q_dot, t),
                    slow.accelerations_and_multipliers(q, q_dot, t), strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9)
    y = np.concatenate([q[0, 0], q_dot[0, 0]])
    np.testing.assert_allclose(fast.rhs(t, y), slow.rhs(t, y), rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_double_pendulum_closed_forms(backend):
    if backend == "c" and not compiled.available():
        pytest.skip("no C compiler")
    system = lagrangian.load("double_pendulum").with_parameters(m1=2.0, m2=0.5, l1=1.5, l2=0.8)
    numeric_system = system.numeric(backend=backend)
    m1, m2, l1, l2, g = 2.0, 0.5, 1.5, 0.8, 9.81
    q, w = np.array([0.9, -0.4]), np.array([1.3, -2.1])
    c = np.cos(q[0] - q[1])
    mass = np.array([[(m1 + m2) * l1**2, m2 * l1 * l2 * c], [m2 * l1 * l2 * c, m2 * l2**2]])
    np.testing.assert_allclose(numeric_system.mass_matrix(q, w), mass, rtol=1e-13)
    s = np.sin(q[0] - q[1])
    forcing = np.array([-m2 * l1 * l2 * s * w[1] ** 2 - (m1 + m2) * g * l1 * np.sin(q[0]),
                        m2 * l1 * l2 * s * w[0] ** 2 - m2 * g * l2 * np.sin(q[1])])
    np.testing.assert_allclose(numeric_system.forcing(q, w), forcing, rtol=1e-12)
    energy = (0.5 * (m1 + m2) * l1**2 * w[0] ** 2 + 0.5 * m2 * l2**2 * w[1] ** 2
              + m2 * l1 * l2 * w[0] * w[1] * c
              - (m1 + m2) * g * l1 * np.cos(q[0]) - m2 * g * l2 * np.cos(q[1]))
    assert numeric_system.energy(q, w) == pytest.approx(energy, rel=1e-13)
    np.testing.assert_allclose(numeric_system.rhs(0.0, np.concatenate([q, w]))[2:],
                               np.linalg.solve(mass, forcing), rtol=1e-12)


@needs_c
def test_pendulum_acceleration_and_parameters_reuse_the_compiled_module():
    system = pendulum()
    short, long = system.numeric(backend="c"), system.numeric({"L": 2.0}, backend="c")
    # parameters are runtime inputs of the generated C: one module serves both
    assert short._kernel.module is long._kernel.module
    theta = np.linspace(-3, 3, 13)[:, None]
    q_ddot, _ = short.accelerations_and_multipliers(theta, np.zeros_like(theta))
    np.testing.assert_allclose(q_ddot[:, 0], -9.81 / 0.5 * np.sin(theta[:, 0]), rtol=1e-13, atol=1e-14)
    q_ddot, _ = long.accelerations_and_multipliers(theta, np.zeros_like(theta))
    np.testing.assert_allclose(q_ddot[:, 0], -9.81 / 2.0 * np.sin(theta[:, 0]), rtol=1e-13, atol=1e-14)


@needs_c
def test_constrained_multipliers_cartesian_pendulum():
    """Rod tension of the Cartesian pendulum from the KKT solve, both backends alike."""
    system = lagrangian.load("cartesian_pendulum")
    fast, slow = system.numeric(backend="c"), system.numeric(backend="numpy")
    rng = np.random.default_rng(3)
    q, q_dot = rng.uniform(-1, 1, (50, fast.n)), rng.uniform(-1, 1, (50, fast.n))
    a, b = fast.accelerations_and_multipliers(q, q_dot), slow.accelerations_and_multipliers(q, q_dot)
    assert a[1].shape == (50, 1)
    np.testing.assert_allclose(a[0], b[0], rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(a[1], b[1], rtol=1e-10, atol=1e-10)
    # the accelerations satisfy Phi_q q_ddot = gamma
    jacobian, gamma = fast.constraint_jacobian(q, q_dot), fast.acceleration_rhs(q, q_dot)
    np.testing.assert_allclose(np.einsum("bij,bj->bi", jacobian, a[0]), gamma, atol=1e-10)


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_batch_equals_loop_of_single_states(backend):
    if backend == "c" and not compiled.available():
        pytest.skip("no C compiler")
    numeric_system = lagrangian.load("double_pendulum").numeric(backend=backend)
    rng = np.random.default_rng(11)
    q, q_dot = rng.uniform(-3, 3, (5, 4, 2)), rng.uniform(-3, 3, (5, 4, 2))
    t = rng.uniform(0, 1, (5, 1))  # broadcast against the (5, 4) batch
    batch_q_ddot, _ = numeric_system.accelerations_and_multipliers(q, q_dot, t)
    batch_mass = numeric_system.mass_matrix(q, q_dot, t)
    batch_energy = numeric_system.energy(q, q_dot, t)
    assert batch_q_ddot.shape == (5, 4, 2) and batch_mass.shape == (5, 4, 2, 2)
    assert batch_energy.shape == (5, 4)
    for i in range(5):
        for j in range(4):
            single, _ = numeric_system.accelerations_and_multipliers(q[i, j], q_dot[i, j], t[i, 0])
            assert single.shape == (2,)
            np.testing.assert_array_equal(batch_q_ddot[i, j], single)
            np.testing.assert_array_equal(batch_mass[i, j], numeric_system.mass_matrix(q[i, j], q_dot[i, j]))
            assert batch_energy[i, j] == numeric_system.energy(q[i, j], q_dot[i, j])
            y = np.concatenate([q[i, j], q_dot[i, j]])
            np.testing.assert_allclose(numeric_system.rhs(t[i, 0], y)[2:], single, rtol=1e-14)


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_rhs_returns_a_fresh_array_every_call(backend):
    """PyDy's rhs reuses one output array and solve_ivp then integrates a wrong system."""
    if backend == "c" and not compiled.available():
        pytest.skip("no C compiler")
    numeric_system = lagrangian.load("double_pendulum").numeric(backend=backend)
    y1, y2 = np.array([1.0, 0.5, 0.0, 0.0]), np.array([-0.3, 2.0, 1.0, -1.0])
    first = numeric_system.rhs(0.0, y1)
    kept = first.copy()
    second = numeric_system.rhs(0.0, y2)
    assert first is not second and not np.shares_memory(first, second)
    np.testing.assert_array_equal(first, kept)  # the second call did not overwrite the first
    first[:] = np.nan  # writing into a result does not leak into later calls
    np.testing.assert_array_equal(numeric_system.rhs(0.0, y1), kept)
    assert not np.shares_memory(numeric_system.rhs(0.0, y1), y1)
    # hence solve_ivp sees the right system: the same steps as with explicit copies
    plain = solve_ivp(numeric_system.rhs, (0, 2), y1, method="DOP853", rtol=1e-8, atol=1e-8)
    copied = solve_ivp(lambda t, y: numeric_system.rhs(t, y).copy(), (0, 2), y1, method="DOP853",
                       rtol=1e-8, atol=1e-8)
    assert plain.nfev == copied.nfev
    np.testing.assert_array_equal(plain.y, copied.y)


@needs_c
def test_rhs_accepts_lists_and_rejects_wrong_lengths():
    numeric_system = lagrangian.load("double_pendulum").numeric(backend="c")
    np.testing.assert_allclose(numeric_system.rhs(0, [1.0, 0.5, 0.0, 0.0]),
                               numeric_system.rhs(0.0, np.array([1.0, 0.5, 0.0, 0.0])))
    with pytest.raises(ValueError, match="y must hold 4 numbers"):
        numeric_system.rhs(0.0, np.zeros(3))
    with pytest.raises(ValueError, match="last axis of length 2"):
        numeric_system.mass_matrix(np.zeros(3), np.zeros(3))


def test_unknown_backend_is_rejected():
    with pytest.raises(ValueError, match="backend must be one of auto, c, numpy"):
        pendulum().numeric(backend="fortran")


def singular_at_zero() -> lagrangian.System:
    """x = s^2: M = 4 m s^2 vanishes at s = 0."""
    b = lagrangian.SystemBuilder("singular at zero")
    s = b.coordinate("s")
    b.add_particle("bead", b.parameter("m", 1.0), (s**2, 0))
    return b.build()


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_singular_mass_matrix_raises_linalg_error(backend):
    if backend == "c" and not compiled.available():
        pytest.skip("no C compiler")
    numeric_system = singular_at_zero().numeric(backend=backend)
    q_ddot = numeric_system.accelerations_and_multipliers([1.0], [1.0])[0]
    assert q_ddot == pytest.approx([-1.0])  # -s_dot^2/s
    with pytest.raises(np.linalg.LinAlgError):
        numeric_system.accelerations_and_multipliers([[1.0], [0.0]], [[1.0], [1.0]])
    with pytest.raises(np.linalg.LinAlgError):
        numeric_system.rhs(0.0, [0.0, 1.0])


@needs_c
def test_empty_batch_and_unwritable_cache(monkeypatch, tmp_path):
    numeric_system = lagrangian.load("double_pendulum").numeric(backend="c")
    q_ddot, multipliers = numeric_system.accelerations_and_multipliers(np.zeros((0, 2)), np.zeros((0, 2)))
    assert q_ddot.shape == (0, 2) and multipliers.shape == (0, 0)
    assert numeric_system.energy(np.zeros((0, 2)), np.zeros((0, 2))).shape == (0,)
    blocked = tmp_path / "file"
    blocked.write_text("not a directory")
    monkeypatch.setenv("LAGRANGIAN_CACHE", str(blocked / "cache"))
    system = pendulum(f"pendulum {uuid.uuid4()}")
    with pytest.raises(BackendUnavailable, match="cannot write the compiled-module cache"):
        system.numeric(backend="c")
    with pytest.warns(RuntimeWarning, match="using numpy"):
        assert system.numeric().backend == "numpy"


@needs_c
def test_second_build_loads_from_the_cache_without_compiling(tmp_path):
    """A fresh process with a warm cache must not run the compiler at all."""
    script = textwrap.dedent("""
        import lagrangian
        from lagrangian.compile import compiled
        def refuse(command):
            raise AssertionError("the compiler ran")
        compiled._run_compiler = refuse
        system = lagrangian.load("pendulum").numeric(backend="c")
        print(system.backend, system.rhs(0.0, [0.3, 0.0])[1])
    """)
    env = dict(os.environ, LAGRANGIAN_CACHE=str(tmp_path))
    cold = subprocess.run([sys.executable, "-c", script.replace(
        "compiled._run_compiler = refuse", "")], env=env, capture_output=True, text=True, timeout=120)
    assert cold.returncode == 0, cold.stderr
    assert list(tmp_path.glob("lg_*.c")) and list(tmp_path.glob("lg_*.so"))
    warm = subprocess.run([sys.executable, "-c", script], env=env,
                          capture_output=True, text=True, timeout=120)
    assert warm.returncode == 0, warm.stderr
    assert warm.stdout.split()[0] == "c"
    assert float(warm.stdout.split()[1]) == pytest.approx(-9.81 / 0.5 * np.sin(0.3), rel=1e-13)


def test_falls_back_to_numpy_without_a_compiler(monkeypatch):
    monkeypatch.setattr(compiled, "find_compiler", lambda: None)
    system = pendulum(f"pendulum {uuid.uuid4()}")
    numeric_system = system.numeric()  # auto
    assert numeric_system.backend == "numpy"
    assert numeric_system.rhs(0.0, [0.3, 0.0])[1] == pytest.approx(-9.81 / 0.5 * np.sin(0.3))
    with pytest.raises(BackendUnavailable, match="no C compiler"):
        system.numeric(backend="c")


@needs_c
def test_falls_back_to_numpy_when_the_build_fails(monkeypatch, tmp_path):
    monkeypatch.setenv("LAGRANGIAN_CACHE", str(tmp_path))

    def broken(command):
        return subprocess.CompletedProcess(command, 1, "", "cc: internal compiler error")

    monkeypatch.setattr(compiled, "_run_compiler", broken)
    system = pendulum(f"pendulum {uuid.uuid4()}")  # a new source: not already loaded
    with pytest.warns(RuntimeWarning, match="internal compiler error"):
        numeric_system = numeric(system.equations_of_motion())
    assert numeric_system.backend == "numpy"
    with pytest.raises(BackendUnavailable, match="compiling the generated C failed"):
        numeric(system.equations_of_motion(), backend="c")
    assert not list(tmp_path.glob("lg_*.so"))


@needs_c
def test_generated_source_has_no_symbolic_inverse_and_shares_subexpressions():
    from lagrangian.compile.codegen import generate

    source = generate(lagrangian.load("double_pendulum").equations_of_motion()).source
    assert "lg_solve(" in source  # the solve is numeric, in C
    parts = source.split("static void lg_parts")[1].split("static double lg_energy")[0]
    calls = re.findall(r"\b(?:sin|cos)\([^()]*\)", parts)
    assert calls and len(calls) == len(set(calls))  # cse: each trig call computed once
    assert functions_module.BACKENDS == ("auto", "c", "numpy")


def test_angle_sums_are_split_only_when_that_saves_trig_calls():
    import sympy as sp

    from lagrangian.compile.codegen import _fewer_trig_calls

    angles = sp.symbols("a b c d")
    w, t, phi = sp.symbols("w t phi")
    pairs = [(x, y) for i, x in enumerate(angles) for y in angles[i + 1:]]
    chain = [f(x - y) for x, y in pairs for f in (sp.sin, sp.cos)]
    split = _fewer_trig_calls(chain)  # 12 calls -> sin and cos of a, b, c, d
    assert {e for s in split for e in s.atoms(sp.sin, sp.cos)} == {
        f(x) for x in angles for f in (sp.sin, sp.cos)}
    values = dict(zip(angles, (0.3, -1.2, 2.5, 0.7), strict=True))
    for original, rewritten in zip(chain, split, strict=True):
        assert float(rewritten.subs(values)) == pytest.approx(float(original.subs(values)), abs=1e-15)
    assert _fewer_trig_calls(chain[:6]) == chain[:6]  # only pairs with a: 6 calls, 8 if split
    drive = [sp.sin(w * t + phi)]  # one call; splitting would make it four
    assert _fewer_trig_calls(drive) == drive
