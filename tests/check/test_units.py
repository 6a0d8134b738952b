"""Dimensional analysis of models: T, V in J, D in W, Q in J per unit of q, trig args pure."""

from __future__ import annotations

import pytest

import lagrangian
from lagrangian.check.units import check_model_units

BAD = """
name = "Bad units"
[coordinates]
theta = "rad"
x = "m"
[parameters]
m = { value = 1.0, unit = "kg" }
L = { value = 0.5, unit = "m" }
g = { value = 9.81, unit = "m/s^2" }
k = { value = 10.0, unit = "N/m" }
c = { value = 0.2, unit = "N*s/m" }
F = { value = 3.0, unit = "N" }
[energy]
T = "1/2*m*L^2*theta_dot^2 + 1/2*m*x_dot^2"
V = "-m*g*L*cos(theta) + 1/2*k*x^2 + m*g*sin(L)"
D = "1/2*c*x_dot"
[[loads]]
name = "push"
torque = "F"
angle = "theta"
[generalized_forces]
x = "F*L"
theta = "F*L"
"""


@pytest.fixture(scope="module")
def bad():
    return lagrangian.parse_model(BAD, source="bad.toml")


def test_every_inconsistent_term_is_named(bad):
    report = check_model_units(bad)
    assert not report.consistent
    by_item = {}
    for issue in report.issues:
        by_item.setdefault(issue.item, []).append(issue)
    # sin(L): a length inside a trig function, and m g sin(L) is a force, not an energy.
    assert any("the argument of sin" in i.message and i.term == "L" for i in by_item["V"])
    assert any(i.term == "g*m*sin(L)" for i in by_item["V"])
    assert [i.term for i in by_item["D"]] == ["c*x_dot/2"]
    assert "a power" in by_item["D"][0].message
    assert [i.item for i in report.issues if i.item.startswith("loads")] == ["loads[push].torque"]
    # Q on a length must be a force (N); F*L is N m. Q on an angle is N m: F*L is right.
    assert "Q[x]" in by_item and "Q[theta]" not in by_item
    assert "N" in by_item["Q[x]"][0].message


def test_examples_are_consistent():
    for name in lagrangian.examples():
        report = lagrangian.load(name).check_units()
        assert report.consistent, (name, report.issues)


def test_parameters_without_units_are_not_judged():
    model = lagrangian.parse_model("""
[coordinates]
x = "m"
[parameters]
m = 1.0
k = { value = 2.0, unit = "N/m" }
[energy]
T = "1/2*m*x_dot^2"
V = "1/2*k*x^2"
""")
    report = check_model_units(model)
    assert report.consistent and report.unchecked == ("m",)


FORGOT_L = """
name = "forgot L"
[coordinates]
theta = "rad"
[parameters]
m = { value = 1.0, unit = "kg" }
L = { value = 0.5, unit = "m" }
[[particles]]
name = "bob"
mass = "m"
position = ["L*sin(theta)", "%s"]
"""


def test_geometry_in_bare_numbers_is_si_metres_but_a_forgotten_length_is_caught():
    """A chain whose joints and centres are bare numbers (SI metres, as in a URDF) is not a
    flood of 'no units' warnings; a model that names its length L in x and forgets it in y
    is still told so."""
    b = lagrangian.SystemBuilder("numbers")
    b.parameter("g", 9.81, unit="m/s^2")
    b.set_gravity("g", (0, 0, -1))
    parent = None
    for i in range(3):
        b.coordinate(f"q{i}", "rad")
        joint = {"type": "revolute", "axis": "xy"[i % 2], "angle": f"q{i}"}
        if parent:
            joint["at"] = [0, 0, -1]
        b.add_rigid_body(f"link{i}", 1.0, [0.1, 0.1, 0.02], parent=parent, joint=joint,
                         center=[0, 0, -0.5])
        parent = f"link{i}"
    assert check_model_units(b.build().model).consistent
    wrong = check_model_units(lagrangian.parse_model(FORGOT_L % "-cos(theta)"))
    assert [i.item for i in wrong.issues] == ["particles[bob].position.y"]
    assert check_model_units(lagrangian.parse_model(FORGOT_L % "-L*cos(theta)")).consistent


def test_a_long_exact_number_is_shown_in_three_figures():
    """In messages (units warnings, the [control] laws' line); the JSON keeps every digit."""
    # 1e-300*1e-300 is the exact 1/10^600: the warning printed its 600 digits, one line of 650
    # characters; a number of 20 digits or fewer is shown as it is
    import sympy as sp

    from lagrangian.model.printing import shown_expression as format_expression

    theta = sp.Symbol("theta")
    assert format_expression(theta**2 / sp.Integer(10)**600) == "1.00e-600*theta**2"
    assert format_expression(theta**2 * sp.cos(sp.Integer(10)**24)) == "theta**2*cos(1.00e+24)"
    assert format_expression(-sp.Integer(10)**30 * theta) == "-1.00e+30*theta"
    assert format_expression(sp.Rational(1, 3) * theta) == "theta/3"
    from lagrangian.output.control import law_summary, law_text

    model = lagrangian.parse_model(
        '[coordinates]\nx = { unit = "m", initial = 0, rate = 0 }\n'
        '[parameters]\nm = { value = 1, unit = "kg" }\nF = { value = 0, unit = "N" }\n'
        '[energy]\nT = "m*x_dot^2/2"\nV = "0"\n[generalized_forces]\nx = "F"\n'
        '[control]\nF = "-1e-300*1e-300*x"\n')
    assert law_text(model).endswith("F = -1.00e-600*x")
    assert len(law_summary(model)["laws"]["F"]) > 600  # exact in the JSON
