"""The compiled DOP853 integrator against closed forms and against scipy's DOP853."""

from __future__ import annotations

import signal

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import ellipk

import lagrangian
from lagrangian.compile import compiled
from lagrangian.simulation.compiled_loop import FastResult, integrate_fast

pytestmark = pytest.mark.skipif(not compiled.available(), reason="no C compiler / Python headers")


def test_large_amplitude_pendulum_period_matches_the_elliptic_integral():
    """T = 4 sqrt(L/g) K(sin(theta0/2)) for theta0 = 170 deg, to 1e-8 relative."""
    functions = lagrangian.load("pendulum").numeric(backend="c")
    L, g, theta0 = 0.5, 9.81, np.radians(170.0)
    period = 4 * np.sqrt(L / g) * ellipk(np.sin(theta0 / 2) ** 2)  # scipy's K takes m = k^2
    result = integrate_fast(functions, (0.0, period), np.array([theta0, 0.0]), rtol=1e-12, atol=1e-12,
                            t_eval=np.array([0.0, period / 2, period]))
    assert result.success, result.message
    np.testing.assert_allclose(result.t, [0.0, period / 2, period])
    theta, rate = result.y[:, 0], result.y[:, 1]
    assert theta[1] == pytest.approx(-theta0, abs=1e-8)
    # at t = T the bob is back at rest at theta0: the period error is rate / |theta_ddot|
    period_error = abs(rate[2]) / (g / L * np.sin(theta0))
    assert period_error / period < 1e-8
    assert theta[2] == pytest.approx(theta0, abs=1e-8)


@pytest.mark.parametrize("y0, tolerance", [
    ((1.0, 0.5, 0.0, 0.0), 1e-10),  # the model file's initial state
    ((1.2, -0.6, 0.0, 2.0), 1e-12),  # chaotic: at 1e-10 scipy's DOP853 drifts 1.7e-9 too
])
def test_double_pendulum_conserves_energy_over_ten_seconds(y0, tolerance):
    functions = lagrangian.load("double_pendulum").numeric(backend="c")
    result = integrate_fast(functions, (0.0, 10.0), np.array(y0), rtol=tolerance, atol=tolerance)
    assert result.success and result.t[-1] == 10.0
    energy = functions.energy(result.y[:, :2], result.y[:, 2:])
    assert np.max(np.abs(energy - energy[0])) / abs(energy[0]) < 1e-9


