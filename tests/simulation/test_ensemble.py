"""Ensembles in one C call (simulation/ensemble.py integrate_ensemble): every member equals the
single-point DOP853 loop run on it alone, on vector lanes or one by one, whatever the other
members of the call do (fail, take 100x more steps); and the physics holds (closed forms,
conservation of energy)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import lagrangian
from lagrangian.analysis.sweep import ENSEMBLE_NATIVE
from lagrangian.compile import compiled
from lagrangian.compile.codegen import generate
from lagrangian.compile.functions import equations_key
from lagrangian.simulation.ensemble import integrate_ensemble
from lagrangian.simulation.invariants import energy_drift as _drift

pytestmark = pytest.mark.skipif(not compiled.available(), reason="no C compiler / Python headers")

RTOL = ATOL = 1e-9


def _module(system):
    """The model's module as ensembles load it (study/engine.py)."""
    eom = system._equations
    return compiled.load_keyed(equations_key(eom), lambda: generate(eom, vector=True),
                              native=ENSEMBLE_NATIVE)


def _one_by_one(module, P, Y0, grid, max_steps=10_000_000):
    """Each member through the single-point loop (module.dop853), summarized in numpy."""
    n = Y0.shape[1] // 2
    rows = []
    for p, y0 in zip(P, Y0, strict=True):
        t, y, _, _, status, reached = module.dop853(p, grid[0], grid[-1], y0, RTOL, ATOL, grid,
                                                    max_steps)
        if status != 0:
            rows.append((None, status, reached))
            continue
        q, v = np.ascontiguousarray(y[:, :n]), np.ascontiguousarray(y[:, n:])
        energy = module.energy(q, v, t, p)
        kinetic = energy - module.energy(q, np.zeros_like(v), t, p)
        rows.append(((y[-1], y.min(axis=0), y.max(axis=0), t[-1], _drift(energy, kinetic), y),
                     status, reached))
    return rows


@pytest.fixture(scope="module")
def pendulum2():
    return lagrangian.load("double_pendulum")


def _assert_same(run, rows, rtol):
    """run equals the members run alone: to ``rtol``, or to the last bit when rtol is 0."""
    def same(a, b):
        if rtol == 0:
            np.testing.assert_array_equal(a, b)
        else:
            np.testing.assert_allclose(a, b, rtol=rtol, atol=1e-13)

    for i, (summary, status, reached) in enumerate(rows):
        assert run.status[i] == status
        same(run.t_reached[i], reached)
        if summary is None:
            assert np.all(np.isnan(run.final[i])) and np.isnan(run.drift[i])
            if run.trajectory is not None:
                assert np.all(np.isnan(run.trajectory[i]))
            continue
        final, low, high, t_final, drift, y = summary
        same(run.final[i], final)
        same(run.minimum[i], low)
        same(run.maximum[i], high)
        assert run.t_final[i] == t_final
        # the drift (~1e-10) compares energies that agree to a few ulps: absolute 1e-14
        assert run.drift[i] == (drift if rtol == 0 else pytest.approx(drift, rel=1e-6, abs=1e-14))
        if run.trajectory is not None:
            same(run.trajectory[i], y)


@pytest.fixture(scope="module")
def libm_module(pendulum2):
    """The double pendulum's module with libm's sin and cos on the lanes (LG_LIBM_TRIG): the
    vector loop then does each member's arithmetic exactly as the scalar loop."""
    generated = generate(pendulum2._equations, vector=True)
    return compiled.load(dataclasses.replace(
        generated, source="#define LG_LIBM_TRIG 1\n" + generated.source))


def _inputs(system, count, seed=0, **columns):
    rng = np.random.default_rng(seed)
    names = [p.name for p in system.model.parameters]
    P = np.tile([p.value for p in system.model.parameters], (count, 1)).astype(float)
    for name, values in columns.items():
        P[:, names.index(name)] = values
    Y0 = np.zeros((count, 2 * len(system.model.coordinates)))
    Y0[:, :2] = rng.uniform(-1, 1, (count, 2))
    return P, Y0


