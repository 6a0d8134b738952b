"""System.to_opty(): opty's implicit equations eom(x, x', r, p) = 0 vanish on the state
derivatives of the right-hand side simulate integrates (opty itself needs a system IPOPT to
build, so the equations are checked on their own: sympy objects in opty's form)."""

import numpy as np
import pytest
import sympy as sp

import lagrangian
from lagrangian.errors import ModelError


def residual(equations, x, x_dot, r):
    t = equations.time
    values = dict(equations.parameters)
    for state, rate in zip(equations.states, x_dot, strict=True):
        values[sp.Derivative(state, t)] = rate
    values.update({state: value for state, value in zip(equations.states, x, strict=True)})
    values.update({s: value for s, value in zip(equations.specified, r, strict=True)})
    derivatives = {k: v for k, v in values.items() if isinstance(k, sp.Derivative)}
    rest = {k: v for k, v in values.items() if not isinstance(k, sp.Derivative)}
    return np.array([float(e.subs(derivatives).subs(rest)) for e in equations.eom])


@pytest.mark.parametrize("name, inputs", [("double_pendulum", ["theta1"]),
                                          ("cart_pendulum", ["push"])])
def test_opty_equations_vanish_on_our_rhs(name, inputs):
    system = lagrangian.load(name)
    equations = system.to_opty(inputs=inputs)
    assert len(equations.states) == 2 * len(system.coordinates)
    assert [str(s) for s in equations.specified] == [f"r_{k}(t)" for k in inputs]
    rhs = system.to_casadi(inputs=inputs).rhs  # u added to the load's value, as in to_opty
    rng = np.random.default_rng(1)
    for _ in range(3):
        x, r = rng.uniform(-2, 2, len(equations.states)), rng.uniform(-3, 3, len(inputs))
        x_dot = np.asarray(rhs(x, r)).ravel()
        assert np.abs(residual(equations, x, x_dot, r)).max() < 1e-11
        assert np.abs(residual(equations, x, x_dot + 0.1, r)).max() > 1e-3  # and only there


def test_opty_refusals():
    with pytest.raises(ModelError, match="without constraints"):
        lagrangian.load("slider_crank").to_opty()
    with pytest.raises(ModelError, match="enters the mass matrix"):
        lagrangian.load("cart_pendulum").to_opty(inputs=["m"])
    assert "specified=['r_push(t)']" in repr(lagrangian.load("cart_pendulum").to_opty(["push"]))
