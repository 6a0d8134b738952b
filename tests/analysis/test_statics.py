"""Statics by virtual work: load magnitudes that hold a mechanism, against closed forms."""

from __future__ import annotations

import math

import pytest

from lagrangian.analysis.statics import solve_statics
from lagrangian.derivation.lagrange import derive
from lagrangian.errors import ModelError
from lagrangian.model.reader import parse_model
from statics_models import SLIDER_CRANK


@pytest.mark.parametrize("degrees", [15, 40, 90, 135])
def test_slider_crank_piston_force_balances_the_crank_torque(degrees):
    eom = derive(parse_model(SLIDER_CRANK))
    theta = math.radians(degrees)
    report = solve_statics(eom, {"theta": theta}, ["P"])
    r, l, tau = 0.1, 0.3, 12.0
    # delta W = tau delta theta + P delta x = 0 with x = r cos(theta) + sqrt(l^2 - r^2 sin^2):
    # P = tau / (r sin(theta) (1 + r cos(theta) / sqrt(l^2 - r^2 sin^2 theta)))
    closed = tau / (r * math.sin(theta)
                    * (1 + r * math.cos(theta) / math.sqrt(l**2 - r**2 * math.sin(theta) ** 2)))
    assert report.solved["P"] == pytest.approx(closed, rel=1e-9)
    assert report.found_from_constraints == ("phi", "x")
    assert report.configuration["x"] == pytest.approx(
        r * math.cos(theta) + math.sqrt(l**2 - r**2 * math.sin(theta) ** 2), rel=1e-12)
    # every coordinate's shares (loads and reactions) cancel
    for name in ("theta", "phi", "x"):
        assert sum(v for _, c, v in report.shares if c == name) == pytest.approx(0, abs=1e-9)


LADDER = """
name = "Ladder against a smooth wall, held at its foot by a horizontal force"
[coordinates]
theta = { unit = "rad", initial = 1.0 }
[parameters]
m = { value = 20.0, unit = "kg" }
g = { value = 9.81, unit = "m/s^2" }
L = { value = 4.0, unit = "m" }
H = { unit = "N" }
[gravity]
g = "g"
[[particles]]
name = "ladder"
mass = "m"
position = ["L/2*cos(theta)", "L/2*sin(theta)"]
[[loads]]
name = "hold"
point = ["L*cos(theta)", 0]
force = ["-H", 0]
"""


@pytest.mark.parametrize("degrees", [30, 50, 70])
def test_ladder_held_by_a_horizontal_force(degrees):
    eom = derive(parse_model(LADDER))
    theta = math.radians(degrees)
    report = solve_statics(eom, {"theta": theta}, ["H"])
    # moments about the top (smooth wall): H L sin(theta) = m g L/2 cos(theta)
    assert report.solved["H"] == pytest.approx(20.0 * 9.81 / (2 * math.tan(theta)), rel=1e-12)
    shares = {source: value for source, _, value in report.shares}
    assert shares["hold"] == pytest.approx(-shares["weight of ladder"], rel=1e-12)
    assert report.units == {"H": "N"}


LINK = """
[coordinates]
theta = "rad"
[parameters]
F = { unit = "N" }
G = { unit = "N" }
L = 0.5
tau = 10.0
[[loads]]
name = "tip"
point = ["L*sin(theta)", "L*cos(theta)"]
force = ["F", 0]
[[loads]]
name = "tip2"
point = ["L*sin(theta)", "L*cos(theta)"]
force = ["2*G", 0]
[[loads]]
name = "motor"
torque = "tau"
angle = "theta"
"""


def test_link_force_for_a_motor_torque_is_tau_over_l_cos_theta():
    model = parse_model(LINK.replace('force = ["2*G", 0]', 'force = [0, "G"]'))
    report = solve_statics(derive(model), {"theta": math.radians(40)}, ["F"],
                           parameters={"G": 0.0})
    assert report.solved["F"] == pytest.approx(-10.0 / (0.5 * math.cos(math.radians(40))))


def error(eom, unknowns, at=None, parameters=None) -> str:
    with pytest.raises(ModelError) as info:
        solve_statics(eom, at or {"theta": 0.5}, unknowns, parameters)
    return str(info.value)


def test_bad_requests_are_named():
    eom = derive(parse_model(LINK))
    assert error(eom, ["F", "G"]) == (
        "solve_for: too many unknowns: 'F' and 'G' for 1 equilibrium conditions; solve for "
        "fewer")
    assert error(eom, ["Q"]) == ("solve_for: 'Q' is not a parameter of this model; expected one of: "
                                 "F, G, L, tau")
    assert error(eom, ["F"]) == (
        "parameters.G: parameter 'G' has no value; give one (or solve for it)")
    assert error(eom, []) == "solve_for: give at least one parameter to solve for"
    tilted = derive(parse_model(LINK.replace('force = ["F", 0]', 'force = ["F*cos(G)", 0]')))
    assert error(tilted, ["G"], parameters={"F": 1.0}) == (
        "solve_for: 'G' does not enter the generalized forces linearly, so it is not a load "
        "magnitude that virtual work can solve for")
    assert error(eom, ["F"], at={"phi": 1.0}) == (
        "configuration: 'phi' is not a coordinate or t of this model; expected one of: theta, t")


def test_dependent_unknowns_and_too_few_unknowns_are_named():
    two = parse_model("""
[coordinates]
x = "m"
y = "m"
[parameters]
F = { unit = "N" }
G = { unit = "N" }
k = 100.0
[[springs]]
name = "sx"
stiffness = "k"
length = "x"
[[springs]]
name = "sy"
stiffness = "k"
length = "y"
[[loads]]
name = "a"
point = ["x", "y"]
force = ["F", "F"]
[[loads]]
name = "b"
point = ["x", "y"]
force = ["G", "G"]
""")
    eom = derive(two)
    assert error(eom, ["F", "G"], at={"x": 0.1, "y": 0.1}) == (
        "solve_for: 'F' and 'G' are not independent: they enter the equilibrium conditions in a "
        "fixed proportion, so only a combination of them is fixed")
    assert error(eom, ["F"], at={"x": 0.1, "y": 0.2}, parameters={"G": 0.0}).startswith(
        "solve_for: too few unknowns: 'F' cannot satisfy all 2 independent equilibrium "
        "conditions at this configuration")
    # where one value satisfies both, it is found
    report = solve_statics(eom, {"x": 0.1, "y": 0.1}, ["F"], {"G": 0.0})
    assert report.solved["F"] == pytest.approx(10.0)


def test_a_load_that_does_no_work_there_cannot_be_solved_for():
    eom = derive(parse_model(LINK))
    assert error(eom, ["F"], at={"theta": math.pi / 2}, parameters={"G": 0.0}) == (
        "solve_for: 'F' does no virtual work in this configuration (it is not in Q), so the "
        "equilibrium cannot fix it")
