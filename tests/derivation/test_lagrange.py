"""Lagrange's equations checked against independent derivations and closed forms."""

import math
import random

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

import lagrangian
from lagrangian.errors import DerivationError, ModelError

t = sp.Symbol("t")


def brute_force_residuals(eom):
    """d/dt(dL/dq_dot) - dL/dq - Q (+ Phi_q^T lambda) by sympy's own time differentiation of q(t).

    Independent of our structured formula: q becomes q(t), L and Q are rewritten in it and the
    Euler-Lagrange operator is applied literally.
    """
    model = eom.model
    functions = [dynamicsymbols(c.name) for c in model.coordinates]
    to_time = {}
    for c, f in zip(model.coordinates, functions, strict=True):
        to_time[c.symbol] = f
        to_time[c.velocity] = f.diff(t)
    back = {}
    for c, f in zip(model.coordinates, functions, strict=True):
        back[f.diff(t, 2)] = c.acceleration
        back[f.diff(t)] = c.velocity
        back[f] = c.symbol
    # xreplace, not subs: the same literal rewriting without subs' pattern matching (the
    # bicycle's brute force 51 s -> 6 s)
    L = eom.lagrangian.xreplace(to_time)
    D = eom.dissipation.xreplace(to_time)
    residuals = []
    for i, (c, f) in enumerate(zip(model.coordinates, functions, strict=True)):
        qd = f.diff(t)
        expression = L.diff(qd).diff(t) - L.diff(f) + D.diff(qd)
        # Q from loads other than dampers/dissipation (those came in through D above).
        given = sum((part.expression for part in eom.load_contributions
                     if part.coordinate == c.name and part.load not in
                     {d.name for d in model.dampers} | {"dissipation"}), sp.S.Zero)
        expression -= given.xreplace(to_time)
        for k in range(eom.multipliers.rows):
            expression += eom.constraint_jacobian[k, i].xreplace(to_time) * eom.multipliers[k]
        residuals.append(expression.xreplace(back))
    return residuals


def random_point(eom, seed=0):
    rng = random.Random(seed)
    values = {}
    for p in eom.model.parameters:
        values[p.symbol] = p.value if p.value is not None else rng.uniform(0.5, 2)
    for c in eom.model.coordinates:
        values[c.symbol] = rng.uniform(-1, 1) + (c.initial or 0)
        values[c.velocity] = rng.uniform(-1, 1)
        values[c.acceleration] = rng.uniform(-1, 1)
    for s in eom.multipliers:
        values[s] = rng.uniform(-1, 1)
    values[t] = rng.uniform(0, 2)
    return {k: sp.Float(v, 30) for k, v in values.items()}


@pytest.mark.parametrize("name", lagrangian.examples())
def test_every_example_matches_a_brute_force_euler_lagrange_derivation(name):
    eom = lagrangian.load(name).equations_of_motion()
    brute = brute_force_residuals(eom)
    for seed in range(3):
        point = random_point(eom, seed)
        for ours, theirs in zip(eom.equations, brute, strict=True):
            a, b = complex(ours.xreplace(point).evalf(30)), complex(theirs.xreplace(point).evalf(30))
            assert a == pytest.approx(b, rel=1e-12, abs=1e-12)


def test_double_pendulum_matches_the_textbook_equations():
    system = lagrangian.load("double_pendulum")
    eom = system.equations_of_motion()
    t1, t2, w1, w2, a1, a2, m1, m2, l1, l2, g = (system.symbol(n) for n in (
        "theta1", "theta2", "theta1_dot", "theta2_dot", "theta1_ddot", "theta2_ddot",
        "m1", "m2", "l1", "l2", "g"))
    # Hand derivation (e.g. Goldstein), absolute angles:
    hand = [
        (m1 + m2) * l1**2 * a1 + m2 * l1 * l2 * a2 * sp.cos(t1 - t2)
        + m2 * l1 * l2 * w2**2 * sp.sin(t1 - t2) + (m1 + m2) * g * l1 * sp.sin(t1),
        m2 * l2**2 * a2 + m2 * l1 * l2 * a1 * sp.cos(t1 - t2)
        - m2 * l1 * l2 * w1**2 * sp.sin(t1 - t2) + m2 * g * l2 * sp.sin(t2),
    ]
    for ours, theirs in zip(eom.equations, hand, strict=True):
        assert sp.simplify(sp.expand_trig(ours - theirs)) == 0


