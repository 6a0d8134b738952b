"""Rigid bodies in space: Euler's equations, tops and pendulums in closed form, and an
independent derivation by sympy.physics.mechanics."""

import math
import random

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import (
    LagrangesMethod,
    Lagrangian,
    Point,
    ReferenceFrame,
    RigidBody,
    dynamicsymbols,
    inertia,
)

import lagrangian
from lagrangian.model.builder import ModelBuilder

EULER = [["z", "phi"], ["x", "theta"], ["z", "psi"]]


def _free_body(I1, I2, I3):
    b = ModelBuilder("free body")
    for name in ("phi", "theta", "psi"):
        b.coordinate(name, "rad")
    b.add_rigid_body("body", 1, [I1, I2, I3], position=[0, 0, 0], rotation=EULER)
    return lagrangian.System(b.build_model())


def _omega_and_rate(system, q, q_dot):
    """Body-axes omega and its time derivative from the equations' accelerations."""
    model = system.model
    body = model.rigid_bodies[0]
    q_ddot, _ = system.numeric(backend="numpy").accelerations_and_multipliers(q, q_dot)
    point = dict(zip(model.q, q, strict=True)) | dict(zip(model.q_dot, q_dot, strict=True))
    omega = np.array([float(w.xreplace(point)) for w in body.angular_velocity])
    rate = np.array([
        float(sum(w.diff(x) * v for x, v in zip(model.q, model.q_dot, strict=True))
              .xreplace(point))
        + sum(float(w.diff(v).xreplace(point)) * a
              for v, a in zip(model.q_dot, q_ddot.ravel(), strict=True))
        for w in body.angular_velocity])
    return omega, rate


def test_torque_free_body_obeys_eulers_equations():
    I = np.array([1.0, 2.0, 2.5])
    system = _free_body(*map(float, I))
    rng = np.random.default_rng(1)
    for _ in range(5):
        q = rng.uniform(-2, 2, 3)
        q[1] = rng.uniform(0.3, 2.8)  # away from the z-x-z singularity at theta = 0
        omega, rate = _omega_and_rate(system, q, rng.uniform(-2, 2, 3))
        # I1 w1' = (I2 - I3) w2 w3 and cyclically
        expected = np.array([(I[1] - I[2]) * omega[1] * omega[2] / I[0],
                             (I[2] - I[0]) * omega[2] * omega[0] / I[1],
                             (I[0] - I[1]) * omega[0] * omega[1] / I[2]])
        assert rate == pytest.approx(expected, rel=1e-9, abs=1e-9)


def test_symmetric_body_precesses_at_the_closed_form_rate():
    I1, I3 = 2.0, 3.0
    system = _free_body(I1, I1, I3)
    omega, rate = _omega_and_rate(system, np.array([0.4, 1.1, -0.7]), np.array([0.8, 0.3, 2.0]))
    # In body axes (w1, w2) turns about the symmetry axis at Omega = (I3 - I1)/I1 w3; w3 is fixed.
    Omega = (I3 - I1) / I1 * omega[2]
    assert rate == pytest.approx([-Omega * omega[1], Omega * omega[0], 0.0], abs=1e-12)