@pytest.mark.parametrize("vector", [True, False])
def test_double_pendulum_ensemble_equals_member_by_member(pendulum2, vector):
    """Initial angles and the upper rod's length drawn per member (11 members: not a multiple
    of the lanes); 2 s chaotic motion; energy conserved to 1e-7."""
    module = _module(pendulum2)
    P, Y0 = _inputs(pendulum2, 11, l1=np.linspace(0.5, 1.5, 11))
    grid = np.linspace(0.0, 2.0, 41)
    run = integrate_ensemble(module, P, Y0, grid, RTOL, ATOL, trajectories=True, vector=vector)
    _assert_same(run, _one_by_one(module, P, Y0, grid), rtol=1e-9)
    assert np.all(run.status == 0) and np.all(run.drift < 1e-7)


def test_lanes_ending_at_different_times(pendulum2, libm_module):
    """Members needing from tens to thousands of steps (g from 0.1 to 1000, amplitudes from
    1e-3 to 1 rad), shuffled: each lane takes a new member when its own ends, and every member
    equals its run alone to the last bit."""
    module = libm_module
    assert module.lanes > 1
    rng = np.random.default_rng(3)
    g = rng.permutation(np.geomspace(0.1, 1000.0, 13))
    P, Y0 = _inputs(pendulum2, 13, g=g)
    Y0[:, :2] *= rng.permutation(np.geomspace(1e-3, 1.0, 13))[:, None]
    grid = np.linspace(0.0, 3.0, 31)
    steps = [module.dop853(p, 0.0, 3.0, y0, RTOL, ATOL, grid, 10**7)[3]
             for p, y0 in zip(P, Y0, strict=True)]
    assert max(steps) > 20 * min(steps)
    run = integrate_ensemble(module, P, Y0, grid, RTOL, ATOL, trajectories=True)
    _assert_same(run, _one_by_one(module, P, Y0, grid), rtol=0)


def test_failing_members_are_recorded_while_the_rest_complete(pendulum2, libm_module):
    """A member with massless rods (M = 0, singular) fails at its first step; with a step
    limit, the members needing more steps fail where the loop alone would, and the others
    finish as if alone (to the last bit)."""
    module = libm_module
    P, Y0 = _inputs(pendulum2, 9, seed=5)
    P[4, 0] = P[4, 1] = 0.0  # m1 = m2 = 0
    grid = np.linspace(0.0, 2.0, 21)
    run = integrate_ensemble(module, P, Y0, grid, RTOL, ATOL, trajectories=True)
    assert run.status[4] == 3 and run.t_reached[4] == 0.0  # singular mass matrix at t = 0
    assert np.all(np.isnan(run.final[4])) and np.isnan(run.drift[4])
    assert np.all(np.delete(run.status, 4) == 0)
    _assert_same(run, _one_by_one(module, P, Y0, grid), rtol=0)

    steps = [module.dop853(p, 0.0, 2.0, y0, RTOL, ATOL, grid, 10**7)[3]
             for p, y0 in zip(P, Y0, strict=True) if p[0] > 0]
    limit = int(np.median(steps))
    run = integrate_ensemble(module, P, Y0, grid, RTOL, ATOL, max_steps=limit, trajectories=True)
    alone = _one_by_one(module, P, Y0, grid, max_steps=limit)
    assert {1, 0} <= set(run.status.tolist())  # some hit the limit (code 1), some finished
    _assert_same(run, alone, rtol=0)


