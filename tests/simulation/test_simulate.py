"""Simulation against closed forms, conservation laws and constraint residuals (SI units)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import ellipk

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.output.simulation import simulation_summary
from lagrangian.simulation.simulate import SaveAt, StepControl, parse_stop_condition, simulate

pytestmark = pytest.mark.smoke  # pytest -m smoke: the quick subset

G = 9.81


def run(example, t_end, *, method="DOP853", rtol=1e-9, atol=1e-9, samples=1001, stop_when=None,
        fast=True, **options):
    eom = lagrangian.load(example).equations_of_motion()
    stop = parse_stop_condition(stop_when, eom.model) if stop_when else None
    return simulate(eom, t_end, step_control=StepControl(method, rtol, atol),
                    save_at=SaveAt(samples), stop=stop, compiled_loop=fast, **options)


def test_large_amplitude_pendulum_period_matches_the_elliptic_integral():
    """T = 4 sqrt(L/g) K(k^2), k = sin(theta0/2); released at rest at +170 deg, theta_dot turns
    positive again for the first time at the far end of the swing, T/2 later."""
    theta0 = math.radians(170)
    result = run("pendulum", 10, initial={"theta": theta0, "theta_dot": 0.0}, rtol=1e-12,
                 atol=1e-12, stop_when="theta_dot > 0")
    period = 4 * math.sqrt(0.5 / G) * ellipk(math.sin(theta0 / 2) ** 2)
    assert result.status == "stopped"
    assert abs(2 * result.t[-1] - period) / period < 1e-8
    assert result.q[-1, 0] == pytest.approx(-theta0, abs=1e-8)


@pytest.mark.parametrize("fast", [True, False])
def test_double_pendulum_conserves_energy_over_ten_seconds(fast):
    result = run("double_pendulum", 10, rtol=1e-12, atol=1e-12, fast=fast)
    assert result.status == "finished" and result.t[-1] == 10.0
    assert result.energy_conserved
    assert result.energy_drift < 1e-9
    assert np.all(result.power == 0)


def test_compiled_loop_and_scipy_agree_on_the_double_pendulum():
    fast = run("double_pendulum", 3, rtol=1e-12, atol=1e-12, fast=True)
    slow = run("double_pendulum", 3, rtol=1e-12, atol=1e-12, fast=False)
    assert slow.backend == "scipy"
    np.testing.assert_allclose(fast.q, slow.q, atol=1e-8)


@pytest.mark.parametrize("method", ["DOP853", "Radau"])
def test_cartesian_pendulum_stays_on_the_rod_and_its_tension_is_the_multiplier(method):
    """M q_ddot + Phi_q^T lambda = f with Phi = x^2 + y^2 - L^2, M = m I, f = (0, -m g).

    The rod force on the bob is -Phi_q^T lambda = -2 lambda (x, y) = -2 L lambda r_hat, so the
    tension (pulling inward) is 2 L lambda. Radially, m (-L theta_dot^2) = -T + m g cos(theta)
    with cos(theta) = -y/L, hence lambda = (m g cos(theta) + m L theta_dot^2) / (2 L), where
    L theta_dot = |v|.
    """
    m, L = 1.0, 0.5
    result = run("cartesian_pendulum", 10, rtol=1e-10, atol=1e-10, method=method)
    assert result.status == "finished"
    assert result.max_residual < 1e-9
    x, y = result.q.T
    speed_squared = np.sum(result.q_dot**2, axis=1)
    tension = m * G * (-y / L) + m * speed_squared / L
    np.testing.assert_allclose(result.multipliers[:, 0], tension / (2 * L), rtol=1e-7)
    # radial velocity stays zero too (velocity-level projection)
    assert np.max(np.abs(np.sum(result.q * result.q_dot, axis=1))) < 1e-8


def test_cartesian_pendulum_follows_the_angle_pendulum():
    """Two independent descriptions of one pendulum agree: x = L sin(theta), y = -L cos(theta)."""
    cartesian = run("cartesian_pendulum", 3, rtol=1e-11, atol=1e-11)
    theta0 = math.atan2(cartesian.q[0, 0], -cartesian.q[0, 1])
    angle = run("pendulum", 3, initial={"theta": theta0, "theta_dot": 0.0}, rtol=1e-11,
                atol=1e-11, fast=False)
    np.testing.assert_allclose(cartesian.q[:, 0], 0.5 * np.sin(angle.q[:, 0]), atol=1e-8)
    np.testing.assert_allclose(cartesian.q[:, 1], -0.5 * np.cos(angle.q[:, 0]), atol=1e-8)


@pytest.mark.parametrize("method", ["DOP853", "BDF"])
def test_rolling_cylinder_accelerates_at_two_thirds_g_sin_alpha(method):
    """m x_ddot + lambda = m g sin(alpha), (m R^2/2) phi_ddot - R lambda = 0, x_dot = R phi_dot:
    x_ddot = 2/3 g sin(alpha) and the friction reaction lambda = 1/3 m g sin(alpha)."""
    m, R, alpha = 2.0, 0.1, math.radians(30)
    result = run("rolling_cylinder", 2, rtol=1e-10, atol=1e-10, method=method)
    a = 2 / 3 * G * math.sin(alpha)
    np.testing.assert_allclose(result.q[:, 0], 0.5 * a * result.t**2, rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(result.q_dot[:, 1], result.q_dot[:, 0] / R, rtol=1e-8, atol=1e-9)
    np.testing.assert_allclose(result.multipliers[:, 0], m * G * math.sin(alpha) / 3, rtol=1e-9)
    assert result.max_residual < 1e-9
    assert result.energy_conserved and result.energy_drift < 1e-8  # rolling does no work


def test_atwood_machine_accelerates_uniformly():
    m1, m2, I, R = 3.0, 2.0, 0.01, 0.1
    result = run("atwood", 2, rtol=1e-11, atol=1e-11)
    a = (m1 - m2) * G / (m1 + m2 + I / R**2)
    np.testing.assert_allclose(result.q[:, 0], 0.5 * a * result.t**2, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(result.q_dot[:, 0], a * result.t, rtol=1e-9, atol=1e-12)


def test_damped_oscillator_decays_as_exp_minus_zeta_omega_t():
    """m = 1, k = 4, c = 0.4: omega_n = 2, zeta = 0.1; released from x0 = 0.1 at rest."""
    omega, zeta, x0 = 2.0, 0.1, 0.1
    result = run("damped_oscillator", 10, rtol=1e-11, atol=1e-12)
    wd = omega * math.sqrt(1 - zeta**2)
    t = result.t
    exact = x0 * np.exp(-zeta * omega * t) * (np.cos(wd * t) + zeta / math.sqrt(1 - zeta**2)
                                              * np.sin(wd * t))
    np.testing.assert_allclose(result.q[:, 0], exact, atol=1e-9)
    # amplitude: successive maxima one damped period apart shrink by exp(-zeta omega T_d)
    x = result.q[:, 0]
    peaks = [i for i in range(1, len(x) - 1) if x[i - 1] < x[i] >= x[i + 1]]
    ratio = x[peaks[1]] / x[peaks[0]]
    assert ratio == pytest.approx(math.exp(-zeta * omega * 2 * math.pi / wd), rel=1e-3)
    # the damper's power is -c x_dot^2, and it is what the energy loses
    np.testing.assert_allclose(result.power, -0.4 * result.q_dot[:, 0] ** 2, atol=1e-15)
    lost = np.concatenate([[0], np.cumsum(np.diff(t) * (result.power[1:] + result.power[:-1]) / 2)])
    np.testing.assert_allclose(result.energy - result.energy[0], lost, atol=1e-6)
    assert not result.energy_conserved and result.energy_drift is None


def test_initial_state_off_the_constraint_is_projected_holding_the_given_values():
    """x = 0.3 and x_dot = 1 given on the rod L = 0.5: y = -0.4 and y_dot = -x x_dot / y = 0.75."""
    result = run("cartesian_pendulum", 0.1, initial={"x": 0.3, "x_dot": 1.0})
    assert result.q[0] == pytest.approx([0.3, -0.4], abs=1e-12)
    assert result.q_dot[0] == pytest.approx([1.0, 0.75], abs=1e-12)
    assert set(result.projected_initial_state) == {"y", "y_dot"}
    given, used = result.projected_initial_state["y"]
    assert given == pytest.approx(-0.47766824456280375) and used == pytest.approx(-0.4)
    summary = simulation_summary(result)["projected_initial_state"]["y_dot"]
    assert summary == {"given": 0.0, "used": pytest.approx(0.75, abs=1e-12)}


def test_initial_velocity_breaking_rolling_is_projected_onto_no_slip():
    result = run("rolling_cylinder", 0.1, initial={"x_dot": 1.0})
    assert result.q_dot[0] == pytest.approx([1.0, 10.0])
    assert result.projected_initial_state == {"phi_dot": (0.0, 10.0)}


def test_consistent_initial_state_is_not_reported_as_projected():
    assert run("slider_crank", 0.05).projected_initial_state == {}


def test_ctrl_c_keeps_what_was_computed():
    def progress(t):
        if t > 0.5:
            raise KeyboardInterrupt

    result = run("cartesian_pendulum", 10, progress=progress)
    assert result.status == "interrupted" and not result.completed
    assert 0.5 < result.t[-1] < 10 and "interrupted" in result.message
    assert len(result.t) > 10 and np.all(np.diff(result.t) > 0)
    assert f"t = {result.t[-1]:.9g} s" in result.message


def test_a_failing_integration_stops_with_the_time_reached_and_the_partial_result():
    """T = x^2 x_dot^2 / 2: the mass matrix x^2 vanishes when x reaches 0 (at t = pi/2)."""
    system = lagrangian.SystemBuilder("singular")
    x = system.coordinate("x", initial=1.0, rate=0.0)
    system.add_kinetic_energy(x**2 * system.velocity(x) ** 2 / 2).add_potential_energy(x**2 / 2)
    eom = system.build().equations_of_motion()
    for method in ("RK45", "Radau"):
        result = simulate(eom, 5, step_control=StepControl(method))
        assert result.status == "failed"
        assert "stopped at t = " in result.message
        assert 0.5 < result.t[-1] <= 1.01 and len(result.t) > 10


def test_stop_condition_grammar():
    model = lagrangian.load("double_pendulum").model
    condition = parse_stop_condition("theta2 - theta1 >= l1*0.5", model)
    assert condition.operator == ">="
    for text, message in [
        ("__import__('os') < 1", "unknown function '__import__'"),
        ("__import__('os').system('true') < 1", "only the functions sin, cos"),
        ("theta1", "found no comparison"),
        ("0 < theta1 < 1", "found 2 comparisons"),
        ("theta1 == 0", "'==' is not allowed"),
        ("theta1 < ", "the right side of 'theta1 < ' is empty"),
        ("phi < 0", "unknown name 'phi'"),
        ("theta1.real < 0", "attribute access"),
    ]:
        with pytest.raises(ModelError, match="--stop-when") as info:
            parse_stop_condition(text, model, field="--stop-when")
        assert message in str(info.value)


def test_stop_condition_with_time_and_quarter_period():
    """A small swing crosses theta = 0 a quarter period after release: pi/2 sqrt(L/g)."""
    result = run("pendulum", 5, initial={"theta": 1e-4}, stop_when="theta < 0", rtol=1e-12,
                 atol=1e-12)
    assert result.t[-1] == pytest.approx(math.pi / 2 * math.sqrt(0.5 / G), rel=1e-6)
    timed = run("pendulum", 5, stop_when="t >= 1.25")
    assert timed.status == "stopped" and timed.t[-1] == pytest.approx(1.25, abs=1e-12)


def test_bad_arguments_are_reported():
    with pytest.raises(ModelError, match="unknown method 'Euler'"):
        run("pendulum", 1, method="Euler")
    with pytest.raises(ModelError, match="'phi' is not a coordinate or velocity"):
        run("pendulum", 1, initial={"phi": 1.0})
    with pytest.raises(ModelError, match="must be after the start time"):
        run("pendulum", 0)


def test_columns_are_named_as_documented():
    result = run("slider_crank", 0.05)
    assert list(result.columns()) == [
        "t", "theta", "phi", "x", "theta_dot", "phi_dot", "x_dot", "energy",
        "lambda_loop_y", "lambda_loop_x", "residual_loop_y", "residual_loop_x", "power"]


def test_ctrl_c_in_the_compiled_loop_keeps_what_was_computed(monkeypatch):
    """A run that looks long (a clock that jumps 10 s a reading) goes in pieces with progress."""
    import lagrangian.simulation.simulate as module

    if run("double_pendulum", 0.1, samples=3).backend != "compiled":
        pytest.skip("no compiled integration loop here (no C compiler)")
    clock = iter(range(0, 10**6, 10))
    monkeypatch.setattr(module.time, "perf_counter", lambda: float(next(clock)))
    reached = []

    def progress(t):
        reached.append(t)
        if t > 3:
            raise KeyboardInterrupt

    result = run("double_pendulum", 10, samples=1001, progress=progress)
    assert result.backend == "compiled" and result.status == "interrupted"
    assert len(reached) > 3 and 3 < result.t[-1] < 4
    assert np.allclose(np.diff(result.t), 0.01)  # the samples computed so far, none repeated
    whole = run("double_pendulum", 10, samples=1001)
    np.testing.assert_allclose(result.q, whole.q[: len(result.t)], atol=1e-7)


@pytest.mark.parametrize("method", ["BDF", "LSODA"])
def test_multistep_solvers_are_restarted_from_projected_states_without_crawling(method):
    """Restarts drop BDF/LSODA to order 1; spacing them out keeps the step count sane."""
    result = run("cartesian_pendulum", 10, rtol=1e-10, atol=1e-10, method=method)
    assert result.status == "finished"
    assert result.steps < 20_000  # about 4,000 for BDF; restarting every step took 900,000
    assert result.max_residual < 1e-9