def test_heavy_top_has_the_two_steady_precession_rates():
    system = lagrangian.load("heavy_top")
    p = system.parameters
    m, g, l, A, C = p["m"], p["g"], p["l"], p["A"], p["C"]
    A_pivot = A + m * l**2  # transverse moment about the pivot
    numeric = system.numeric(backend="numpy")
    theta, omega3 = 0.6, 80.0
    # theta_ddot = 0 at constant theta: A' Omega^2 cos(theta) - C omega3 Omega + m g l = 0
    root = math.sqrt(C**2 * omega3**2 - 4 * A_pivot * m * g * l * math.cos(theta))
    rates = [(C * omega3 + sign * root) / (2 * A_pivot * math.cos(theta)) for sign in (-1, 1)]
    assert 0 < rates[0] < rates[1] / 5  # slow and fast precession
    for Omega in rates:
        q_dot = np.array([Omega, 0.0, omega3 - Omega * math.cos(theta)])
        q_ddot, _ = numeric.accelerations_and_multipliers(np.array([0.2, theta, 1.0]), q_dot)
        assert q_ddot.ravel() == pytest.approx([0.0, 0.0, 0.0], abs=1e-9 * Omega**2)
    # and a rate between them is not steady: the top nods
    q_dot = np.array([10.0, 0.0, omega3 - 10.0 * math.cos(theta)])
    assert abs(numeric.accelerations_and_multipliers(np.array([0.0, theta, 0.0]), q_dot)[0][1]) > 1


def _spherical_pendulum():
    b = ModelBuilder("spherical compound pendulum")
    for name in ("a", "b", "c"):
        b.coordinate(name, "rad")
    for name, value in (("m", 2.0), ("g", 9.81), ("l", 0.7), ("Ix", 0.3), ("Iy", 0.2),
                        ("Iz", 0.15)):
        b.parameter(name, value)
    b.set_gravity("g", [0, 0, -1])
    b.add_rigid_body("link", "m", ["Ix", "Iy", "Iz"],
                     joint={"type": "spherical", "rotation": [["x", "a"], ["y", "b"],
                                                               ["z", "c"]]},
                     center=[0, 0, "-l"])
    return lagrangian.System(b.build_model())


def test_spherical_pendulum_reduces_to_the_planar_compound_pendulum():
    system = _spherical_pendulum()
    p = system.parameters
    numeric = system.numeric(backend="numpy")
    for a, a_dot in ((0.5, 0.0), (-1.2, 2.0), (2.5, -1.0)):
        q_ddot, _ = numeric.accelerations_and_multipliers(np.array([a, 0.0, 0.0]),
                                                          np.array([a_dot, 0.0, 0.0]))
        planar = -p["m"] * p["g"] * p["l"] * math.sin(a) / (p["Ix"] + p["m"] * p["l"] ** 2)
        assert q_ddot.ravel() == pytest.approx([planar, 0.0, 0.0], abs=1e-12)


PLANAR = """
[coordinates]
theta = "rad"
[parameters]
m = 1.5
I = 0.2
Ix = 0.15
Iy = 0.3
l = 0.4
g = 9.81
k = 30.0
tau = 0.7
F = 2.0
[gravity]
g = "g"
direction = {direction}
[[bodies]]
name = "link"
mass = "m"
{body}
[[springs]]
name = "spring"
stiffness = "k"
rest_length = 0.1
between = [{{ body = "link", offset = {offset} }}, {ground}]
[[loads]]
name = "push"
point = {{ body = "link", offset = {offset} }}
force = {force}
[[loads]]
name = "drive"
{drive}
"""


def test_planar_model_written_with_3d_keys_gives_the_same_equations():
    planar = lagrangian.parse_model(PLANAR.format(
        direction="[0, -1]", body='inertia = "I"\nposition = ["l*sin(theta)", "-l*cos(theta)"]\n'
        'angle = "theta"', offset='[0.3, 0.1]', ground="[1, 0]", force='["F", 0]',
        drive='torque = "tau"\nangle = "link"'))
    spatial = lagrangian.parse_model(PLANAR.format(
        direction="[0, -1, 0]", body='inertia = ["Ix", "Iy", "I"]\n'
        'position = ["l*sin(theta)", "-l*cos(theta)", 0]\nrotation = [["z", "theta"]]',
        offset='[0.3, 0.1, 0]', ground="[1, 0, 0]", force='["F", 0, 0]',
        drive='body = "link"\nmoment = [0, 0, "tau"]'))
    a, b = (lagrangian.System(m).equations_of_motion() for m in (planar, spatial))
    assert sp.simplify(a.mass_matrix - b.mass_matrix) == sp.zeros(1, 1)
    assert sp.simplify(a.forcing - b.forcing) == sp.zeros(1, 1)
    assert sp.simplify(a.lagrangian - b.lagrangian) == 0
    assert [(c.load, c.coordinate) for c in a.load_contributions] == \
        [(c.load, c.coordinate) for c in b.load_contributions]


