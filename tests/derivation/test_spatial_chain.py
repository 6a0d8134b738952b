"""A spatial chain of rigid bodies on revolute joints (axes x, y, x, ...): the unexpanded
Jacobian form of the equations against the term-by-term path and sympy's KanesMethod, energy
conservation, and the general path kept where inertia depends on q or the motion on t."""

import random
import warnings

import numpy as np
import pytest
import sympy as sp

import lagrangian
from lagrangian.derivation.body_jacobians import takes_jacobian_form
from lagrangian.derivation.kinematics import Differentiator
from lagrangian.derivation.lagrange import derive
from lagrangian.derivation.regularity import numeric_matrix
from lagrangian.model.builder import ModelBuilder
from lagrangian.output.derivation import derivation_latex, derivation_text

INERTIA = (0.1, 0.08, 0.02)


def _chain(n, *, inertia=INERTIA, last_angle=None, name="chain"):
    """n links of 1 m hanging on joints about x, y, x, ...; centre of mass 0.5 m below each."""
    b = ModelBuilder(name)
    b.parameter("g", 9.81)
    b.set_gravity("g", (0, 0, -1))
    parent = None
    for i in range(n):
        b.coordinate(f"q{i}", "rad", initial=0.3 * (i + 1), rate=0.5 - 0.4 * i)
        b.parameter(f"m{i}", 1.0 + 0.25 * i)
        angle = last_angle if (last_angle and i == n - 1) else f"q{i}"
        joint = {"type": "revolute", "axis": "xy"[i % 2], "angle": angle}
        if parent:
            joint["at"] = [0, 0, -1]
        body_inertia = inertia(i) if callable(inertia) else list(inertia)
        b.add_rigid_body(f"link{i}", f"m{i}", body_inertia, parent=parent, joint=joint,
                         center=[0, 0, -0.5])
        parent = f"link{i}"
    return b.build_model()


def _kane_chain(n):
    """The same chain by sympy.physics.mechanics (System, PinJoint, KanesMethod)."""
    from sympy.physics.mechanics import (
        Inertia,
        PinJoint,
        ReferenceFrame,
        RigidBody,
        System,
        dynamicsymbols,
    )
    from sympy.utilities.exceptions import SymPyDeprecationWarning

    g = sp.Symbol("g")
    ground = RigidBody("ground", frame=ReferenceFrame("N"))
    system = System.from_newtonian(ground)
    previous = ground
    for i in range(n):
        frame = ReferenceFrame(f"B{i}")
        body = RigidBody(f"link{i}", frame=frame, mass=sp.Symbol(f"m{i}"))
        body.inertia = Inertia.from_inertia_scalars(body.masscenter, frame, *INERTIA)
        q, u = dynamicsymbols(f"q{i} u{i}")
        axis = previous.frame.x if i % 2 == 0 else previous.frame.y
        child_axis = frame.x if i % 2 == 0 else frame.y
        parent_point = previous.masscenter if i == 0 else previous.masscenter.locatenew(
            f"J{i}", -0.5 * previous.frame.z)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SymPyDeprecationWarning)  # parent_axis/child_axis
            joint = PinJoint(f"J{i}", previous, body, coordinates=q, speeds=u,
                             parent_point=parent_point, child_point=0.5 * frame.z,
                             parent_axis=axis, child_axis=child_axis)
        system.add_joints(joint)
        previous = body
    system.apply_uniform_gravity(-g * ground.frame.z)
    system.form_eoms()
    qs = [dynamicsymbols(f"q{i}") for i in range(n)]
    us = [dynamicsymbols(f"u{i}") for i in range(n)]
    return system.mass_matrix, system.forcing, qs, us


def _values(eom, point):
    """M and f at a point, in floats (each shared sub-expression evaluated once)."""
    values = point | {p.symbol: p.value for p in eom.model.parameters}
    return numeric_matrix(eom.mass_matrix, values), numeric_matrix(eom.forcing, values).ravel()


