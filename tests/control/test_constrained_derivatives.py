"""Forward dynamics' derivatives of constrained model files, through the multipliers (the
index-1 form M q_ddot + Phi_q^T lambda = f + tau, Phi_q q_ddot = gamma): against central
differences of the constrained run's own right-hand side, and against the Cartesian pendulum's
closed form and its modes (a second derivation, on the constraint manifold)."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import InputError, ModelError

# holonomic (a rod, closed loops, a crank) and velocity constraints (rolling without slipping)
CONSTRAINED = ["cartesian_pendulum", "four_bar", "slider_crank", "rolling_coin"]


@pytest.mark.parametrize("name", CONSTRAINED)
def test_derivatives_agree_with_central_differences_of_the_run(name):
    system = lagrangian.load(name)
    dynamics, functions = system.dynamics(), system.numeric()
    n, rng, t, h = functions.n, np.random.default_rng(7), 0.3, 1e-6
    q, v, tau = rng.uniform(-1, 1, (3, 2, n))  # a batch of two states
    by_q, by_v, by_tau = dynamics.forward_dynamics_derivatives(q, v, tau, t=t)
    assert by_q.shape == by_v.shape == by_tau.shape == (2, n, n)
    for k in range(2):
        y = np.concatenate([q[k], v[k]])
        # the run's right-hand side (no tau) is the dynamics' forward dynamics at tau = 0
        np.testing.assert_allclose(dynamics.forward_dynamics(q[k], v[k], 0 * tau[k], t=t),
                                   functions.rhs(t, y)[n:], rtol=1e-12, atol=1e-12)
        columns = []
        for j in range(2 * n):
            e = np.zeros(2 * n)
            e[j] = h
            columns.append((functions.rhs(t, y + e)[n:] - functions.rhs(t, y - e)[n:]) / (2 * h))
        by_state = np.stack(columns, axis=-1)
        # tau's columns: central differences of forward dynamics with tau on top of f
        shifted = [(dynamics.forward_dynamics(q[k], v[k], tau[k] + h * e, t=t)
                    - dynamics.forward_dynamics(q[k], v[k], tau[k] - h * e, t=t)) / (2 * h)
                   for e in np.eye(n)]
        at_tau = np.stack(shifted, axis=-1)
        scale = max(1.0, np.abs(by_state).max())
        # at tau = 0 against the run; tau enters r linearly, so d/dx at tau = 0 is checked
        zero_q, zero_v, _ = dynamics.forward_dynamics_derivatives(q[k], v[k], 0 * tau[k], t=t)
        assert np.abs(np.hstack([zero_q, zero_v]) - by_state).max() < 1e-7 * scale
        assert np.abs(by_tau[k] - at_tau).max() < 1e-7 * max(1.0, np.abs(at_tau).max())


def test_the_cartesian_pendulum_at_the_bottom_is_the_closed_form():
    """x_ddot = -(g/L) x for small x: A's pair +-i sqrt(g/L); the same as modes(), which
    linearizes on the constraint manifold."""
    system = lagrangian.load("cartesian_pendulum")
    L, g = 0.5, 9.81
    by_q, by_v, by_tau = system.dynamics().forward_dynamics_derivatives([0, -L], [0, 0], [0, 0])
    np.testing.assert_allclose(by_q, [[-g / L, 0], [0, 0]], atol=1e-12)
    np.testing.assert_allclose(by_v, 0, atol=1e-12)
    np.testing.assert_allclose(by_tau, [[1, 0], [0, 0]], atol=1e-12)  # 1/m along the rod's normal
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [by_q, by_v]])
    omega = np.abs(np.linalg.eigvals(A).imag).max()
    assert omega**2 == pytest.approx(g / L, rel=1e-12)
    modes = system.modes({"x": 0, "y": -L})
    assert omega == pytest.approx(modes.natural_frequencies[0], rel=1e-9)


def test_a_constrained_model_has_no_inverse_dynamics_and_checks_shapes():
    dynamics = lagrangian.load("four_bar").dynamics()
    with pytest.raises(ModelError, match="defined only up to") as caught:
        dynamics.inverse_dynamics([0, 0, 0], [0, 0, 0], [0, 0, 0])
    assert caught.value.field == "constraints" and "\n" not in str(caught.value)
    with pytest.raises(InputError, match="expected 3 values") as caught:
        dynamics.forward_dynamics_derivatives([0, 0], [0, 0, 0], [0, 0, 0])
    assert caught.value.field == "q"


def test_the_rest_of_a_constrained_models_dynamics(cli):
    """M, -f, V as the unconstrained equations give them; computed torque (M q_ddot = tau -
    bias, no constraint forces) is refused in one line."""
    system = lagrangian.load("cartesian_pendulum")
    dynamics = system.dynamics()
    q = np.array([0.3, -0.4])
    np.testing.assert_allclose(dynamics.mass_matrix(q), np.eye(2), atol=1e-15)  # m = 1 kg
    np.testing.assert_allclose(dynamics.gravity(q), [0, 9.81], rtol=1e-12)
    assert float(dynamics.potential_energy(q)) == pytest.approx(-9.81 * 0.4, rel=1e-12)
    lam = dynamics.multipliers(q, [0, 0], [0, 0])  # at rest: 2 L lambda = the rod's tension
    assert 2 * 0.5 * float(lam[0]) == pytest.approx(9.81 * 0.4 / 0.5, rel=1e-12)
    from lagrangian.control import computed_torque

    with pytest.raises(ModelError, match="computed torque needs a model without constraints"):
        computed_torque(system, [0, -0.5], 100, 20)
    with pytest.raises(ModelError, match="actuator models need a model without constraints"):
        system.dynamics(actuators=True)
    result = cli("dynamics", "cartesian_pendulum", "--q", "0,-0.5", "--v", "0,0", "--tau",
                 "0,0", "--derivatives", "--json")
    assert result.code == 0, result.err
    import json

    document = json.loads(result.out)
    assert document["dqdd_dq"][0][0] == pytest.approx(-9.81 / 0.5, rel=1e-12)


def test_a_state_where_the_constraints_are_redundant_is_a_nan_row():
    """At x = y = 0 the rod's Jacobian [2x, 2y] vanishes: K is singular there. That row is NaN
    with one DynamicsWarning, the other row is the state's own result."""
    from lagrangian.errors import DynamicsWarning

    dynamics = lagrangian.load("cartesian_pendulum").dynamics()
    q = np.array([[0.0, 0.0], [0.0, -0.5]])
    with pytest.warns(DynamicsWarning, match="1 of 2 states") as caught:
        by_q, _, _ = dynamics.forward_dynamics_derivatives(q, np.zeros((2, 2)), np.zeros((2, 2)))
    assert len([w for w in caught if issubclass(w.category, DynamicsWarning)]) == 1
    assert np.isnan(by_q[0]).all()
    np.testing.assert_allclose(by_q[1], [[-9.81 / 0.5, 0], [0, 0]], atol=1e-12)
