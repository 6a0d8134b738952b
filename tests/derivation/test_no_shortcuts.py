"""The printed equations are the Euler-Lagrange equations of the printed L, whatever depends on
q, q_dot or t: closed forms for masses and inertias that change, and a property-based comparison
with a brute-force derivation that shares nothing with ours (sympy's own d/dt on q(t))."""

from __future__ import annotations

import random

import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from sympy.physics.mechanics import dynamicsymbols

from lagrangian.derivation.lagrange import derive
from lagrangian.model.builder import ModelBuilder
from lagrangian.model.model import Body, Particle, PointForce, Torque
from lagrangian.model.reader import parse_model
from variable_models import BEAD_ON_SPINNING_HOOP, ROTOR_WITH_BEAD

t = sp.Symbol("t")


def symbols(model):
    names = {p.name: p.symbol for p in model.parameters}
    for c in model.coordinates:
        names.update({c.name: c.symbol, c.velocity.name: c.velocity,
                      c.acceleration.name: c.acceleration})
    return names


def test_rotor_with_a_sliding_bead_keeps_the_coriolis_and_centrifugal_terms():
    eom = derive(parse_model(ROTOR_WITH_BEAD))
    s = symbols(eom.model)
    I0, m, r, rd, w = s["I0"], s["m"], s["r"], s["r_dot"], s["phi_dot"]
    # d/dt((I0 + m r^2) phi_dot) = 0 and m r_ddot - m r phi_dot^2 = 0
    expected = [(I0 + m * r**2) * s["phi_ddot"] + 2 * m * r * rd * w,
                m * s["r_ddot"] - m * r * w**2]
    for ours, theirs in zip(eom.equations, expected, strict=True):
        assert sp.expand(ours - theirs) == 0
    assert sp.expand(eom.kinetic_energy - ((I0 + m * r**2) * w**2 + m * rd**2) / 2) == 0


def test_figure_skater_with_a_prescribed_inertia_conserves_angular_momentum():
    model = parse_model("""
[coordinates]
phi = "rad"
[parameters]
I0 = 3.0
a = 0.5
w = 2.0
[[bodies]]
name = "skater"
mass = 60
inertia = "I0*(1 + a*sin(w*t))"
position = [0, 0]
angle = "phi"
""")
    eom = derive(model)
    s = symbols(model)
    inertia = s["I0"] * (1 + s["a"] * sp.sin(s["w"] * t))
    # The equation is d/dt(I phi_dot) = I phi_ddot + I_dot phi_dot = 0: I phi_dot is conserved.
    assert sp.expand(eom.equations[0] - (inertia * s["phi_ddot"]
                                         + inertia.diff(t) * s["phi_dot"])) == 0


def test_variable_length_pendulum():
    model = parse_model("""
[coordinates]
theta = "rad"
[parameters]
m = 1.0
g = 9.81
l0 = 1.0
a = 0.2
w = 3.0
[definitions]
l = "l0 + a*sin(w*t)"
[gravity]
g = "g"
[[particles]]
name = "bob"
mass = "m"
position = ["l*sin(theta)", "-l*cos(theta)"]
""")
    eom = derive(model)
    s = symbols(model)
    length = s["l0"] + s["a"] * sp.sin(s["w"] * t)
    theta = s["theta"]
    expected = (s["m"] * length**2 * s["theta_ddot"]
                + 2 * s["m"] * length * length.diff(t) * s["theta_dot"]
                + s["m"] * s["g"] * length * sp.sin(theta))
    assert sp.simplify(eom.equations[0] - expected) == 0


def test_mass_that_depends_on_position_under_gravity():
    """A bucket filling as it falls, m(y) = m0 + k (h - y), with T = 1/2 m y_dot^2, V = m g y."""
    model = parse_model("""
[coordinates]
y = "m"
[parameters]
m0 = 1.0
k = 0.3
h = 2.0
g = 9.81
[gravity]
g = "g"
[[particles]]
name = "bucket"
mass = "m0 + k*(h - y)"
position = [0, "y"]
""")
    eom = derive(model)
    s = symbols(model)
    y, yd = s["y"], s["y_dot"]
    mass = s["m0"] + s["k"] * (s["h"] - y)
    L = mass * yd**2 / 2 - mass * s["g"] * y
    # d/dt(m y_dot) - dL/dy = m y_ddot + dm/dy y_dot^2 - 1/2 dm/dy y_dot^2 + g (m + dm/dy y)
    expected = (L.diff(yd).diff(yd) * s["y_ddot"] + L.diff(yd).diff(y) * yd - L.diff(y))
    assert sp.expand(eom.equations[0] - expected) == 0