@pytest.mark.slow
def test_three_body_chain_jacobian_form_agrees_with_term_by_term_and_kane():
    model = _chain(3)
    unexpanded, expanded = derive(model, jacobian_form=True), derive(model, jacobian_form=False)
    K, k, qs, us = _kane_chain(3)
    constants = {sp.Symbol("g"): 9.81} | {sp.Symbol(f"m{i}"): 1.0 + 0.25 * i for i in range(3)}
    rng = random.Random(7)
    for _ in range(4):
        state = [rng.uniform(-2.5, 2.5) for _ in range(6)]
        point = dict(zip((*model.q, *model.q_dot), state, strict=True))
        M1, f1 = _values(unexpanded, point)
        M2, f2 = _values(expanded, point)
        theirs = dict(zip((*qs, *us), state, strict=True)) | constants
        M3 = np.array(K.xreplace(theirs), dtype=float)
        f3 = np.array(k.xreplace(theirs), dtype=float).ravel()
        for mine in (M1, M2):
            assert mine == pytest.approx(M3, rel=1e-12, abs=1e-12)
        for mine in (f1, f2):
            assert mine == pytest.approx(f3, rel=1e-12, abs=1e-12)


def test_deep_chain_takes_the_jacobian_form_by_size_and_shallow_bodies_stay_expanded():
    model = _chain(5)
    d, sizes = Differentiator(), {}
    taken = [takes_jacobian_form(b, model.q, model.time, d, sizes) for b in model.rigid_bodies]
    # the first bodies' expanded kinematics is short (textbook form), the deeper ones' is not
    assert taken[:2] == [False, False] and taken[-2:] == [True, True]


def test_two_body_chain_is_the_same_in_both_forms():
    model = _chain(2)
    unexpanded, expanded = derive(model, jacobian_form=True), derive(model, jacobian_form=False)
    rng = random.Random(3)
    for _ in range(3):
        point = {x: rng.uniform(-2.5, 2.5) for x in (*model.q, *model.q_dot)}
        for mine, theirs in zip(_values(unexpanded, point), _values(expanded, point),
                                strict=True):
            assert mine == pytest.approx(theirs, rel=1e-12, abs=1e-12)


@pytest.mark.slow
def test_four_body_chain_keeps_its_energy_in_simulation():
    """Energy from sympy's own derivatives of the body positions and omega (not from our T)."""
    model = _chain(4)
    system = lagrangian.System(model)
    run = system.simulate(3.0, samples=61)
    assert run.completed
    values = {p.symbol: p.value for p in model.parameters}
    energy = sp.S.Zero
    for body in model.rigid_bodies:
        velocity = [sum(sp.diff(r, x) * v for x, v in zip(model.q, model.q_dot, strict=True))
                    for r in body.position]
        omega = sp.Matrix(body.angular_velocity)
        energy += (body.mass * sum(v**2 for v in velocity) / 2
                   + (omega.T * sp.Matrix(body.inertia) * omega)[0] / 2
                   + body.mass * sp.Symbol("g") * body.position[2])  # V = m g z, g along -z
    function = sp.lambdify([*model.q, *model.q_dot], energy.xreplace(values))
    E = np.array([function(*q, *v) for q, v in zip(run.q, run.q_dot, strict=True)])
    assert np.ptp(run.q[:, 3]) > 0.5  # the chain really moves
    assert np.max(np.abs(E - E[0])) < 1e-7 * (1 + abs(E[0]))


def _euler_lagrange_residual(eom, rng, samples=2):
    """M q_ddot - f against d/dt dL/dq_dot - dL/dq of the printed L, by sympy's diff."""
    model = eom.model
    t = model.time
    q, v, a = model.q, model.q_dot, model.q_ddot
    functions = {x: sp.Function(str(x))(t) for x in q}
    to_time = dict(functions) | {vi: functions[x].diff(t) for x, vi in zip(q, v, strict=True)}
    back = {functions[x].diff(t, 2): ai for x, ai in zip(q, a, strict=True)}
    back |= {functions[x].diff(t): vi for x, vi in zip(q, v, strict=True)}
    back |= {functions[x]: x for x in q}
    moving = eom.lagrangian.xreplace(to_time)
    worst = 0.0
    for i, x in enumerate(q):
        brute = moving.diff(functions[x].diff(t)).diff(t) - moving.diff(functions[x])
        brute = brute.xreplace(back).xreplace(back).xreplace(back)
        ours = (eom.mass_matrix * sp.Matrix(a) - eom.forcing)[i]
        for _ in range(samples):
            point = {s: rng.uniform(-1.5, 1.5) for s in (*q, *v, *a, t)}
            point |= {p.symbol: p.value for p in model.parameters}
            worst = max(worst, abs(float(ours.xreplace(point)) - float(brute.xreplace(point))))
    return worst


