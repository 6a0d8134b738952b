"""An independent derivation by Newton-Euler, compared with Lagrange coordinate by coordinate.

Free bodies: each particle and planar body obeys m a_G = F + R and I alpha = M_G + M_R, with
a_G and alpha from the positions as functions of time differentiated twice (sympy's own d/dt,
not the Lagrange kinematics), every applied force an explicit vector (gravity m g, spring
tension k (l - l0) along the unit vector between its ends, damper force, loads), and unknown
reactions R. Ideal reactions do no virtual work, so projecting onto the virtual displacements
dr/dq_i eliminates them (with constraints, the multiplier terms Phi_q^T lambda remain, the same
on both sides):

    E_i = sum_b [(m a_G - F) . dr_G/dq_i + (I alpha - M_G) dangle/dq_i]

which must equal Lagrange's (M q_ddot - f)_i identically. The reaction on each body is then
R = m a_G - F (and M_R = I alpha - M_G about its centre of mass), with q_ddot solved from E.

A body in space obeys Euler's equations in body axes, I alpha + omega x I omega = M_G, with
omega from omega~ = R^T R_dot by sympy's own d/dt of its rotation matrix (not the model's
composed omega); its rotational part of E_i is (I alpha + omega x I omega - M_G) . d omega/d q_dot_i.
The reaction at a body in space's joint (its origin J: a pivot, a joint on its parent, or the
body's own reference point) is what its parent or the ground exerts on it and on every body it
carries: summed over that subtree, R_J = sum (m a_G - F) and, about J in world axes,
M_J = sum [(r_G - r_J) x (m a_G - F) + R (I alpha + omega x I omega) - M_G]. For a free body
on a rolling contact (no joint), that is the contact force (its moment about J from the contact
point's arm).

A spring or damper given ``between`` two points acts on the particles or bodies at its ends,
equal and opposite (on a body also with its moment about G from the end's offset); one given by
its length only still enters the virtual work, but then no reactions are reported.

The free bodies, the forces on them and E_i are drawn in free_bodies.py; here they are compared
with Lagrange's equations, and the reactions solved.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..errors import LagrangianError
from ..model.expressions import format_expression as fmt
from ..model.model import Model
from ..model.structure import complex_values
from ..model.values import resolve_parameters, resolve_state
from . import equivalence as eq
from .crosscheck_report import CoordinateAgreement, CrosscheckReport, Reaction
from .free_bodies import (
    _AppliedForces,
    _Clock,
    _free_bodies,
    _FreeBody,
    _projected_equations,
    _require_free_bodies,
    carried,
)
from .jets import UnsupportedExpression
from .newton_euler_numeric import numeric_crosscheck, wants_numeric

SYMBOLIC_REACTIONS_MAX_UNKNOWNS = 3
SOLVED_MAX_OPS = 60  # beyond this, reactions read better in terms of the accelerations


def crosscheck(eom: EquationsOfMotion) -> CrosscheckReport:
    """Derive by Newton-Euler and compare with ``eom`` (Lagrange) coordinate by coordinate."""
    model = eom.model
    _require_free_bodies(model)
    if wants_numeric(model):
        try:
            return numeric_crosscheck(eom)
        except UnsupportedExpression:
            pass  # a function the jets do not know: the symbolic route, however long
    points = eq.random_points(model)
    clock = _Clock(model)
    bodies = _free_bodies(model, clock)
    forces = _AppliedForces(model, bodies, points)
    forces.add_gravity()
    forces.add_loads()
    forces.add_springs()
    forces.add_dampers(clock)
    forces.add_given_generalized_forces()
    newton_euler = _projected_equations(model, bodies, forces.work)
    agreements = _compare(eom, newton_euler, points)
    notes = forces.notes
    reactions: tuple[Reaction, ...] = ()
    if forces.unattributed:
        notes.append("reactions not reported: the forces of "
                     + ", ".join(f"'{u}'" for u in forces.unattributed)
                     + " cannot be placed on a free body from the model")
    else:
        if model.rigid_bodies:
            notes.append("bodies in space ("
                         + ", ".join(f"'{b.name}'" for b in model.rigid_bodies)
                         + ") are checked by Euler's equations; the reaction at each one's joint "
                         "is the force and moment (about the joint, world axes) that its parent "
                         "or the ground exerts on it and the bodies it carries")
        reactions = _at_initial_state(eom, _reactions(eom, bodies, newton_euler, notes))
    return CrosscheckReport(model.name, agreements, reactions, tuple(notes))


def _at_initial_state(eom: EquationsOfMotion, reactions: tuple[Reaction, ...]
                      ) -> tuple[Reaction, ...]:
    """Each reaction's value at the initial state: q, q_dot, t and the parameters substituted,
    [[M, Phi_q^T], [Phi_q, 0]] [q_ddot; lambda] = [f; gamma] solved there by numpy. A reaction
    in space on the accelerations runs to thousands of characters; its numbers still read."""
    model = eom.model
    if not reactions:
        return reactions
    try:
        parameters = resolve_parameters(model).symbol_values(model)
    except LagrangianError:
        return reactions  # a parameter without a value
    values = {**parameters, **{s: sp.Float(v)
                               for s, v in resolve_state(model).symbol_values(model).items()}}

    def real(numbers: list[complex]) -> list[float]:
        if any(abs(z.imag) > 1e-12 * max(1.0, abs(z.real)) for z in numbers):
            raise ValueError("a complex value")
        return [z.real for z in numbers]

    def number(matrix) -> np.ndarray:
        matrix = sp.Matrix(matrix)
        return np.array(real(complex_values(list(matrix), values)),
                        dtype=float).reshape(matrix.shape)

    n, m = len(model.q), eom.multipliers.shape[0]
    try:
        M, f = number(eom.mass_matrix), number(eom.forcing).ravel()
        A = number(eom.constraint_jacobian) if m else np.zeros((0, n))
        gamma = number(eom.acceleration_rhs).ravel() if m else np.zeros(0)
        K = np.block([[M, A.T], [A, np.zeros((m, m))]])
        solved = np.linalg.solve(K, np.concatenate([f, gamma]))
    except (TypeError, ValueError, ArithmeticError, np.linalg.LinAlgError):
        return reactions  # symbols left (no value) or singular at this state
    if not np.all(np.isfinite(solved)):
        return reactions
    values.update({s: sp.Float(v) for s, v in zip([*model.q_ddot, *eom.multipliers], solved,
                                                   strict=True)})
    out = []
    for r in reactions:
        try:
            numbers = tuple(real(complex_values(r.components, values)))
        except (TypeError, ValueError, ArithmeticError):
            out.append(r)
            continue
        out.append(Reaction(r.joint, r.labels, r.components, numbers))
    return tuple(out)


def _compare(eom: EquationsOfMotion, newton_euler: list[sp.Expr],
             points: eq.Points) -> tuple[CoordinateAgreement, ...]:
    """Each E_i against Lagrange's (M q_ddot - f)_i, identically (at random points)."""
    lagrange = list(eom.mass_matrix * eom.acceleration_symbols - eom.forcing)
    agreements = []
    verdicts = eq.identical_pairs(list(zip(newton_euler, lagrange, strict=True)), points)
    for c, ne, la, same in zip(eom.model.coordinates, newton_euler, lagrange, verdicts,
                               strict=True):
        difference = None if same else fmt(eq.display(sp.expand(ne - la)) if eq.is_small(ne - la)
                                           else ne - la)
        agreements.append(CoordinateAgreement(c.name, same, difference, ne))
    return tuple(agreements)