def test_moment_enters_through_the_virtual_rotation():
    b = ModelBuilder("top with a moment")
    for name in ("phi", "theta", "psi"):
        b.coordinate(name, "rad")
    M = [b.parameter(name, 1.0) for name in ("Mx", "My", "Mz")]
    b.add_rigid_body("top", 1, [1, 1, 2], origin=[0, 0, 0], rotation=EULER)
    b.add_moment("world", "top", M)
    b.add_moment("spin", "top", [0, 0, "Mz"], axes="body")
    eom = lagrangian.System(b.build_model()).equations_of_motion()
    phi, theta, psi = sp.symbols("phi theta psi")
    Mx, My, Mz = M
    parts = {(c.load, c.coordinate): c.expression for c in eom.load_contributions}
    # delta(angle) = delta phi e_z + delta theta (line of nodes) + delta psi (body axis)
    nodes = (sp.cos(phi), sp.sin(phi), 0)
    axis = (sp.sin(theta) * sp.sin(phi), -sp.sin(theta) * sp.cos(phi), sp.cos(theta))
    expected = {("world", "phi"): Mz,
                ("world", "theta"): Mx * nodes[0] + My * nodes[1],
                ("world", "psi"): Mx * axis[0] + My * axis[1] + Mz * axis[2],
                ("spin", "phi"): Mz * sp.cos(theta), ("spin", "psi"): Mz}
    assert set(parts) == set(expected)
    for key, value in expected.items():
        assert sp.simplify(parts[key] - value) == 0, key


def _sympy_top(values):
    """The same body by sympy.physics.mechanics: frames, RigidBody, LagrangesMethod."""
    phi, theta, psi = q = dynamicsymbols("phi theta psi")
    N = ReferenceFrame("N")
    B = N.orientnew("B", "Body", (phi, theta, psi), "ZXZ")
    O = Point("O")
    O.set_vel(N, 0)
    s = {k: sp.Symbol(k) for k in values}
    G = O.locatenew("G", s["a"] * B.x + s["l"] * B.z)
    G.v2pt_theory(O, N, B)
    P = O.locatenew("P", 0.2 * B.x - 0.1 * B.y + 0.3 * B.z)
    P.v2pt_theory(O, N, B)
    dyadic = inertia(B, s["Ixx"], s["Iyy"], s["Izz"], s["Ixy"], s["Iyz"], s["Izx"])
    body = RigidBody("top", G, B, s["m"], (dyadic, G))
    body.potential_energy = s["m"] * s["g"] * G.pos_from(O).dot(N.z)
    loads = [(B, s["Mx"] * N.x + s["Mz"] * N.z), (P, s["F"] * N.y)]
    method = LagrangesMethod(Lagrangian(N, body), q, forcelist=loads, frame=N)
    method.form_lagranges_equations()
    return q, method.mass_matrix, method.forcing


