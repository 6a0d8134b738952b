"""What the derivation says is conserved (and the power that changes it), and models with no
inertia at all (statics by virtual work)."""

from __future__ import annotations

import math

import pytest
import sympy as sp

import lagrangian
from lagrangian.derivation.lagrange import derive
from lagrangian.derivation.regularity import require_inertia
from lagrangian.errors import DerivationError
from lagrangian.model.reader import parse_model


def eom_of(name: str):
    return derive(lagrangian.load(name).model)


def symbols(model):
    names = {p.name: p.symbol for p in model.parameters}
    for c in model.coordinates:
        names.update({c.name: c.symbol, c.velocity.name: c.velocity})
    return names


def test_bead_on_a_hoop_conserves_the_jacobi_integral_not_t_plus_v():
    eom = eom_of("bead_on_hoop")
    s = symbols(eom.model)
    m, R, g, Omega, th, w = (s[k] for k in ("m", "R", "g", "Omega", "theta", "theta_dot"))
    # h = 1/2 m R^2 (theta_dot^2 - Omega^2 sin^2 theta) - m g R cos theta (rotating frame)
    expected = m * R**2 * (w**2 - Omega**2 * sp.sin(th) ** 2) / 2 - m * g * R * sp.cos(th)
    assert sp.expand(eom.jacobi_integral - expected) == 0
    assert eom.invariant_kind == "jacobi_integral"
    assert sp.expand(eom.invariant - expected) == 0
    assert eom.power == 0


def test_charged_particle_jacobi_integral_is_the_kinetic_energy():
    eom = eom_of("charged_particle")
    assert eom.invariant_kind == "jacobi_integral"  # V has q_dot: h is not T + V
    assert sp.expand(eom.jacobi_integral - eom.kinetic_energy) == 0


def test_conservative_pendulum_conserves_energy():
    eom = eom_of("pendulum")
    assert eom.invariant_kind == "energy"
    assert sp.expand(eom.invariant - eom.kinetic_energy - eom.potential_energy) == 0


def test_damped_oscillator_loses_c_x_dot_squared():
    eom = eom_of("damped_oscillator")
    s = symbols(eom.model)
    assert eom.invariant_kind == "work_balance"
    assert sp.expand(eom.power + s["c"] * s["x_dot"] ** 2) == 0


def test_driven_pendulum_power_is_torque_times_rate():
    model = parse_model("""
[coordinates]
theta = "rad"
[parameters]
m = 1.0
L = 1.0
g = 9.81
A = 0.5
w = 2.0
[gravity]
g = "g"
[[particles]]
name = "bob"
mass = "m"
position = ["L*sin(theta)", "-L*cos(theta)"]
[[loads]]
name = "drive"
torque = "A*cos(w*t)"
angle = "theta"
""")
    eom = derive(model)
    s = symbols(model)
    assert eom.invariant_kind == "work_balance"
    t = model.time
    assert sp.expand(eom.power - s["A"] * sp.cos(s["w"] * t) * s["theta_dot"]) == 0


def test_prescribed_support_motion_does_work_through_explicit_time():
    eom = eom_of("support_pendulum")
    assert eom.invariant_kind == "work_balance"
    # dh/dt = -dL/dt: check it against a finite difference of h along no motion in q
    t = eom.model.time
    assert sp.expand(eom.power + eom.lagrangian.diff(t)) == 0


LINK = """
name = "Worked example 2 as written: a massless link, 100 N horizontal at its tip"
[coordinates]
theta = "rad"
[parameters]
F = { value = 100, unit = "N" }
L = { value = 0.5, unit = "m" }
[[loads]]
name = "tip_force"
point = ["L*sin(theta)", "L*cos(theta)"]
force = ["F", 0]
"""


def test_a_massless_link_derives_and_gives_43_30_newton_metres():
    eom = derive(parse_model(LINK))
    s = symbols(eom.model)
    assert not eom.has_inertia
    assert eom.coordinates_without_inertia == ("theta",)
    assert eom.static_conditions[0] == s["F"] * s["L"] * sp.cos(s["theta"])
    values = {s["F"]: 100.0, s["L"]: 0.5, s["theta"]: math.radians(30)}
    assert float(eom.generalized_forces[0].subs(values)) == pytest.approx(43.30127, abs=1e-5)
    assert eom.accelerations is None
    assert eom.accelerations_note == (
        "none: the model has no inertia (statics: the equations are the equilibrium "
        "conditions 0 = f)")


def test_what_needs_inertia_names_the_coordinates_without_it():
    eom = derive(parse_model(LINK))
    with pytest.raises(DerivationError) as info:
        require_inertia(eom, "simulate")
    assert str(info.value) == (
        "simulate needs inertia: the model has no mass, inertia or kinetic energy for 'theta' "
        "(a statics model: derive, forces, equilibria, check and statics work without it)")
    require_inertia(eom_of("pendulum"), "simulate")  # no error with inertia


def test_partly_massless_models_are_still_refused():
    model = parse_model('[coordinates]\nx = "m"\ny = "m"\n[energy]\nT = "x_dot^2/2"\n'
                        'V = "x^2 + y^2"\n')
    with pytest.raises(DerivationError, match="singular mass matrix: the kinetic energy does "
                       "not contain the velocity of 'y'"):
        derive(model)


def test_a_massless_slider_crank_with_spring_and_constraints_derives():
    model = parse_model("""
[coordinates]
theta = "rad"
x = "m"
[parameters]
r = 0.1
l = 0.3
k = 500
x0 = 0.3
[[springs]]
name = "spring"
stiffness = "k"
rest_length = "x0"
length = "x"
[[constraints]]
name = "rod"
holonomic = "(x - r*cos(theta))^2 + (r*sin(theta))^2 - l^2"
""")
    eom = derive(model)
    s = symbols(model)
    assert not eom.has_inertia
    assert sp.expand(eom.static_conditions[1] + s["k"] * (s["x"] - s["x0"])) == 0


def test_time_dependence_at_rest_is_decided_by_value():
    model = parse_model("""
[coordinates]
x = "m"
[parameters]
m = 1.0
k = 4.0
W = 3.0
[energy]
T = "m*x_dot^2/2"
V = "k*(sin(W*t)^2 + cos(W*t)^2)*x^2/2 + x*t*x_dot"
""")
    eom = derive(model)
    assert model.time in eom.forcing[0].free_symbols  # t is there by form ...
    assert eom.rest_is_time_invariant  # ... but not by value
    assert not eom_of("support_pendulum").rest_is_time_invariant
    assert eom_of("bead_on_hoop").rest_is_time_invariant
    # V = x t x_dot is a generalized potential with explicit t: h changes by -dL/dt = x x_dot
    assert eom.invariant_kind == "work_balance"


def test_an_identity_in_t_is_no_explicit_time_for_the_invariant():
    model = parse_model("""
[coordinates]
x = "m"
[parameters]
m = 1.0
k = 4.0
W = 3.0
[energy]
T = "m*x_dot^2/2"
V = "k*(1 + sin(2*W*t) - 2*sin(W*t)*cos(W*t))*x^2/2"
""")
    eom = derive(model)
    assert eom.power != 0  # by form
    assert eom.invariant_kind == "energy"  # by value