@pytest.mark.parametrize("t_eval", [None, np.linspace(0.0, 5.0, 51)])
def test_same_steps_and_answers_as_scipy_dop853(t_eval):
    functions = lagrangian.load("double_pendulum").numeric(backend="c")
    y0 = np.array([1.0, 0.5, 0.0, 0.0])
    ours = integrate_fast(functions, (0.0, 5.0), y0, rtol=1e-9, atol=1e-9, t_eval=t_eval)
    scipy = solve_ivp(functions.rhs, (0.0, 5.0), y0, method="DOP853", rtol=1e-9, atol=1e-9, t_eval=t_eval)
    assert isinstance(ours, FastResult) and ours.success
    # the same method and error control: step for step the same run
    assert abs(ours.nfev - scipy.nfev) <= 0.02 * scipy.nfev
    assert ours.t.shape == scipy.t.shape and ours.y.shape == (len(scipy.t), 4)
    np.testing.assert_allclose(ours.t, scipy.t, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(ours.y, scipy.y.T, rtol=1e-6, atol=1e-6)
    if t_eval is not None:
        assert ours.nfev == scipy.nfev  # dense output costs 3 extra calls per step, as in scipy
    else:
        assert ours.steps == len(scipy.t) - 1  # every accepted step is recorded


def test_backward_in_time_matches_scipy():
    functions = lagrangian.load("pendulum").numeric(backend="c")
    y0 = np.array([2.0, 0.5])
    ours = integrate_fast(functions, (3.0, 0.0), y0, rtol=1e-10, atol=1e-10)
    scipy = solve_ivp(functions.rhs, (3.0, 0.0), y0, method="DOP853", rtol=1e-10, atol=1e-10)
    assert ours.success and ours.t[-1] == 0.0 and np.all(np.diff(ours.t) < 0)
    np.testing.assert_allclose(ours.y[-1], scipy.y[:, -1], rtol=1e-7, atol=1e-8)


def test_harmonic_oscillator_closed_form():
    b = lagrangian.SystemBuilder("oscillator")
    x = b.coordinate("x")
    m, k = b.parameter("m", 2.0), b.parameter("k", 8.0)
    b.add_kinetic_energy(m * b.velocity(x) ** 2 / 2).add_potential_energy(k * x**2 / 2)
    functions = b.build().numeric(backend="c")
    t = np.linspace(0.0, 10.0, 201)
    result = integrate_fast(functions, (0.0, 10.0), np.array([0.1, 0.0]), rtol=1e-11, atol=1e-13, t_eval=t)
    np.testing.assert_allclose(result.y[:, 0], 0.1 * np.cos(2.0 * t), atol=1e-10)
    np.testing.assert_allclose(result.y[:, 1], -0.2 * np.sin(2.0 * t), atol=1e-10)


def test_not_used_for_constrained_models_or_without_the_c_backend():
    constrained = lagrangian.load("cartesian_pendulum").numeric(backend="c")
    assert integrate_fast(constrained, (0, 1), np.zeros(4), rtol=1e-8, atol=1e-8) is None
    numpy_only = lagrangian.load("pendulum").numeric(backend="numpy")
    assert integrate_fast(numpy_only, (0, 1), np.array([0.1, 0.0]), rtol=1e-8, atol=1e-8) is None


def test_step_limit_keeps_the_partial_result():
    functions = lagrangian.load("double_pendulum").numeric(backend="c")
    result = integrate_fast(functions, (0.0, 10.0), np.array([1.0, 0.5, 0.0, 0.0]), rtol=1e-10,
                            atol=1e-10, max_steps=10)
    assert not result.success
    assert result.message.startswith("Reached the limit of 10 steps at t = ")
    assert len(result.t) == 11 and 0 < result.t[-1] < 10.0
    # two calls to start (f0, initial step), then 12 a step attempt (rejected ones included)
    assert (result.nfev - 2) % 12 == 0 and result.nfev >= 2 + 12 * 10


def test_singular_mass_matrix_on_the_way_stops_with_the_time_reached():
    """x = s^2 with s -> 0: M = 4 m s^2 becomes singular; the states so far are kept."""
    b = lagrangian.SystemBuilder("bead through the singular point")
    s = b.coordinate("s")
    b.add_particle("bead", b.parameter("m", 1.0), (s**2, 0))
    functions = b.build().numeric(backend="c")
    result = integrate_fast(functions, (0.0, 5.0), np.array([1.0, -1.0]), rtol=1e-8, atol=1e-8)
    assert not result.success
    assert "at t = " in result.message
    assert ("Singular" in result.message) or ("step size" in result.message)
    assert len(result.t) > 5 and result.t[-1] < 5.0
    # x = s^2 moves at constant speed 2 s s_dot = -2 until the bead reaches the origin at t = 0.5
    x = result.y[:, 0] ** 2
    np.testing.assert_allclose(x[result.t < 0.45], 1.0 - 2.0 * result.t[result.t < 0.45], atol=1e-6)


def test_bad_arguments_are_rejected():
    functions = lagrangian.load("pendulum").numeric(backend="c")
    with pytest.raises(ValueError, match="y0 must hold 2 numbers"):
        integrate_fast(functions, (0, 1), np.zeros(3), rtol=1e-6, atol=1e-6)
    with pytest.raises(ValueError, match="not within t_span"):
        integrate_fast(functions, (0, 1), np.zeros(2), rtol=1e-6, atol=1e-6, t_eval=np.array([2.0]))
    with pytest.raises(ValueError, match="not properly sorted"):
        integrate_fast(functions, (0, 1), np.zeros(2), rtol=1e-6, atol=1e-6, t_eval=np.array([0.5, 0.2]))
    with pytest.raises(ValueError, match="rtol must be positive"):
        integrate_fast(functions, (0, 1), np.zeros(2), rtol=0.0, atol=1e-6)


def test_ctrl_c_stops_the_compiled_loop_and_keeps_what_was_computed():
    import _thread
    import threading

    functions = lagrangian.load("double_pendulum").numeric(backend="c")
    # Python installs its Ctrl-C handler only where SIGINT came in at its default: a suite run
    # as a background job inherits it ignored, and interrupt_main() then does nothing
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.2, _thread.interrupt_main)  # what Ctrl-C does to the main thread
    timer.start()
    try:
        result = integrate_fast(functions, (0.0, 1e6), np.array([1.0, 0.5, 0.0, 0.0]), rtol=1e-12,
                                atol=1e-12)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    assert not result.success
    assert result.message.startswith("Interrupted at t = ")
    assert 0.0 < result.t[-1] < 1e6 and len(result.t) == len(result.y) > 100
    energy = functions.energy(result.y[:, :2], result.y[:, 2:])
    assert np.max(np.abs(energy - energy[0])) / abs(energy[0]) < 1e-8  # a valid partial run