def test_vector_lanes_equal_the_scalar_loop_bit_for_bit_with_libm_trig(pendulum2, libm_module):
    """With libm's sin and cos the lanes give the scalar batched loop's numbers exactly."""
    assert libm_module.lanes > 1
    P, Y0 = _inputs(pendulum2, 7, seed=2, m2=np.linspace(0.5, 2.0, 7))
    P[3, 2] = 0.0  # l1 = 0: M singular
    grid = np.linspace(0.0, 2.0, 21)
    lanes = integrate_ensemble(libm_module, P, Y0, grid, RTOL, ATOL, trajectories=True)
    alone = integrate_ensemble(libm_module, P, Y0, grid, RTOL, ATOL, trajectories=True,
                               vector=False)
    for a, b in zip(dataclasses.astuple(lanes), dataclasses.astuple(alone), strict=True):
        np.testing.assert_array_equal(a, b)
    assert lanes.status[3] == 3


def test_small_oscillations_follow_the_closed_form():
    """Pendulum at 1e-4 rad: theta(t) = theta0 cos(sqrt(g/L) t), L varied per member."""
    system = lagrangian.load("pendulum")
    module = _module(system)
    lengths = np.linspace(0.2, 2.0, 6)
    P = np.tile([1.0, 0.5, 9.81], (6, 1))
    P[:, 1] = lengths
    theta0 = 1e-4
    Y0 = np.tile([theta0, 0.0], (6, 1))
    grid = np.linspace(0.0, 3.0, 301)
    run = integrate_ensemble(module, P, Y0, grid, 1e-12, 1e-14, trajectories=True)
    expected = theta0 * np.cos(np.sqrt(9.81 / lengths)[:, None] * grid)
    np.testing.assert_allclose(run.trajectory[:, :, 0], expected, rtol=0, atol=1e-7 * theta0)
    np.testing.assert_allclose(run.maximum[:, 0], expected.max(axis=1), rtol=1e-7)
    np.testing.assert_allclose(run.minimum[:, 0], expected.min(axis=1), rtol=1e-7)
    np.testing.assert_allclose(run.final, np.stack([expected[:, -1], -theta0 * np.sqrt(
        9.81 / lengths) * np.sin(np.sqrt(9.81 / lengths) * 3.0)], axis=1), atol=1e-7 * theta0 * 10)


def test_models_without_a_vector_kernel_run_member_by_member(tmp_path):
    """V = k |x| gives the force -k sign(x), which has no vector version: the module has one
    lane and the ensemble is the loop itself. Closed form: from rest at x0 the mass returns
    after 4 sqrt(2 m x0 / k)."""
    model = tmp_path / "vee.toml"
    model.write_text('name = "V-shaped well"\n'
                     '[coordinates]\nx = { unit = "m", initial = 0.1, rate = 0.0 }\n'
                     '[parameters]\nm = { value = 1.0, unit = "kg" }\n'
                     'k = { value = 2.0, unit = "N" }\n'
                     '[energy]\nT = "1/2*m*x_dot^2"\nV = "k*abs(x)"\n')
    system = lagrangian.load(model)
    module = _module(system)
    assert module.lanes == 1
    x0 = np.array([0.05, 0.1, 0.2])
    P = np.tile([1.0, 2.0], (3, 1))
    Y0 = np.stack([x0, np.zeros(3)], axis=1)
    period = 4 * np.sqrt(2 * 1.0 * x0 / 2.0)
    for i in range(3):
        grid = np.linspace(0.0, period[i], 11)
        run = integrate_ensemble(module, P[i:i + 1], Y0[i:i + 1], grid, 1e-10, 1e-12)
        assert run.final[0, 0] == pytest.approx(x0[i], rel=1e-6)
        assert run.maximum[0, 0] == pytest.approx(x0[i], rel=1e-9)
        assert run.minimum[0, 0] == pytest.approx(-x0[i], rel=1e-6)
    grid = np.linspace(0.0, 2.0, 11)
    run = integrate_ensemble(module, P, Y0, grid, RTOL, ATOL, trajectories=True)
    _assert_same(run, _one_by_one(module, P, Y0, grid), rtol=1e-12)