def test_cartesian_pendulum_multiplier_form_gives_the_pendulum_motion():
    cartesian = lagrangian.load("cartesian_pendulum").equations_of_motion()
    polar = lagrangian.load("pendulum").equations_of_motion()
    assert cartesian.multipliers.rows == 1  # one multiplier per constraint
    x, y, xd, yd = sp.symbols("x y x_dot y_dot")
    theta, theta_dot = sp.symbols("theta theta_dot")
    L_rod = 0.5
    numbers = {sp.Symbol("m"): 1.0, sp.Symbol("L"): L_rod, sp.Symbol("g"): 9.81}
    for th, w in [(0.3, 0.0), (1.2, -2.0), (-2.5, 1.5)]:
        state = {x: L_rod * math.sin(th), y: -L_rod * math.cos(th),
                 xd: L_rod * math.cos(th) * w, yd: L_rod * math.sin(th) * w}
        M = np.array(cartesian.mass_matrix.xreplace(numbers), dtype=float)
        f = np.array(cartesian.forcing.xreplace(numbers).xreplace(state), dtype=float).ravel()
        A = np.array(cartesian.constraint_jacobian.xreplace(numbers).xreplace(state), dtype=float)
        gamma = np.array(cartesian.acceleration_rhs.xreplace(state), dtype=float).ravel()
        kkt = np.block([[M, A.T], [A, np.zeros((1, 1))]])
        xdd, ydd, lam = np.linalg.solve(kkt, np.concatenate([f, gamma]))
        # theta_ddot from the polar equation; x_ddot follows by differentiating x = L sin(theta)
        thdd = float(polar.accelerations[0].xreplace(numbers).xreplace({theta: th, theta_dot: w}))
        assert xdd == pytest.approx(L_rod * (math.cos(th) * thdd - math.sin(th) * w**2))
        assert ydd == pytest.approx(L_rod * (math.sin(th) * thdd + math.cos(th) * w**2))
        # rod tension m g cos(theta) + m L w^2 = 2 L lambda (force -lambda Phi_q on the bob)
        assert 2 * L_rod * lam == pytest.approx(9.81 * math.cos(th) + L_rod * w**2)


def test_prescribed_support_motion_explicit_time():
    system = lagrangian.load("support_pendulum")
    eom = system.equations_of_motion()
    theta, m, L, g, A, Omega = (system.symbol(n) for n in ("theta", "m", "L", "g", "A", "Omega"))
    x_s_ddot = -A * Omega**2 * sp.cos(Omega * t)
    expected = m * L**2 * system.symbol("theta_ddot") + m * L * x_s_ddot * sp.cos(theta) \
        + m * g * L * sp.sin(theta)
    assert sp.simplify(eom.equations[0] - expected) == 0


def test_velocity_dependent_lagrangian_charged_particle():
    system = lagrangian.load("charged_particle")
    eom = system.equations_of_motion()
    m, q, B = (system.symbol(n) for n in ("m", "q", "B"))
    xd, yd = system.symbol("x_dot"), system.symbol("y_dot")
    # Lorentz force q v x B with B along z: m x'' = q B y', m y'' = -q B x'
    assert eom.accelerations[0] == q * B * yd / m
    assert eom.accelerations[1] == -q * B * xd / m


def test_nonholonomic_rolling_uses_multipliers_not_substitution():
    system = lagrangian.load("rolling_cylinder")
    eom = system.equations_of_motion()
    g, alpha, m = (system.symbol(n) for n in ("g", "alpha", "m"))
    assert eom.accelerations[0] == 2 * g * sp.sin(alpha) / 3
    # the multiplier is the friction force: m x'' = m g sin(alpha) - lambda
    lam = m * g * sp.sin(alpha) - m * eom.accelerations[0]
    assert sp.simplify(lam - m * g * sp.sin(alpha) / 3) == 0
    assert eom.constraint_jacobian.shape == (1, 2)


def test_physical_pendulum_from_a_body():
    b = lagrangian.SystemBuilder("rod")
    theta = b.coordinate("theta", unit="rad")
    m, L, g = b.parameter("m", 2.0), b.parameter("L", 1.0), b.parameter("g", 9.81)
    b.add_body("rod", m, m * L**2 / 12, (L / 2 * sp.sin(theta), -L / 2 * sp.cos(theta)), theta)
    b.set_gravity(g)
    eom = b.build().equations_of_motion()
    # I_pivot theta'' = -m g L/2 sin(theta) with I_pivot = m L^2 / 3
    assert sp.simplify(eom.accelerations[0] + 3 * g * sp.sin(theta) / (2 * L)) == 0


