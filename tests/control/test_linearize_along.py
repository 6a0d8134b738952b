"""System.linearize_along: A(t), B(t) at a run's samples, against the pendulum's closed form and
against the run itself (a perturbed run's difference follows the transition matrix of A(t))."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

import lagrangian
from lagrangian.errors import InputError


def test_pendulum_along_a_swing_is_the_closed_form():
    """x = (theta, theta_dot): A = [[0, 1], [-g/L cos theta(t), 0]], B = [[0], [1/(m L^2)]]."""
    pendulum = lagrangian.load("pendulum")
    run = pendulum.simulate(2, initial={"theta": 1.0}, samples=51)
    along = pendulum.linearize_along(run)
    assert along.A.shape == (51, 2, 2) and along.B.shape == (51, 2, 1)
    m, L, g = 1.0, 0.5, 9.81
    np.testing.assert_allclose(along.A[:, 1, 0], -g / L * np.cos(run.q[:, 0]), rtol=1e-12)
    np.testing.assert_allclose(along.A[:, 0, 1], 1.0)
    np.testing.assert_allclose(along.B[:, 1, 0], 1 / (m * L**2), rtol=1e-12)


def test_a_perturbed_double_pendulum_follows_the_transition_matrix_of_a_of_t():
    system = lagrangian.load("double_pendulum")
    start = {"theta1": 0.8, "theta2": -0.4}
    run = system.simulate(1, initial=start, samples=2001, rtol=1e-12, atol=1e-12)
    along = system.linearize_along(run)
    transition = np.eye(4)
    for k in range(len(run.t) - 1):  # midpoint exponentials: second order in the spacing
        step = (along.A[k] + along.A[k + 1]) / 2 * (run.t[k + 1] - run.t[k])
        transition = scipy.linalg.expm(step) @ transition
    delta = 1e-6 * np.array([1.0, -0.5, 0.3, 0.2])
    moved = system.simulate(1, initial={"theta1": 0.8 + delta[0], "theta2": -0.4 + delta[1],
                                        "theta1_dot": delta[2], "theta2_dot": delta[3]},
                            samples=2001, rtol=1e-12, atol=1e-12)
    difference = np.concatenate([moved.q[-1] - run.q[-1], moved.q_dot[-1] - run.q_dot[-1]])
    assert np.linalg.norm(difference - transition @ delta) < 1e-3 * np.linalg.norm(difference)


def test_linearize_along_refuses_a_foreign_run_and_unknown_inputs():
    pendulum = lagrangian.load("pendulum")
    run = lagrangian.load("double_pendulum").simulate(0.1, samples=3)
    with pytest.raises(InputError, match="not of this system") as caught:
        pendulum.linearize_along(run)
    assert caught.value.field == "simulation"
    with pytest.raises(InputError, match="'phi' is not a coordinate"):
        pendulum.linearize_along(pendulum.simulate(0.1, samples=3), inputs=["phi"])


def test_a_constrained_run_is_linearized_through_its_multipliers():
    """The pendulum in Cartesian coordinates hanging at rest: A's oscillating pair is
    +-i sqrt(g/L) at every sample (the other two eigenvalues 0: off the rod, Phi_ddot = 0)."""
    system = lagrangian.load("cartesian_pendulum")
    run = system.simulate(0.5, initial={"x": 0.0, "y": -0.5}, samples=5)
    along = system.linearize_along(run, inputs=["x"])
    assert along.A.shape == (5, 4, 4) and along.B.shape == (5, 4, 1)
    for A in along.A:
        eigenvalues = np.sort_complex(np.linalg.eigvals(A))
        assert eigenvalues.imag.max() == pytest.approx(np.sqrt(9.81 / 0.5), rel=1e-12)
        assert np.abs(eigenvalues.real).max() < 1e-9
    np.testing.assert_allclose(along.B[:, 2, 0], 1.0, rtol=1e-12)  # 1/m on x, none on y
    np.testing.assert_allclose(along.B[:, 3, 0], 0.0, atol=1e-12)


def perturbed_pendulum_runs():
    """(system, run, moved): the Cartesian pendulum swinging from 0.3 m aside, and again turned
    by 2e-6 rad along the rod's circle, 2001 samples over 1 s."""
    system = lagrangian.load("cartesian_pendulum")
    L, angle = 0.5, np.arcsin(0.3 / 0.5)
    options = {"samples": 2001, "rtol": 1e-12, "atol": 1e-12}
    run = system.simulate(1, initial={"x": L * np.sin(angle), "y": -L * np.cos(angle)},
                          **options)
    moved = system.simulate(1, initial={"x": L * np.sin(angle + 2e-6),
                                        "y": -L * np.cos(angle + 2e-6)}, **options)
    return system, run, moved


def transition_matrix(along, t) -> np.ndarray:
    """Phi(t[-1], t[0]) of x_dot = A(t) x, A held at its mean over each sample interval."""
    transition = np.eye(along.A.shape[-1])
    for k in range(len(t) - 1):
        step = (along.A[k] + along.A[k + 1]) / 2 * (t[k + 1] - t[k])
        transition = scipy.linalg.expm(step) @ transition
    return transition


def test_a_perturbed_constrained_run_follows_the_transition_matrix_of_a_of_t():
    """The perturbed pendulum's difference from the first run is Phi(t) of A(t) times the
    first difference."""
    system, run, moved = perturbed_pendulum_runs()
    transition = transition_matrix(system.linearize_along(run), run.t)
    delta = np.concatenate([moved.q[0] - run.q[0], [0.0, 0.0]])
    difference = np.concatenate([moved.q[-1] - run.q[-1], moved.q_dot[-1] - run.q_dot[-1]])
    assert np.linalg.norm(difference - transition @ delta) < 1e-4 * np.linalg.norm(difference)


def test_explicit_time_is_read_at_each_samples_time():
    """The pendulum on a support moving as A cos(Omega t): A(t) equals central differences of
    the run's right-hand side at each sample's own t (not at t = 0)."""
    system = lagrangian.load("support_pendulum")
    run = system.simulate(2, samples=5)
    along = system.linearize_along(run)
    functions, h = system.numeric(), 1e-6
    for k, t in enumerate(run.t):
        y = np.concatenate([run.q[k], run.q_dot[k]])
        columns = [(functions.rhs(t, y + e) - functions.rhs(t, y - e)) / (2 * h)
                   for e in h * np.eye(len(y))]
        np.testing.assert_allclose(along.A[k], np.stack(columns, axis=-1), atol=1e-7)
