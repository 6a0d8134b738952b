"""The derived impact map against closed forms: a ball's rebound (KE ratio e^2), stick and slip
on a sliding ball, a pendulum striking a wall, a rod falling flat onto a corner (angular
momentum about the corner conserved, omega+ = 3 v / 2 L), the rimless wheel's spoke strike
(omega+ = cos(2 alpha) omega-); the law holds on the striking point after each."""

from __future__ import annotations

import math

import numpy as np
import pytest

import lagrangian
from lagrangian.derivation.impact_map import derive_impact_maps
from lagrangian.errors import ModelError
from lagrangian.model.reader import parse_model
from lagrangian.simulation.hybrid import CompiledImpact

BALL = """
[coordinates]
x = "m"
y = "m"
[parameters]
m = 2.0
e = 0.7
[gravity]
g = 9.81
[[particles]]
name = "ball"
mass = "m"
position = ["x", "y"]
[[impacts]]
name = "floor"
guard = "y"
point = "ball"
normal = [0, 1]
restitution = "e"
tangential = "LAW"
"""
WALL = """
[coordinates]
theta = "rad"
[parameters]
m = 1.0
L = 0.5
e = 0.6
[gravity]
g = 9.81
[[particles]]
name = "bob"
mass = "m"
position = ["L*sin(theta)", "-L*cos(theta)"]
[[impacts]]
name = "wall"
guard = "theta"
point = "bob"
normal = [1, 0]
restitution = "e"
tangential = "stick"
"""
ROD = """
[coordinates]
x = "m"
y = "m"
theta = "rad"
[parameters]
m = 2.0
L = 1.2
[gravity]
g = 9.81
[[bodies]]
name = "rod"
mass = "m"
inertia = "m*L^2/12"
position = ["x", "y"]
angle = "theta"
[[impacts]]
name = "corner"
guard = "y - L/2*sin(theta)"
point = { body = "rod", offset = ["-L/2", 0] }
normal = [0, 1]
tangential = "stick"
"""


def compiled(text: str) -> tuple[CompiledImpact, object]:
    system = lagrangian.System(parse_model(text))
    eom = system.equations_of_motion()
    substitution = {p.symbol: p.value for p in eom.model.parameters}
    impact_map, = derive_impact_maps(eom)
    return CompiledImpact(eom.model, impact_map, substitution), impact_map


@pytest.fixture(scope="module")
def slip_ball():
    return compiled(BALL.replace("LAW", "slip"))


@pytest.fixture(scope="module")
def stick_ball():
    return compiled(BALL.replace("LAW", "stick"))


def test_a_ball_rebounds_with_e_and_keeps_e_squared_of_its_energy(slip_ball):
    impact, _ = slip_ball
    m, e, v = 2.0, 0.7, 3.0
    q, v_after, impulse, lost, residual, *_ = impact.apply(np.zeros(2), np.array([0.0, -v]), 0.)
    assert v_after == pytest.approx([0.0, e * v], abs=1e-14)
    assert impulse == pytest.approx([0.0, m * (1 + e) * v], rel=1e-14)
    assert lost == pytest.approx((1 - e**2) * 0.5 * m * v**2, rel=1e-13)
    assert residual < 1e-14


def test_slip_keeps_the_tangential_velocity_and_stick_stops_it(slip_ball, stick_ball):
    m, e, u, v = 2.0, 0.7, 1.5, 3.0
    before = np.array([u, -v])
    _, slipped, slip_impulse, slip_lost, *_ = slip_ball[0].apply(np.zeros(2), before, 0.0)
    _, stuck, stick_impulse, stick_lost, residual, *_ = stick_ball[0].apply(
        np.zeros(2), before, 0.0)
    assert slipped == pytest.approx([u, e * v], abs=1e-14)
    assert stuck == pytest.approx([0.0, e * v], abs=1e-14)
    assert stick_impulse == pytest.approx([-m * u, m * (1 + e) * v], rel=1e-14)
    assert slip_lost == pytest.approx(0.5 * m * (1 - e**2) * v**2, rel=1e-13)
    assert stick_lost == pytest.approx(0.5 * m * ((1 - e**2) * v**2 + u**2), rel=1e-13)
    assert residual < 1e-14