def test_agrees_with_sympy_mechanics_at_random_states():
    values = dict(m=0.8, g=9.81, l=0.3, a=0.05, Ixx=0.05, Iyy=0.04, Izz=0.03, Ixy=0.004,
                  Iyz=-0.003, Izx=0.002, Mx=0.3, Mz=-0.2, F=1.1)
    b = ModelBuilder("asymmetric top")
    for name in ("phi", "theta", "psi"):
        b.coordinate(name, "rad")
    for name, value in values.items():
        b.parameter(name, value)
    b.set_gravity("g", [0, 0, -1])
    b.add_rigid_body("top", "m", [["Ixx", "Ixy", "Izx"], ["Ixy", "Iyy", "Iyz"],
                                  ["Izx", "Iyz", "Izz"]],
                     origin=[0, 0, 0], rotation=EULER, center=["a", 0, "l"])
    b.add_moment("moment", "top", ["Mx", 0, "Mz"])
    b.add_force("push", {"body": "top", "offset": [0.2, -0.1, 0.3]}, [0, "F", 0])
    eom = lagrangian.System(b.build_model()).equations_of_motion()
    q, M, f = _sympy_top(values)
    t = sp.Symbol("t")
    rng = random.Random(3)
    for _ in range(4):
        state = [rng.uniform(-2, 2) for _ in range(6)]
        ours = {s: v for s, v in zip((*eom.model.q, *eom.model.q_dot), state, strict=True)}
        theirs = {x.diff(t): v for x, v in zip(q, state[3:], strict=True)}
        theirs |= {x: v for x, v in zip(q, state[:3], strict=True)}
        constants = {sp.Symbol(k): v for k, v in values.items()}
        assert np.array(eom.mass_matrix.xreplace(ours).xreplace(constants), dtype=float) == \
            pytest.approx(np.array(M.xreplace(theirs).xreplace(constants), dtype=float),
                          rel=1e-12, abs=1e-14)
        assert np.array(eom.forcing.xreplace(ours).xreplace(constants), dtype=float) == \
            pytest.approx(np.array(f.xreplace(theirs).xreplace(constants), dtype=float),
                          rel=1e-12, abs=1e-14)


@pytest.mark.slow
def test_time_driven_rotation_and_varying_inertia_give_the_printed_lagrangians_equations():
    """A body on a turntable spun at Omega t (explicit time in R) whose inertia grows with a
    coordinate: the equations are exactly Euler-Lagrange applied to the printed L."""
    b = ModelBuilder("turntable")
    b.coordinate("theta", "rad")
    b.coordinate("s")
    for name, value in (("Omega", 2.0), ("g", 9.81), ("k", 5.0)):
        b.parameter(name, value)
    b.set_gravity("g", (0, 0, -1))
    b.add_rigid_body("arm", "1 + s^2", ["0.1 + s^2", "0.2 + s^2", "0.25 + s^2"],
                     origin=[0, 0, 0], center=["s", 0, 0.1],
                     rotation=[["z", "Omega*t"], ["y", "theta"]])
    b.add_spring("return", "k", 0.5, length="s")
    eom = lagrangian.System(b.build_model()).equations_of_motion()
    t = sp.Symbol("t")
    L = eom.lagrangian
    q, v, a = eom.model.q, eom.model.q_dot, eom.model.q_ddot
    functions = {x: sp.Function(str(x))(t) for x in q}
    to_time = dict(functions) | {vi: functions[x].diff(t) for x, vi in zip(q, v, strict=True)}
    back = {functions[x].diff(t, 2): ai for x, ai in zip(q, a, strict=True)}
    back |= {functions[x].diff(t): vi for x, vi in zip(q, v, strict=True)}
    back |= {functions[x]: x for x in q}
    moving = L.xreplace(to_time)
    rng = random.Random(5)
    for i, x in enumerate(q):
        brute = (moving.diff(functions[x].diff(t)).diff(t) - moving.diff(functions[x]))
        brute = brute.xreplace(back).xreplace(back).xreplace(back)
        ours = (eom.mass_matrix * sp.Matrix(a) - eom.forcing)[i]
        for _ in range(3):
            point = {symbol: rng.uniform(-1.5, 1.5) for symbol in (*q, *v, *a, t)}
            point |= {p.symbol: p.value for p in eom.model.parameters}
            assert float(ours.xreplace(point)) == pytest.approx(float(brute.xreplace(point)),
                                                                rel=1e-10, abs=1e-10)
    assert t in eom.kinetic_energy.free_symbols  # the printed T shows the driven spin