# -- property-based: random models from every component kind ------------------------------------

PARAMETERS = {"a": 0.7, "b": 1.3, "c": 0.4, "k": 2.5, "g": 9.81}


def _brute_force(model, state: dict) -> list[float]:
    """d/dt(dL/dq_dot) - dL/dq + dD/dq_dot - Q + Phi_q^T lambda at ``state``, from the model's
    components alone, with sympy's own d/dt on functions of time.

    Each coordinate is a function q(t) and its velocity a function u(t) (u = dq/dt: positions
    are differentiated with sympy's chain rule, which gives dq/dt, replaced by u). Partial
    derivatives by q and u go through stand-in symbols; the total d/dt of dL/du is sympy's.
    """
    q_of_t = {c.symbol: dynamicsymbols(c.name) for c in model.coordinates}
    u_of_t = {c.symbol: dynamicsymbols(f"{c.name}_u") for c in model.coordinates}
    # Parameters are constants: their values go in first, which keeps the expressions small.
    to_time = {p.symbol: sp.Rational(str(p.value)) for p in model.parameters}
    to_time.update(q_of_t)
    to_time.update({c.velocity: u_of_t[c.symbol] for c in model.coordinates})
    rates = {q_of_t[c.symbol].diff(t): u_of_t[c.symbol] for c in model.coordinates}

    def timed(expr):
        return sp.sympify(expr).xreplace(to_time)

    def dt(vector):  # velocity of a point, in u
        return [timed(x).diff(t).xreplace(rates) for x in vector]

    T, V, D = timed(model.kinetic_energy), timed(model.potential_energy), timed(model.dissipation)
    gravity = model.gravity
    for item in (*model.particles, *model.bodies):
        v = dt(item.position)
        T += timed(item.mass) * sp.Add(*(x**2 for x in v)) / 2
        if isinstance(item, Body):
            T += timed(item.inertia) * dt([item.angle])[0] ** 2 / 2
        if gravity is not None:
            V -= timed(item.mass) * gravity.magnitude * sp.Add(
                *(d * timed(x) for d, x in zip(gravity.direction, item.position, strict=True)))
    for spring in model.springs:
        V += timed(spring.stiffness) * (timed(spring.length) - timed(spring.rest_length)) ** 2 / 2
    for damper in model.dampers:
        D += timed(damper.coefficient) * timed(damper.rate) ** 2 / 2
    L = timed(T - V)
    stand_in = {f: sp.Dummy(str(f.func)) for f in (*q_of_t.values(), *u_of_t.values())}
    back = {v: k for k, v in stand_in.items()}

    def partial(expr, x):
        return expr.xreplace(stand_in).diff(stand_in[x]).xreplace(back)

    given = dict(model.generalized_forces)
    residuals = []
    for c in model.coordinates:
        q, u = q_of_t[c.symbol], u_of_t[c.symbol]
        expression = (partial(L, u).diff(t) - partial(L, q) + partial(D, u)
                      - timed(given.get(c.name, 0)))
        for load in model.loads:
            if isinstance(load, PointForce):
                expression -= sp.Add(*(timed(f) * partial(timed(x), q)
                                       for f, x in zip(load.force, load.point, strict=True)))
            elif isinstance(load, Torque):
                expression -= timed(load.torque) * partial(timed(load.angle), q)
        for constraint in model.constraints:
            lam = state[sp.Symbol(f"lambda_{constraint.name}")]
            if constraint.kind == "holonomic":
                expression += partial(timed(constraint.expression), q) * lam
            else:
                expression += partial(timed(constraint.expression), u) * lam
        residuals.append(expression)
    values = {}
    for c in model.coordinates:
        q, u = q_of_t[c.symbol], u_of_t[c.symbol]
        values[u.diff(t)] = state[c.acceleration]
        values[q.diff(t)] = state[c.velocity]
    functions = {q_of_t[c.symbol]: state[c.symbol] for c in model.coordinates}
    functions.update({u_of_t[c.symbol]: state[c.velocity] for c in model.coordinates})
    return [complex(e.xreplace(values).xreplace(functions).xreplace({t: state[t]}).evalf(30))
            for e in residuals]


