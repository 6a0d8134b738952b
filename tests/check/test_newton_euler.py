"""Newton-Euler (free bodies, explicit forces, reactions eliminated) agrees with Lagrange."""

from __future__ import annotations

from dataclasses import replace

import pytest
import sympy as sp
from check_helpers import system

from lagrangian import DerivationError
from lagrangian.check.newton_euler import crosscheck
from lagrangian.model.expressions import format_expression, parse_expression


@pytest.mark.parametrize("name", ["ladder_pendulum", "double_pendulum", "cart_pendulum",
                                  "slider_crank", "rolling_disk", "rolling_cylinder",
                                  "cartesian_pendulum", "virtual_work_link", "support_pendulum",
                                  "damped_oscillator"])
def test_agrees_with_lagrange(name):
    report = system(name).crosscheck()
    assert report.agree, report
    assert [c.coordinate for c in report.coordinates] == [c.name for c in
                                                          system(name).model.coordinates]
    assert all(c.difference is None for c in report.coordinates)


def test_pendulum_rod_tension():
    s = system("ladder_pendulum")
    theta, theta_dot = s.symbol("theta"), s.symbol("theta_dot")
    m, g, L = (s.symbol(n) for n in "mgL")
    bob = s.crosscheck().reaction("bob")
    assert bob.labels == ("R_x", "R_y")
    R_x, R_y = bob.components
    # Along the rod towards the pivot: m g cos(theta) + m L theta_dot^2; nothing across it.
    along = -R_x * sp.sin(theta) + R_y * sp.cos(theta)
    across = R_x * sp.cos(theta) + R_y * sp.sin(theta)
    assert sp.simplify(along - (m * g * sp.cos(theta) + m * L * theta_dot**2)) == 0
    assert sp.simplify(across) == 0


def test_rolling_disk_contact_reaction():
    # x_ddot = g/3 down a 30 deg slope: normal m g cos 30, friction m g/6 up the slope.
    s = system("rolling_disk")
    m, g, R = (s.symbol(n) for n in "mgR")
    disk = s.crosscheck().reaction("disk")
    assert disk.labels == ("R_x", "R_y", "M_z")
    expected = (-m * g / 6, sp.sqrt(3) * m * g / 2, -m * g * R / 6)
    assert all(sp.simplify(a - b) == 0 for a, b in zip(disk.components, expected, strict=True))


def test_cartesian_pendulum_reaction_is_the_rod_tension():
    s = system("cartesian_pendulum")
    x, y, x_dot, y_dot = (s.symbol(n) for n in ("x", "y", "x_dot", "y_dot"))
    m, g = s.symbol("m"), s.symbol("g")
    R_x, R_y = s.crosscheck().reaction("bob").components
    # Parallel to the rod (x, y): its moment about the pivot vanishes.
    assert sp.simplify(x * R_y - y * R_x) == 0
    # On the circle of radius L at rest at the bottom (x=0, y=-L): tension m g.
    L = s.symbol("L")
    assert sp.simplify(R_y.subs({x: 0, y: -L, x_dot: 0, y_dot: 0}) - m * g) == 0


def test_a_wrong_lagrange_derivation_is_caught():
    # Change the gravity term of the Lagrange forcing: Newton-Euler must disagree there.
    s = system("ladder_pendulum")
    eom = s.equations_of_motion()
    theta = s.symbol("theta")
    broken = replace(eom, forcing=sp.ImmutableMatrix([-eom.forcing[0]]))
    report = crosscheck(broken)
    assert not report.agree
    difference = parse_expression(report.coordinates[0].difference,
                                  {n: s.symbol(n) for n in ("theta", "m", "g", "L")})
    # NE minus the broken Lagrange: M q_ddot + m g L sin - (M q_ddot - m g L sin).
    assert sp.simplify(difference - 2 * s.symbol("L") * s.symbol("g") * s.symbol("m")
                       * sp.sin(theta)) == 0


def test_models_without_free_bodies_are_refused():
    with pytest.raises(DerivationError, match="ladder_pendulum"):
        system("pendulum").crosscheck()


def test_reactions_left_out_when_a_spring_has_no_end_points():
    report = system("slider_crank").crosscheck()
    assert report.reactions == ()
    assert any("'spring'" in note for note in report.notes)


def test_reaction_repr_and_difference_strings():
    report = system("ladder_pendulum").crosscheck()
    assert "agree=True" in repr(report)
    assert all(isinstance(format_expression(v), str) for v in report.reactions[0].components)


def test_double_pendulum_reactions_in_terms_of_accelerations():
    s = system("double_pendulum")
    report = s.crosscheck()
    assert any("in terms of the accelerations" in note for note in report.notes)
    names = ("theta1", "theta2", "theta1_dot", "theta2_dot", "theta1_ddot", "theta2_ddot",
             "l1", "l2", "m2", "g")
    t1, t2, w1, w2, a1, a2, l1, l2, m2, g = (s.symbol(n) for n in names)
    R_x, R_y = s.crosscheck().reaction("bob2").components
    # m2 a = R + m2 g with a the second time derivative of (l1 sin t1 + l2 sin t2, ...).
    a_x = l1 * (a1 * sp.cos(t1) - w1**2 * sp.sin(t1)) + l2 * (a2 * sp.cos(t2) - w2**2 * sp.sin(t2))
    assert sp.expand(R_x - m2 * a_x) == 0
    assert R_y.has(a1, a2, g)


def test_elastic_pendulum_spring_between_two_points():
    # A spring 'between' the pivot and the bob: its tension along the unit vector between them.
    from lagrangian import SystemBuilder

    b = SystemBuilder("Elastic pendulum")
    r, th = b.coordinate("r", unit="m"), b.coordinate("theta", unit="rad")
    m, g, k, l0 = (b.parameter(n, v, u) for n, v, u in
                   (("m", 1.0, "kg"), ("g", 9.81, "m/s^2"), ("k", 50.0, "N/m"), ("l0", 0.4, "m")))
    b.set_gravity(g, (0, -1)).add_particle("bob", m, (r * sp.sin(th), -r * sp.cos(th)))
    b.add_spring("spring", k, l0, between=[(0, 0), "bob"])
    b.add_damper("damper", 0.3, between=[(0, 0), "bob"])
    report = b.build().crosscheck()
    assert report.agree, report