def test_builder_accepts_dynamicsymbols_and_strings():
    b = lagrangian.SystemBuilder("oscillator")
    b.coordinate("x")
    x = dynamicsymbols("x")
    m, k = sp.symbols("m k")
    b.parameter("m", 1.0)
    b.parameter("k", 4.0)
    b.add_kinetic_energy(m * x.diff(t) ** 2 / 2)
    b.add_potential_energy("1/2*k*x^2")
    eom = b.build().equations_of_motion()
    assert eom.accelerations[0] == -k * sp.Symbol("x") / m


def test_builder_rejects_undeclared_symbols():
    b = lagrangian.SystemBuilder()
    b.coordinate("x")
    with pytest.raises(ModelError, match="unknown symbol 'k': declare it with coordinate"):
        b.add_potential_energy(sp.Symbol("k") * sp.Symbol("x") ** 2)


def test_singular_mass_matrix_names_the_coordinate():
    model = lagrangian.parse_model(
        '[coordinates]\nx = "m"\ny = "m"\n[energy]\nT = "x_dot^2/2"\nV = "x^2 + y^2"\n',
        source="bad.toml")
    with pytest.raises(DerivationError) as info:
        lagrangian.System(model).equations_of_motion()
    assert str(info.value) == (
        "singular mass matrix: the kinetic energy does not contain the velocity of 'y', so its "
        "equation has no acceleration; give it inertia (a mass, a body or a T term) or remove "
        "the coordinate")


def test_singular_mass_matrix_without_zero_row():
    model = lagrangian.parse_model(
        '[coordinates]\nx = "m"\ny = "m"\n[energy]\nT = "(x_dot + y_dot)^2/2"\n')
    with pytest.raises(DerivationError, match="mass matrix W = d\\^2L/dq_dot\\^2 is singular: "
                       "the accelerations of x, y cannot be solved for"):
        lagrangian.System(model).equations_of_motion()


def test_massless_coordinate_fixed_by_a_constraint_is_fine():
    model = lagrangian.parse_model(
        '[coordinates]\nx = "m"\ny = "m"\n[energy]\nT = "x_dot^2/2"\n'
        '[[constraints]]\nname = "link"\nholonomic = "y - 2*x"\n')
    eom = lagrangian.System(model).equations_of_motion()
    assert eom.multipliers.rows == 1


def test_redundant_constraint_is_named():
    model = lagrangian.parse_model(
        '[coordinates]\nx = "m"\ny = "m"\n[energy]\nT = "(x_dot^2 + y_dot^2)/2"\n'
        '[[constraints]]\nname = "a"\nholonomic = "x - y"\n'
        '[[constraints]]\nname = "b"\nholonomic = "2*x - 2*y"\n')
    with pytest.raises(DerivationError) as info:
        lagrangian.System(model).equations_of_motion()
    assert str(info.value) == (
        "redundant constraint 'b': it depends on the constraints before it (a); remove it so "
        "that there is exactly one multiplier per independent constraint")


def test_load_contributions_are_reported_per_load():
    system = lagrangian.load("cart_pendulum")
    eom = system.equations_of_motion()
    parts = [(c.load, c.coordinate, c.expression) for c in eom.load_contributions]
    assert parts == [("push", "x", system.symbol("F"))]  # the push does no work on theta
    damped = lagrangian.load("damped_oscillator").equations_of_motion()
    assert [(c.load, str(c.expression)) for c in damped.load_contributions] == \
        [("damper", "-c*x_dot")]
    assert damped.dissipation == sp.Symbol("c") * sp.Symbol("x_dot") ** 2 / 2


def test_torque_load_projects_through_the_angle():
    b = lagrangian.SystemBuilder("two gears")
    a = b.coordinate("a", unit="rad")
    b.parameter("I", 1.0)
    tau = b.parameter("tau", 3.0)
    b.add_kinetic_energy("I*a_dot^2/2")
    b.add_torque("motor", tau, 2 * a)  # a 2:1 stage: the motor shaft turns through 2a
    eom = b.build().equations_of_motion()
    assert eom.generalized_forces[0] == 2 * tau