MASSES = ["1", "b", "1 + a*q0^2", "2 + sin(q1)", "1 + t/3", "b + c*cos(q0)*t"]
INERTIAS = ["c", "a + b*q0^2", "1 + sin(t)/2", "c*(2 + cos(q1))"]
TERMS = ["q0", "a*sin(q1)", "b*cos(q1)", "q0*q1", "sin(q0 + t)", "a*cos(q0 - q1)", "c*t", "1"]
ANGLES = ["q1", "q0 + q1", "2*q1 + t", "a*q0"]
COEFFICIENTS = ["k", "k*(1 + q0^2)", "c + t/4", "k*(2 + sin(q1))"]
FORCE_TERMS = ["a", "q0_dot", "b*sin(t)", "c*q1*q0_dot", "-q1_dot*cos(q0)", "t*q1"]


@st.composite
def random_models(draw):
    b = ModelBuilder("random")
    b.coordinate("q0")
    b.coordinate("q1", unit="rad")
    for name, value in PARAMETERS.items():
        b.parameter(name, value)

    # planar models with bodies, or 3D ones of particles only (a body is planar)
    dimension = draw(st.sampled_from([2, 2, 3]))

    def position():  # each component moves with q (a load needs a moving point)
        return [" + ".join([draw(st.sampled_from(TERMS[:-2]))]
                           + draw(st.lists(st.sampled_from(TERMS), max_size=1)))
                for _ in range(dimension)]

    if draw(st.booleans()):
        directions = [(0, -1), (1, -2), ("sin(a)", "-cos(a)")] if dimension == 2 else \
            [(0, 0, -1), (1, "b", -2)]
        b.set_gravity("g", draw(st.sampled_from(directions)))
    points: list[object] = [[0] * dimension]
    for i in range(draw(st.integers(1, 2))):
        b.add_particle(f"p{i}", draw(st.sampled_from(MASSES)), position())
        points.append(f"p{i}")
    for i in range(draw(st.integers(0, 1 if dimension == 2 else 0))):
        b.add_body(f"b{i}", draw(st.sampled_from(MASSES)), draw(st.sampled_from(INERTIAS)),
                   position(), draw(st.sampled_from(ANGLES)))
        points.append({"body": f"b{i}", "offset": [draw(st.sampled_from(["a", "0.5"])), "c"]})
    for i in range(draw(st.integers(0, 2))):
        stiffness, rest = draw(st.sampled_from(COEFFICIENTS)), draw(st.sampled_from(["0", "a", "t/5"]))
        if draw(st.booleans()):
            ends = draw(st.lists(st.sampled_from(points), min_size=2, max_size=2, unique_by=str))
            b.add_spring(f"s{i}", stiffness, rest, between=ends)
        else:
            b.add_spring(f"s{i}", stiffness, rest, length=draw(st.sampled_from(TERMS)))
    for i in range(draw(st.integers(0, 1))):
        coefficient = draw(st.sampled_from(COEFFICIENTS))
        if draw(st.booleans()):
            ends = draw(st.lists(st.sampled_from(points), min_size=2, max_size=2, unique_by=str))
            b.add_damper(f"d{i}", coefficient, between=ends)
        else:
            b.add_damper(f"d{i}", coefficient,
                         rate=draw(st.sampled_from(["q0_dot", "q1_dot*cos(q0) + t*q0_dot"])))
    for i in range(draw(st.integers(0, 2))):
        if draw(st.booleans()):
            point = draw(st.sampled_from(points[1:]))
            force = [draw(st.sampled_from(FORCE_TERMS)) for _ in range(dimension)]
            b.add_force(f"f{i}", point, force)
        else:
            b.add_torque(f"tau{i}", draw(st.sampled_from(FORCE_TERMS)),
                         draw(st.sampled_from(ANGLES)))
    if draw(st.booleans()):
        b.add_kinetic_energy(draw(st.sampled_from(["a*q0_dot*q1_dot*cos(q1)",
                                                   "c*(1 + t)*q1_dot^2/2", "b*q0*q0_dot*t"])))
    if draw(st.booleans()):
        b.add_potential_energy(draw(st.sampled_from(["b*q0^2*t", "c*q0_dot*q1", "k*cos(q1)"])))
    if draw(st.booleans()):
        b.add_dissipation("c*q0_dot^2*(1 + q1^2)/2")
    if draw(st.booleans()):
        b.add_generalized_force("q1", draw(st.sampled_from(FORCE_TERMS)))
    constraint = draw(st.sampled_from([None, "holonomic", "velocity"]))
    if constraint == "holonomic":
        b.add_constraint("h", holonomic=draw(st.sampled_from(["q0 - a*sin(q1) - t/5",
                                                              "q0^2 + q1^2*b - 1"])))
    elif constraint == "velocity":
        b.add_constraint("v", velocity="q0_dot - b*cos(q1)*q1_dot + t/7")
    return b.build_model()


