"""simulate(canonical=True): Hamilton's equations integrated in (q, p), against closed forms and
the run in (q, q_dot)."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from conserved_models import spherical_pendulum
from lagrangian.errors import InputError

SPHERICAL = spherical_pendulum(theta_dot=0.3)


@pytest.fixture(scope="module")
def double():
    system = lagrangian.load("double_pendulum")
    return system, system.simulate(4.0, canonical=True, samples=201), system.simulate(
        4.0, samples=201)


@pytest.fixture(scope="module")
def spherical(tmp_path_factory):
    path = tmp_path_factory.mktemp("canonical") / "spherical.toml"
    path.write_text(SPHERICAL)
    system = lagrangian.load(path)
    return system, system.simulate(3.0, canonical=True, samples=151)


def test_the_double_pendulum_in_q_p_follows_the_run_in_q_q_dot(double):
    _, hamilton, lagrange = double
    assert hamilton.status == "finished" and "(q, p)" in hamilton.backend
    np.testing.assert_allclose(hamilton.q, lagrange.q, atol=1e-6)
    np.testing.assert_allclose(hamilton.q_dot, lagrange.q_dot, atol=1e-5)
    assert np.ptp(hamilton.energy) < 1e-6  # T + V kept: no loads, no drive


def test_the_double_pendulum_momenta_are_m_q_dot(double):
    """p = M(q) q_dot with the closed-form M of two point masses on rods (m = l = 1 here)."""
    system, run, _ = double
    m1, m2, l1, l2 = (system.parameters[k] for k in ("m1", "m2", "l1", "l2"))
    c = np.cos(run.q[:, 0] - run.q[:, 1])
    p1 = (m1 + m2) * l1 ** 2 * run.q_dot[:, 0] + m2 * l1 * l2 * c * run.q_dot[:, 1]
    p2 = m2 * l1 * l2 * c * run.q_dot[:, 0] + m2 * l2 ** 2 * run.q_dot[:, 1]
    np.testing.assert_allclose(run.momenta, np.column_stack([p1, p2]), atol=1e-10)
    np.testing.assert_array_equal(run["p_theta1"], run.momenta[:, 0])


def test_a_cyclic_momentum_stays_fixed_in_q_p(spherical):
    """phi is cyclic: p_phi = m l^2 sin^2(theta) phi_dot has p_phi_dot = dL/dphi = 0 exactly, so
    the run in (q, p) keeps it to rounding while theta swings."""
    system, run = spherical
    m, l = system.parameters["m"], system.parameters["l"]
    p_phi = m * l ** 2 * np.sin(run.q[:, 0]) ** 2 * run.q_dot[:, 1]
    start = m * l ** 2 * np.sin(0.6) ** 2 * 1.0
    np.testing.assert_allclose(run["p_phi"], start, rtol=0, atol=1e-13)
    np.testing.assert_allclose(p_phi, start, rtol=1e-9)
    assert np.ptp(run.q[:, 0]) > 0.05  # it does swing
    assert np.ptp(run.energy) < 1e-7


def test_what_a_run_in_q_p_does_not_take_is_refused_in_one_line(spherical, double):
    system = double[0]
    with pytest.raises(InputError, match="canonical is True or False"):
        system.simulate(1.0, canonical="yes")
    with pytest.raises(InputError, match="no controller"):
        system.simulate(1.0, canonical=True, controller=lambda t, q, v: np.zeros(2))
    with pytest.raises(InputError, match="impacts"):
        lagrangian.load("bouncing_ball").simulate(1.0, canonical=True)
