"""System.to_casadi(): CasADi Functions built from the derived equations agree with the
compiled right-hand side simulate integrates, with closed forms, and with linearize."""

import casadi
import numpy as np
import pytest

import lagrangian
from lagrangian.errors import ModelError


@pytest.fixture(scope="module")
def double_pendulum():
    system = lagrangian.load("double_pendulum")
    return system, system.to_casadi(inputs=["theta1"]), system.numeric()


@pytest.fixture(scope="module")
def cart_pendulum():
    system = lagrangian.load("cart_pendulum")
    return system, system.to_casadi(inputs=["push"])


def test_double_pendulum_rhs_equals_simulate_rhs(double_pendulum):
    system, functions, numeric = double_pendulum
    rng = np.random.default_rng(7)
    for _ in range(20):
        x = rng.uniform(-3, 3, 4)
        ours = numeric.rhs(0.0, x)
        theirs = np.asarray(functions.rhs(x, [0.0])).ravel()
        assert np.allclose(theirs, ours, rtol=1e-12, atol=1e-12 * np.abs(ours).max())


def test_a_torque_input_is_a_generalized_force(double_pendulum):
    """u on theta1 adds M^-1 [u, 0] to the accelerations (a generalized force on theta1)."""
    system, functions, numeric = double_pendulum
    x = np.array([0.3, -0.7, 1.1, 0.4])
    u = 2.5
    mass = numeric.mass_matrix(x[:2], x[2:])
    expected = numeric.rhs(0.0, x)
    expected[2:] += np.linalg.solve(mass, [u, 0.0])
    assert np.allclose(np.asarray(functions.rhs(x, [u])).ravel(), expected, rtol=1e-12,
                       atol=1e-12)
    assert np.allclose(np.asarray(functions.mass_matrix(x[:2])), mass, rtol=1e-13, atol=0)


def test_double_pendulum_jacobian_is_linearize_A(double_pendulum):
    system, functions, _ = double_pendulum
    linear = system.linearize({"theta1": 0.0, "theta2": 0.0}, inputs=["theta1"])
    x, u = casadi.SX.sym("x", 4), casadi.SX.sym("u", 1)
    jac = casadi.Function("j", [x, u], [casadi.jacobian(functions.rhs(x, u), x),
                                        casadi.jacobian(functions.rhs(x, u), u)])
    A, B = (np.asarray(m) for m in jac(np.zeros(4), [0.0]))
    assert np.allclose(A, linear.A, rtol=1e-10, atol=1e-10)
    assert np.allclose(B, linear.B, rtol=1e-10, atol=1e-10)


def test_pendulum_closed_form_and_finite_differences():
    """theta_ddot = -g/L sin(theta) + u/(m L^2); CasADi's AD Jacobian matches central
    differences of the same function."""
    system = lagrangian.load("pendulum")
    f = system.to_casadi(inputs=["theta"]).rhs
    m, L, g = (system.parameters[k] for k in ("m", "L", "g"))
    for theta, rate, u in ((0.4, -1.0, 0.3), (2.9, 3.0, -4.0)):
        out = np.asarray(f([theta, rate], [u])).ravel()
        assert out[0] == rate
        assert out[1] == pytest.approx(-g / L * np.sin(theta) + u / (m * L**2), rel=1e-14)
    x, u = casadi.SX.sym("x", 2), casadi.SX.sym("u", 1)
    jac = casadi.Function("j", [x, u], [casadi.jacobian(f(x, u), x)])
    x0, h = np.array([0.4, -1.0]), 1e-6
    numeric = np.column_stack([(np.asarray(f(x0 + h * e, [0.3])) - np.asarray(f(x0 - h * e, [0.3])))
                               .ravel() / (2 * h) for e in np.eye(2)])
    assert np.allclose(np.asarray(jac(x0, [0.3])), numeric, rtol=1e-7, atol=1e-7)


def test_a_load_input_is_its_parameter(cart_pendulum):
    """u of the load 'push' is its force F: the same as simulating with F = u."""
    system, functions = cart_pendulum
    pushed = system.with_parameters(F=3.0).numeric()
    x = np.array([0.1, 0.5, -0.2, 1.3])
    expected = pushed.rhs(0.0, x)
    assert np.allclose(np.asarray(functions.rhs(x, [3.0])).ravel(), expected, rtol=1e-12,
                       atol=1e-13)
    forcing = np.asarray(functions.forcing(x[:2], x[2:], [3.0])).ravel()
    assert np.allclose(forcing, pushed.forcing(x[:2], x[2:]), rtol=1e-12, atol=1e-13)


def test_constrained_model_rhs_and_residuals():
    system = lagrangian.load("slider_crank")
    functions = system.to_casadi()
    numeric = system.numeric()
    assert functions.constraint_names == numeric.constraint_names
    rng = np.random.default_rng(3)
    for _ in range(5):
        x = rng.uniform(-1, 1, 6)
        ours = numeric.rhs(0.0, x)
        assert np.allclose(np.asarray(functions.rhs(x, [])).ravel(), ours, rtol=1e-10,
                           atol=1e-10 * np.abs(ours).max())
        assert np.allclose(np.asarray(functions.constraints(x[:3], x[3:])).ravel(),
                           numeric.constraint_residual(x[:3], x[3:]), rtol=1e-12, atol=1e-12)


def test_bad_inputs_refused(cart_pendulum):
    system, _ = cart_pendulum
    with pytest.raises(ModelError, match="'pull' is not a parameter, load or coordinate"):
        system.to_casadi(inputs=["pull"])
    with pytest.raises(ModelError, match="enters the mass matrix"):
        system.to_casadi(inputs=["m"])
    with pytest.raises(ModelError, match="named twice"):
        system.to_casadi(inputs=["push", "push"])
    assert "inputs=['push']" in repr(system.to_casadi(inputs=["push"]))