def test_a_pendulum_striking_a_wall():
    """At theta = 0 the bob moves along the wall's normal only: the stick law's tangential row
    repeats nothing the point can do, and the rebound is -e theta_dot."""
    impact, _ = compiled(WALL)
    _, after, impulse, lost, residual, *_ = impact.apply(np.zeros(1), np.array([-2.0]), 0.0)
    m, L, e = 1.0, 0.5, 0.6
    assert after == pytest.approx([2.0 * e], rel=1e-14)
    assert impulse[0] == pytest.approx(m * L * 2.0 * (1 + e), rel=1e-13)
    assert lost == pytest.approx((1 - e**2) * 0.5 * m * L**2 * 4.0, rel=1e-13)
    assert residual < 1e-13


def test_a_rod_falling_flat_onto_a_corner_turns_about_it():
    impact, impact_map = compiled(ROD)
    m, L, v = 2.0, 1.2, 2.5
    assert impact_map.jacobian.shape == (2, 3)  # stick: both rows of the end's velocity
    q = np.array([0.0, 0.0, 0.0])
    _, after, impulse, lost, residual, *_ = impact.apply(q, np.array([0.0, -v, 0.0]), 0.0)
    x_dot, y_dot, omega = after
    assert omega == pytest.approx(-3 * v / (2 * L), rel=1e-13)  # clockwise about the end
    # angular momentum about the corner, (-L/2, 0) from the centre: -m (L/2) v before
    about_corner = m * (L / 2 * y_dot - 0 * x_dot) + m * L**2 / 12 * omega
    assert about_corner == pytest.approx(-m * L / 2 * v, rel=1e-13)
    end_velocity = (x_dot, y_dot - L / 2 * omega)
    assert end_velocity == pytest.approx((0.0, 0.0), abs=1e-13)
    assert lost == pytest.approx(0.25 * 0.5 * m * v**2, rel=1e-12)
    assert impulse == pytest.approx([0.0, m * v / 4], abs=1e-13)
    assert residual < 1e-13


def test_the_rimless_wheels_spoke_strike():
    """A released pivot: the map in (p, theta) with p the old foot, omega+ = cos(2 alpha)
    omega- (the hub's momentum about the new foot conserved), the old foot lifting off."""
    system = lagrangian.load("rimless_wheel")
    eom = system.equations_of_motion()
    substitution = {p.symbol: p.value for p in eom.model.parameters}
    impact_map, = system.impact_maps()
    assert impact_map.extension == 2 and impact_map.mass_matrix.shape == (3, 3)
    impact = CompiledImpact(eom.model, impact_map, substitution)
    alpha = math.pi / 8
    q_after, after, _, lost, residual, _, extended = impact.apply(
        np.array([alpha]), np.array([1.3]), 0.0)
    assert q_after == pytest.approx([-alpha], abs=1e-15)  # relabelled to the new spoke
    assert after == pytest.approx([math.cos(2 * alpha) * 1.3], rel=1e-13)
    assert lost == pytest.approx(0.5 * 1.3**2 * (1 - math.cos(2 * alpha) ** 2), rel=1e-12)
    assert residual < 1e-13
    assert extended[1] > 0  # the old foot's velocity along the normal: it lifts off


def test_a_model_with_constraints_is_refused():
    text = BALL.replace("LAW", "slip") + '[[constraints]]\nname = "rail"\nholonomic = "x"\n'
    eom = lagrangian.System(parse_model(text, source="rail.toml")).equations_of_motion()
    with pytest.raises(ModelError, match="without constraints"):
        derive_impact_maps(eom)


def test_a_released_pivot_needs_the_kinetic_energy_of_its_components():
    text = WALL.replace('tangential = "stick"', 'tangential = "stick"\nrelease = "pivot"')
    text = text.replace("e = 0.6", "e = 0.0").replace('restitution = "e"', "restitution = 0")
    text = text.replace("[gravity]", "[energy]\nT = \"theta_dot^2\"\n[gravity]")
    eom = lagrangian.System(parse_model(text)).equations_of_motion()
    with pytest.raises(ModelError, match=r"\[energy\] T"):
        derive_impact_maps(eom)