def _reactions(eom: EquationsOfMotion, bodies: list[_FreeBody], newton_euler: list[sp.Expr],
               notes: list[str]) -> tuple[Reaction, ...]:
    model = eom.model
    n, m = len(model.q), eom.multipliers.shape[0]
    solution: dict[sp.Symbol, sp.Expr] = {}
    # Bodies in space: solving for q_ddot and tidying with trig identities takes minutes (the
    # rotation's trigonometry), so their reactions stay in terms of the accelerations.
    if n + m <= SYMBOLIC_REACTIONS_MAX_UNKNOWNS and not model.rigid_bodies:
        residual = sp.Matrix(newton_euler)
        if m:
            residual += eom.constraint_jacobian.T * eom.multipliers
        unknowns = list(model.q_ddot) + list(eom.multipliers)
        A, b = eq.linear_system(list(residual), list(model.q_ddot) + list(eom.multipliers))
        if m:
            A = A.col_join(sp.Matrix(eom.constraint_jacobian).row_join(sp.zeros(m, m)))
            b = b.col_join(-sp.Matrix(eom.acceleration_rhs))
        try:
            values = A.LUsolve(-b)
            solution = {u: sp.cancel(v) for u, v in zip(unknowns, values, strict=True)}
            # A solved form this large reads worse than the accelerations themselves.
            if any(sp.count_ops(v) > SOLVED_MAX_OPS for v in solution.values()):
                solution = {}
        except (ValueError, ZeroDivisionError, sp.matrices.exceptions.NonInvertibleMatrixError):
            solution = {}
    if not solution:
        notes.append("reactions are given in terms of the accelerations"
                     + (" and multipliers" if m else "") + " (their solved form is too large)")
    planar = not model.rigid_bodies and all(
        fb.position[2] == 0 and fb.acceleration[2] == 0 and fb.force[2] == 0 for fb in bodies)
    reactions = []
    for fb in bodies:
        if fb.rotation is not None:
            continue  # a body in space: at its joint, below
        force = [fb.mass * a - f for a, f in zip(fb.acceleration, fb.force, strict=True)]
        labels = ["R_x", "R_y", "R_z"]
        components = force[:2] if planar else force
        labels = labels[:len(components)]
        if fb.angle is not None:
            components.append(fb.inertia * fb.angular_acceleration - fb.moment)
            labels.append("M_z")
        values = tuple(_tidy(v.xreplace(solution)) for v in components)
        reactions.append(Reaction(fb.name, tuple(labels), values))
    for body, force, moment in _joint_reactions(model, bodies):
        values = tuple(v.xreplace(solution) for v in (*force, *moment))
        reactions.append(Reaction(body, ("R_x", "R_y", "R_z", "M_x", "M_y", "M_z"), values))
    return tuple(reactions)


