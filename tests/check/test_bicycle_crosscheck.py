"""The Whipple bicycle (Meijaard et al. 2007): Newton-Euler with Euler's equations for its four
bodies agrees with the Lagrange derivation on every coordinate, at random states (issue 15)."""

import pytest
import sympy as sp

import lagrangian
from lagrangian.check import equivalence as eq


@pytest.mark.slow
def test_the_bicycle_s_newton_euler_equations_agree_with_lagrange_on_every_coordinate():
    system = lagrangian.load("whipple_bicycle")
    report = system.crosscheck()
    assert [c.coordinate for c in report.coordinates] == [
        "x", "y", "psi", "phi", "theta", "thetaR", "delta", "thetaF"]
    assert all(c.agree for c in report.coordinates), report
    # The comparison is not vacuous at this size: the steer row with a steer torque of
    # 1% of the front frame's weight times its mass-centre offset added is told apart.
    eom = system.equations_of_motion()
    model = eom.model
    steer = [c.coordinate for c in report.coordinates].index("delta")
    lagrange = (eom.mass_matrix * eom.acceleration_symbols - eom.forcing)[steer]
    newton_euler = report.coordinates[steer].newton_euler
    points = eq.random_points(model)  # crosscheck's own points
    mass, g, offset = sp.Symbol("mH"), sp.Symbol("g"), sp.Symbol("xH")
    assert not eq.identical(newton_euler, lagrange + mass * g * offset / 100, points)
