"""Newton-Euler (free bodies, explicit forces, reactions eliminated) agrees with Lagrange."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from check_helpers import system

from lagrangian import DerivationError
from lagrangian.check.newton_euler import crosscheck
from lagrangian.model.expressions import format_expression, parse_expression
from lagrangian.output.check import crosscheck_document


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


def reaction_at(s, report, joint, state):
    """A reaction's components (SI) at ``state`` (names -> values), the accelerations solved
    from Lagrange's M q_ddot = f there when the reaction is given in terms of them."""
    values = {s.symbol(n): v for n, v in s.parameters.items()}
    values.update({s.symbol(n): v for n, v in state.items()})
    eom = s.equations_of_motion()
    mass_matrix = sp.Matrix(eom.mass_matrix).xreplace(values).evalf()
    forcing = sp.Matrix(eom.forcing).xreplace(values).evalf()
    values.update(zip(s.model.q_ddot, mass_matrix.LUsolve(forcing), strict=True))
    return [float(c.xreplace(values).evalf()) for c in report.reaction(joint).components]


def test_elastic_pendulum_spring_between_two_points():
    """A spring and a damper 'between' the pivot and the bob: their forces act on the bob, so
    its reaction is reported, and it is zero (the bob is a free particle: m a = weight +
    spring + damper, nothing else touches it)."""
    from lagrangian import SystemBuilder

    b = SystemBuilder("Elastic pendulum")
    r, th = b.coordinate("r", unit="m"), b.coordinate("theta", unit="rad")
    m, g, k, l0 = (b.parameter(n, v, u) for n, v, u in
                   (("m", 1.0, "kg"), ("g", 9.81, "m/s^2"), ("k", 50.0, "N/m"), ("l0", 0.4, "m")))
    b.set_gravity(g, (0, -1)).add_particle("bob", m, (r * sp.sin(th), -r * sp.cos(th)))
    b.add_spring("spring", k, l0, between=[(0, 0), "bob"])
    b.add_damper("damper", 0.3, between=[(0, 0), "bob"])
    s = b.build()
    report = s.crosscheck()
    assert report.agree, report
    assert not any("not reported" in note for note in report.notes)
    for state in ({"r": 0.7, "theta": 0.4, "r_dot": -0.3, "theta_dot": 1.2},
                  {"r": 0.2, "theta": -2.0, "r_dot": 0.5, "theta_dot": -0.1}):
        assert reaction_at(s, report, "bob", state) == pytest.approx([0, 0], abs=1e-9)


def rod_with_hanging_mass():
    from lagrangian import SystemBuilder

    b = SystemBuilder("Rod with a hanging mass")
    th, x, y = b.coordinate("theta", unit="rad"), b.coordinate("x"), b.coordinate("y")
    M, m, L, g, k1, k2, l1, l2, c, H = (b.parameter(n, v, u) for n, v, u in (
        ("M", 2.0, "kg"), ("m", 0.5, "kg"), ("L", 0.8, "m"), ("g", 9.81, "m/s^2"),
        ("k1", 40.0, "N/m"), ("k2", 25.0, "N/m"), ("l1", 0.3, "m"), ("l2", 0.2, "m"),
        ("c", 0.7, "N*s/m"), ("H", 2.0, "m")))
    b.set_gravity(g, (0, -1))
    b.add_body("rod", M, M * L**2 / 12, (L / 2 * sp.sin(th), -L / 2 * sp.cos(th)),
               th - sp.pi / 2)
    b.add_particle("mass", m, (x, y))
    b.add_spring("upper", k1, l1, between=[{"body": "rod", "offset": [L / 2, 0]}, "mass"])
    b.add_spring("lower", k2, l2, between=["mass", (0, -H)])
    b.add_damper("dashpot", c, between=["mass", (0, -H)])
    return b.build()


def test_spring_from_a_body_point_to_a_particle_gives_the_pivot_reaction():
    """A uniform rod (M, L) hangs from a pivot at the origin, angle theta from the downward
    vertical: centre G = L/2 (sin, -cos), tip P = L (sin, -cos). A free mass m at (x, y) hangs
    from the tip by spring 'upper' (k1, l1) and is tied to the ground point (0, -H) by spring
    'lower' (k2, l2) and a dashpot (c).

    At theta = 0, theta_dot = w, with the mass at rest at (0, y0) below the tip, the forces on
    the rod (its weight M g at G, the spring's pull T1 = k1 (-L - y0 - l1) at P towards the
    mass) all lie on the vertical through the pivot: theta_ddot = 0, and G moves on its circle
    with a_G = (0, w^2 L/2). The pivot reaction R = M a_G - F is then

        R = (0, M w^2 L/2 + M g + k1 (-L - y0 - l1)),  M_z = 0 (no moment about G),

    the rod carries its weight, the spring's tension and the centripetal force. At any state
    the pivot pushes with a force only, so its moment about G is the reported M_z:
    M_z = (r_pivot - r_G) x R = -(G_x R_y - G_y R_x); the mass is free: its reaction is 0.
    """
    s = rod_with_hanging_mass()
    report = s.crosscheck()
    assert report.agree, report
    assert [r.joint for r in report.reactions] == ["mass", "rod"]
    assert report.reaction("rod").labels == ("R_x", "R_y", "M_z")
    assert not any("not reported" in note for note in report.notes)

    M, L, g, k1, l1 = (s.parameters[n] for n in ("M", "L", "g", "k1", "l1"))
    w, y0 = 1.7, -1.5
    R_x, R_y, M_z = reaction_at(s, report, "rod", {"theta": 0.0, "theta_dot": w, "x": 0.0,
                                                    "y": y0, "x_dot": 0.0, "y_dot": 0.0})
    assert R_x == pytest.approx(0, abs=1e-9)
    assert R_y == pytest.approx(M * w**2 * L / 2 + M * g + k1 * (-L - y0 - l1), rel=1e-12)
    assert M_z == pytest.approx(0, abs=1e-9)

    for state in ({"theta": 0.6, "theta_dot": -0.8, "x": 0.3, "y": -1.1, "x_dot": 0.4,
                   "y_dot": -0.2},
                  {"theta": -1.9, "theta_dot": 2.1, "x": -0.5, "y": -0.4, "x_dot": -1.0,
                   "y_dot": 0.7}):
        R_x, R_y, M_z = reaction_at(s, report, "rod", state)
        G_x, G_y = L / 2 * np.sin(state["theta"]), -L / 2 * np.cos(state["theta"])
        assert M_z == pytest.approx(-(G_x * R_y - G_y * R_x), rel=1e-9, abs=1e-9)
        assert reaction_at(s, report, "mass", state) == pytest.approx([0, 0], abs=1e-9)