@pytest.mark.slow
@settings(max_examples=20, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(random_models())
def test_random_models_match_a_brute_force_euler_lagrange_derivation(model):
    eom = derive(model, check=False)
    rng = random.Random(7)
    for _ in range(2):
        state = {p.symbol: sp.Float(p.value, 30) for p in model.parameters}
        for c in model.coordinates:
            for symbol in (c.symbol, c.velocity, c.acceleration):
                state[symbol] = sp.Float(rng.uniform(-1.2, 1.2), 30)
        for k in eom.multipliers:
            state[k] = sp.Float(rng.uniform(-1, 1), 30)
        state[t] = sp.Float(rng.uniform(0.1, 2.0), 30)
        theirs = _brute_force(model, state)
        ours = [complex(e.xreplace(state).evalf(30)) for e in eom.equations]
        for a, b in zip(ours, theirs, strict=True):
            assert a == pytest.approx(b, rel=1e-10, abs=1e-10)


def test_the_brute_force_sees_a_dropped_term():
    """The comparison has teeth: the rotor without its 2 m r r_dot phi_dot term differs."""
    model = parse_model(ROTOR_WITH_BEAD)
    state = {s: sp.Float(v, 30) for s, v in zip(
        (*(p.symbol for p in model.parameters), *model.q, *model.q_dot, *model.q_ddot),
        (0.2, 0.5, 2.0, 0.3, 0.8, 1.1, -0.7, 0.4, 0.9), strict=True)}
    state[t] = sp.Float(0.5, 30)
    theirs = _brute_force(model, state)
    s = symbols(model)
    wrong = (s["I0"] + s["m"] * s["r"] ** 2) * s["phi_ddot"]  # the old shortcut's equation
    assert complex(wrong.xreplace(state)) != pytest.approx(theirs[0], rel=1e-6)
    ours = derive(model).equations[0]
    assert complex(ours.xreplace(state)) == pytest.approx(theirs[0], rel=1e-12)


def test_particles_alone_need_no_shortcut_terms():
    """Constant masses: the structure path is untouched (M = m J^T J, no extra forcing)."""
    b = ModelBuilder("free")
    x = b.coordinate("x")
    b.add_particle("p", 2, [x, 0])
    eom = derive(b.build_model())
    assert eom.forcing[0] == 0
    assert isinstance(b.build_model().particles[0], Particle)


def test_bead_on_a_spinning_hoop_in_3d_reads_as_in_the_rotating_frame():
    """sin^2(Omega t) + cos^2(Omega t) is recognized inside longer products, so the inertial
    description prints the rotating-frame T, M and f, with no t left."""
    import lagrangian

    inertial = derive(parse_model(BEAD_ON_SPINNING_HOOP))
    rotating = derive(lagrangian.load("bead_on_hoop").model)
    s = symbols(inertial.model)
    assert inertial.mass_matrix == sp.Matrix([[s["R"] ** 2 * s["m"]]])
    assert sp.expand(inertial.forcing[0] - rotating.forcing[0]) == 0
    assert sp.expand(inertial.kinetic_energy - rotating.kinetic_energy) == 0
    assert inertial.model.time not in inertial.lagrangian.free_symbols
    assert inertial.invariant_kind == "jacobi_integral"


def test_a_damper_between_two_masses_on_a_line_is_c_times_the_relative_velocity():
    model = parse_model(BASE_LINE + '[[dampers]]\nname = "d"\ncoefficient = "c"\n'
                        'between = ["a", "b"]\n')
    eom = derive(model)
    s = symbols(model)
    assert eom.generalized_forces[0] == -s["c"] * (s["x1_dot"] - s["x2_dot"])
    assert sp.expand(eom.dissipation - s["c"] * (s["x1_dot"] - s["x2_dot"]) ** 2 / 2) == 0


BASE_LINE = """
[coordinates]
x1 = "m"
x2 = "m"
[parameters]
m = 1.0
c = 0.5
[[particles]]
name = "a"
mass = "m"
position = ["x1", 0]
[[particles]]
name = "b"
mass = "m"
position = ["x2", 0]
"""