@pytest.mark.slow
def test_inertia_depending_on_q_or_motion_on_t_takes_the_general_path_and_is_right():
    """A chain whose last joint is driven (angle q2 + Omega t) and whose middle link's inertia
    grows with q0: those bodies are never put in the Jacobian form, even when asked, and the
    equations are Euler-Lagrange applied to the printed L."""
    def inertia(i):
        return ["0.1 + q0^2", 0.08, 0.02] if i == 1 else list(INERTIA)

    b_model = _chain(3, inertia=inertia, last_angle="q2 + 2*t", name="driven chain")
    d, sizes = Differentiator(), {}
    taken = [takes_jacobian_form(b, b_model.q, b_model.time, d, sizes, force=True)
             for b in b_model.rigid_bodies]
    assert taken == [True, False, False]
    eom = derive(b_model, jacobian_form=True)
    assert _euler_lagrange_residual(eom, random.Random(11)) < 1e-9
    # and the same for the unforced choice and the fully term-by-term path
    other = derive(b_model, jacobian_form=False)
    point = {s: 0.3 + 0.1 * k for k, s in enumerate((*b_model.q, *b_model.q_dot, b_model.time))}
    for x, y in zip(_values(eom, point), _values(other, point), strict=True):
        assert x == pytest.approx(y, rel=1e-12, abs=1e-12)


@pytest.mark.slow
def test_unexpanded_equations_print_and_evaluate():
    """derive's text and LaTeX work on the nested forms (2-body chain, both bodies unexpanded)
    and come out about as long as the term-by-term form's; the numeric mass matrix of a 4-body
    chain is symmetric positive definite (T > 0 for every velocity)."""
    model = _chain(2)
    eom, expanded = derive(model, jacobian_form=True), derive(model, jacobian_form=False)
    text, latex = derivation_text(eom), derivation_latex(eom)
    for i in range(2):
        assert f"[q{i}]" in text and f"q_{{{i}}}" in latex
    assert len(text) < 1.5 * len(derivation_text(expanded))
    assert len(latex) < 1.5 * len(derivation_latex(expanded))
    numeric = lagrangian.System(_chain(4)).numeric(backend="numpy")
    M = numeric.mass_matrix(np.full(4, 0.2), np.full(4, 0.1))
    assert np.allclose(M, M.T) and np.all(np.linalg.eigvalsh(M) > 0)


@pytest.mark.slow
def test_spherical_prismatic_and_revolute_joints_agree_in_both_forms():
    """A body on a spherical joint (z-x-z), a slider along its axis and an arm on a revolute
    joint about a skew axis, full inertia tensor with products of inertia: the Jacobian form
    and the term-by-term form give the same M and f (gravity and a spring on the slider)."""
    b = ModelBuilder("mixed joints")
    for name in ("phi", "theta", "psi", "s", "beta"):
        b.coordinate(name, "m" if name == "s" else "rad")
    for name, value in (("g", 9.81), ("k", 40.0), ("m", 1.3), ("M", 0.7)):
        b.parameter(name, value)
    b.set_gravity("g", (0, 0, -1))
    b.add_rigid_body("base", "m", [0.3, 0.2, 0.15], parent=None, center=[0.1, 0, -0.4],
                     joint={"type": "spherical",
                            "rotation": [["z", "phi"], ["x", "theta"], ["z", "psi"]]})
    b.add_rigid_body("slider", "M", [[0.02, 0.003, 0], [0.003, 0.025, -0.002], [0, -0.002, 0.015]],
                     parent="base", joint={"type": "prismatic", "axis": "z", "distance": "s",
                                           "at": [0, 0.1, -0.8]}, center=[0, 0, -0.1])
    b.add_rigid_body("arm", 0.5, [0.01, 0.02, 0.02], parent="slider",
                     joint={"type": "revolute", "axis": [1, 1, 0], "angle": "beta",
                            "at": [0, 0, -0.2]}, center=[0.3, 0, 0])
    b.add_spring("slide", "k", 0.1, length="s")
    model = b.build_model()
    unexpanded, expanded = derive(model, jacobian_form=True), derive(model, jacobian_form=False)
    rng = random.Random(17)
    for _ in range(3):
        point = {x: rng.uniform(0.2, 1.3) for x in (*model.q, *model.q_dot)}
        for mine, theirs in zip(_values(unexpanded, point), _values(expanded, point),
                                strict=True):
            assert mine == pytest.approx(theirs, rel=1e-11, abs=1e-11)