def _joint_reactions(model: Model, bodies: list[_FreeBody]):
    """(body, R_J, M_J) at each body in space's joint J (its origin): the sums over the subtree
    it heads of m a_G - F (N) and, about J in world axes, (r_G - r_J) x (m a_G - F) +
    R (I alpha + omega x I omega) - M_G (N m)."""
    free = {fb.name: fb for fb in bodies}
    subtrees = carried(model)
    for body in model.rigid_bodies:
        joint = sp.Matrix(body.origin)
        force, moment = sp.zeros(3, 1), sp.zeros(3, 1)
        for name in subtrees[body.name]:
            fb = free[name]
            inertial = sp.Matrix([fb.mass * a - f for a, f in zip(fb.acceleration, fb.force,
                                                                  strict=True)])
            I, w = fb.body_inertia, sp.Matrix(fb.omega)
            spin = fb.rotation * (I * sp.Matrix(fb.alpha) + w.cross(I * w))
            force += inertial
            moment += (sp.Matrix(fb.position) - joint).cross(inertial) + spin \
                - sp.Matrix(fb.moment3)
        yield body.name, list(force), list(moment)


def _tidy(expr: sp.Expr) -> sp.Expr:
    if not eq.is_small(expr):
        return expr
    radicals = [power for power in expr.atoms(sp.Pow) if not power.exp.is_integer]
    if radicals:
        # A spring between two points brings its length sqrt(|d|^2): trigsimp and cancel on
        # the whole term are slow and multiply the roots out, so only the radicands are tidied.
        try:
            return expr.xreplace({r: sp.Pow(sp.trigsimp(r.base), r.exp) for r in radicals})
        except Exception:  # noqa: BLE001 - tidying only costs readability
            return expr
    try:
        return sp.factor(sp.trigsimp(sp.cancel(expr)))
    except Exception:  # noqa: BLE001 - tidying only costs readability
        return expr


__all__ = ["crosscheck"]