def test_crosscheck_json_reports_the_reactions_of_a_model_with_springs():
    document = crosscheck_document(rod_with_hanging_mass().crosscheck())
    assert set(document) == {"agree", "coordinates", "reactions"}
    assert document["agree"] is True
    assert document["coordinates"] == {n: {"agree": True, "difference": None}
                                       for n in ("theta", "x", "y")}
    assert [r["joint"] for r in document["reactions"]] == ["mass", "rod"]
    # the first published keys, and the labelled ones added beside them (the rod has a moment)
    # and their values at the initial state (N, N m), labelled the same way
    assert [set(r) for r in document["reactions"]] == [
        {"joint", "components", "body", "force", "at_initial_state"},
        {"joint", "components", "body", "force", "moment", "at_initial_state"}]
    assert [set(r["at_initial_state"]) for r in document["reactions"]] == [
        {"force"}, {"force", "moment"}]
    assert [r["body"] for r in document["reactions"]] == ["mass", "rod"]
    assert [len(r["components"]) for r in document["reactions"]] == [2, 3]
    assert all(isinstance(c, str) and "k1" in c for c in document["reactions"][1]["components"][:2])


SLIDER_SPRING = 'length = "x"'


@pytest.mark.parametrize("between", ['between = [[0, 0], "slider"]',
                                     'between = [[0, 0], ["x", 0]]'])
def test_slider_crank_with_its_spring_between_points_reports_reactions(tmp_path, between):
    """The slider-crank's spring given 'between' the origin and the slider (by name, or as the
    moving point (x, 0) it shares with the slider): it pushes on the slider only, so the
    slider's reaction (rod pin + guide) is R_x = m3 x_ddot + k (x - x0) for x > 0."""
    import lagrangian
    from lagrangian.model import examples as examples_package

    source = Path(examples_package.__file__).parent / "slider_crank.toml"
    text = source.read_text()
    assert SLIDER_SPRING in text
    path = tmp_path / "slider.toml"
    path.write_text(text.replace(SLIDER_SPRING, between))
    s = lagrangian.load(path)
    report = s.crosscheck()
    assert report.agree, report
    assert [r.joint for r in report.reactions] == ["slider", "crank", "rod"]
    x, x_ddot, m3, k, x0 = (s.symbol(n) for n in ("x", "x_ddot", "m3", "k", "x0"))
    R_x = report.reaction("slider").components[0]
    for value in (0.25, 0.4):
        assert float((R_x - m3 * x_ddot - k * (x - x0)).subs({x: value, x_ddot: 1.3, m3: 2.0,
                                                              k: 500.0, x0: 0.3})) == \
            pytest.approx(0, abs=1e-9)


def test_a_spring_end_on_no_body_leaves_the_reactions_out():
    # A moving end (x, 1) that no particle or body carries: its force cannot be placed.
    from lagrangian import SystemBuilder

    b = SystemBuilder("Loose end")
    x, y = b.coordinate("x"), b.coordinate("y")
    b.add_particle("mass", 1.0, (x, y))
    b.add_spring("loose", 10.0, 0.5, between=["mass", (x, 1)])
    report = b.build().crosscheck()
    assert report.agree, report
    assert report.reactions == ()
    assert any("'loose'" in note and "not reported" in note for note in report.notes)


def test_crosscheck_json_labels_the_rolling_disk_contact_reaction_by_axis():
    """x_ddot = g/3 down a 30 deg slope: friction m g/6 up the slope (force x), normal
    m g cos 30 (force y), and its moment about the centre -m g R/6 (moment z)."""
    s = system("rolling_disk")
    m, g, R = (s.symbol(n) for n in "mgR")
    (disk,) = crosscheck_document(s.crosscheck())["reactions"]
    assert disk["body"] == disk["joint"] == "disk"
    labelled = [disk["force"]["x"], disk["force"]["y"], disk["moment"]["z"]]
    assert labelled == disk["components"]
    names = {str(x): x for x in (m, g, R)}
    expected = (-m * g / 6, sp.sqrt(3) * m * g / 2, -m * g * R / 6)
    assert all(sp.simplify(sp.sympify(text, locals=names) - value) == 0
               for text, value in zip(labelled, expected, strict=True))
