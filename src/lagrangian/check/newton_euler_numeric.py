"""Newton-Euler for deep trees of bodies in space, formed numerically at random states.

The symbolic crosscheck differentiates each body's position and rotation twice with sympy's
d/dt; down a chain of 20 bodies in space those expressions are products of 20 rotations, and
their second derivatives (then their comparison with Lagrange's) take hours. Here the same
free-body equations are formed with numbers: each position r(q) and rotation R(q) is carried
along q(t) = q + q_dot t + q_ddot t^2/2 as a second-order Taylor jet (jets.py), giving a_G,
omega (from R^T R_dot) and alpha exactly, and dr/dq_i, d omega/d q_dot_i from the same jets with
q_dot = e_i. Then, at every random state (random parameters too),

    E_i = sum_b [m a_G . dr_G/dq_i + (I alpha + omega x I omega) . d omega/d q_dot_i] - Q_i

is compared with Lagrange's (M q_ddot - f)_i evaluated at that state. It is still a derivation
independent of Lagrange's (no energy, no partial derivative of L), from the model's own
geometry; only the equations are not printed, and the reactions are given as numbers at the
initial state.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..errors import LagrangianError
from ..model.model import Model
from ..model.values import resolve_parameters, resolve_state
from . import equivalence as eq
from .crosscheck_report import CoordinateAgreement, CrosscheckReport, Reaction
from .free_bodies import (
    _AppliedForces,
    _Clock,
    _FreeBody,
    _require_free_bodies,
    carried,
    free_body,
)
from .jets import JetEvaluator, UnsupportedExpression

# A body more than this many elementary rotations from the ground is checked numerically: the
# symbolic route's cost grows with the product of the chain's rotations (a chain of 4: 15 s,
# of 8: 100 s); the Whipple bicycle's deepest body (its front wheel, 5) stays symbolic.
NUMERIC_ABOVE = 5
RELATIVE_TOLERANCE = 1e-9


def wants_numeric(model: Model) -> bool:
    """Whether crosscheck forms Newton-Euler with numbers (a tree of bodies in space this deep)."""
    return any(body.depth > NUMERIC_ABOVE for body in model.rigid_bodies)


class _PositionsOnly(_Clock):
    """No symbolic d/dt: the jets give the rates."""

    def first(self, expr):
        return sp.S.Zero

    def first_with_velocities(self, expr):
        return sp.S.Zero

    def second(self, expr):
        return sp.S.Zero


class _RecordedForces(_AppliedForces):
    """The applied forces with their projections kept as (force, point) and (moment, body)
    pairs, for the jets to project, instead of symbolic dr/dq_i."""

    def __init__(self, model, bodies, points):
        super().__init__(model, bodies, points)
        self.forces: list[tuple[list, tuple]] = []
        self.moments: list[tuple[list, _FreeBody]] = []

    def project(self, force, point) -> None:
        self.forces.append((list(force), tuple(point)))

    def turn(self, moment, holder: _FreeBody) -> None:
        self.moments.append((list(moment), holder))


class _Lanes:
    """Lane layout: block 0 holds the states (q, q_dot, q_ddot); block 1 + i the same q with
    q_dot = e_i and q_ddot = 0, whose first jet coefficients are the Jacobians d/dq_i."""

    def __init__(self, model: Model, states: np.ndarray, parameters: dict,
                 directions: bool = True):
        n = len(model.q)
        k = states.shape[0]
        self.n, self.k = n, k
        blocks = n + 1 if directions else 1  # without: values at the states only (M and f)
        lanes = k * blocks
        q, v, a, t = states[:, :n], states[:, n:2 * n], states[:, 2 * n:3 * n], states[:, 3 * n]
        jets = {}
        for j, c in enumerate(model.coordinates):
            direction = np.repeat(np.eye(n)[j][None, :], k, axis=0)  # (k, n): e_i's j-th entry
            rate = np.concatenate([v[:, j], *direction.T[:blocks - 1]])
            accel = np.concatenate([a[:, j], np.zeros(k * (blocks - 1))])
            value = np.tile(q[:, j], blocks)
            jets[c.symbol] = np.stack((value, rate, accel / 2))
            jets[c.velocity] = np.stack((rate, accel, np.zeros(lanes)))
            jets[c.acceleration] = np.stack((accel, np.zeros(lanes), np.zeros(lanes)))
        clock = np.concatenate([np.ones(k), np.zeros(k * (blocks - 1))])
        jets[model.time] = np.stack((np.tile(t, blocks), clock, np.zeros(lanes)))
        for symbol, value in parameters.items():
            jets[symbol] = np.stack((np.full(lanes, value), np.zeros(lanes), np.zeros(lanes)))
        self.evaluate = JetEvaluator(jets, lanes)

    def state(self, jet: np.ndarray, order: int = 0) -> np.ndarray:
        """Coefficient ``order`` at the states (block 0): (k,)."""
        return jet[order, :self.k]

    def along(self, jet: np.ndarray) -> np.ndarray:
        """d/dq_i (d/dq_dot_i of a rate) at the states: (n, k)."""
        return jet[1, self.k:].reshape(self.n, self.k)

    def vector(self, exprs) -> np.ndarray:
        return np.stack([self.evaluate(e) for e in exprs])  # (3, 3, lanes)


def _spin(lanes: _Lanes, rotation) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """omega and alpha (body axes) of R(q(t)) at every lane: vee of the skew part of R^T R_dot
    and of R^T R_ddot (R_dot^T R_dot is symmetric), and R itself."""
    R = np.stack([[lanes.evaluate(e) for e in row] for row in rotation])  # (3, 3, 3, lanes)
    rate = np.einsum("jil,jkl->ikl", R[:, :, 0], R[:, :, 1])
    accel = np.einsum("jil,jkl->ikl", R[:, :, 0], 2 * R[:, :, 2])

    def vee(w):
        return 0.5 * np.stack((w[2, 1] - w[1, 2], w[0, 2] - w[2, 0], w[1, 0] - w[0, 1]))
    return vee(rate), vee(accel), R[:, :, 0]


def _inertial_terms(lanes: _Lanes, bodies: list[_FreeBody]) -> tuple[np.ndarray, dict]:
    """sum_b m a_G . dr/dq_i + I alpha dtheta/dq_i + (I alpha + w x I w) . dw/dq_dot_i: (n, k),
    with each body's numbers (a_G, alpha, ...) kept for the reactions."""
    total = np.zeros((lanes.n, lanes.k))
    kept = {}
    for fb in bodies:
        mass = lanes.state(lanes.evaluate(fb.mass))
        position = [lanes.evaluate(r) for r in fb.position]
        accel = np.stack([2 * lanes.state(p, 2) for p in position])  # (3, k)
        for p, a in zip(position, accel, strict=True):
            total += mass * a * lanes.along(p)
        numbers = {"mass": mass, "acceleration": accel}
        if fb.angle is not None:
            angle = lanes.evaluate(fb.angle)
            alpha = 2 * lanes.state(angle, 2)
            inertia = lanes.state(lanes.evaluate(fb.inertia))
            total += inertia * alpha * lanes.along(angle)
            numbers.update(alpha=alpha, inertia=inertia)
        if fb.rotation is not None:
            omega, alpha, R = _spin(lanes, fb.rotation.tolist())
            inertia = np.stack([[lanes.state(lanes.evaluate(e)) for e in row]
                                for row in fb.body_inertia.tolist()])  # (3, 3, k)
            w, al = omega[:, :lanes.k], alpha[:, :lanes.k]
            Iw = np.einsum("ijk,jk->ik", inertia, w)
            euler = np.einsum("ijk,jk->ik", inertia, al) + np.cross(w, Iw, axis=0)
            partial = omega[:, lanes.k:].reshape(3, lanes.n, lanes.k)
            total += np.einsum("ik,ink->nk", euler, partial)
            numbers.update(euler=euler, rotation=R[:, :, :lanes.k])
        kept[fb.name] = numbers
    return total, kept


def _generalized_forces(lanes: _Lanes, forces: _RecordedForces) -> np.ndarray:
    """Q_i: F . dr/dq_i of every force at its point, M . d omega/d q_dot_i of every moment
    (world axes), and the terms given directly: (n, k)."""
    Q = np.zeros((lanes.n, lanes.k))
    for force, point in forces.forces:
        for f, r in zip(force, point, strict=True):
            if f != 0:
                Q += lanes.state(lanes.evaluate(f)) * lanes.along(lanes.evaluate(r))
    for moment, holder in forces.moments:
        omega, _, R = _spin(lanes, holder.rotation.tolist())
        world = np.einsum("ijl,jl->il", R, omega)  # (3, lanes)
        for i, m in enumerate(moment):
            Q += lanes.state(lanes.evaluate(m)) * world[i, lanes.k:].reshape(lanes.n, lanes.k)
    for i, terms in enumerate(forces.work):
        for term in terms:
            Q[i] += lanes.state(lanes.evaluate(term))
    return Q


def _lagrange(lanes: _Lanes, eom: EquationsOfMotion) -> np.ndarray:
    """(M q_ddot - f)_i at the states, with numbers: (n, k)."""
    M = np.stack([[lanes.state(lanes.evaluate(e)) for e in row]
                  for row in eom.mass_matrix.tolist()])  # (n, n, k)
    f = np.stack([lanes.state(lanes.evaluate(e)) for e in eom.forcing])
    accelerations = np.stack([lanes.state(lanes.evaluate(s)) for s in eom.acceleration_symbols])
    return np.einsum("ijk,jk->ik", M, accelerations) - f


def _random_states(model: Model, points: eq.Points) -> tuple[np.ndarray, list[dict]]:
    index = {s: j for j, s in enumerate(points.symbols)}
    order = [*model.q, *model.q_dot, *model.q_ddot, model.time]
    states = np.array([[float(p[index[s]]) for s in order] for p in points.values])
    state = set(order)
    parameters = [{s: float(p[index[s]]) for s in points.symbols if s not in state}
                  for p in points.values]
    return states, parameters


def numeric_crosscheck(eom: EquationsOfMotion) -> CrosscheckReport:
    """Newton-Euler against Lagrange at random states, formed with jets (see the module)."""
    model = eom.model
    _require_free_bodies(model)
    points = eq.random_points(model)
    clock = _PositionsOnly(model)
    bodies = [free_body(item, clock)
              for item in (*model.particles, *model.bodies, *model.rigid_bodies)]
    forces = _RecordedForces(model, bodies, points)
    forces.add_gravity()
    forces.add_loads()
    forces.add_springs()
    forces.add_dampers(_Clock(model))
    forces.add_given_generalized_forces()
    states, parameters = _random_states(model, points)
    differences = np.zeros((len(model.q), 0))
    scales = np.zeros((len(model.q), 0))
    for group in points.groups:  # the parameters are shared within a group
        at, values = states[list(group)], parameters[group[0]]
        lanes = _Lanes(model, at, values)
        inertial, _ = _inertial_terms(lanes, bodies)
        newton_euler = inertial - _generalized_forces(lanes, forces)
        lagrange = _lagrange(_Lanes(model, at, values, directions=False), eom)
        differences = np.hstack([differences, newton_euler - lagrange])
        scales = np.hstack([scales, np.abs(inertial) + np.abs(lagrange) + 1e-300])
    agreements = []
    for i, c in enumerate(model.coordinates):
        relative = np.abs(differences[i]) / scales[i]
        finite = np.isfinite(relative)
        same = bool(finite.any()) and bool(np.all(relative[finite] <= RELATIVE_TOLERANCE))
        worst = int(np.argmax(np.where(finite, relative, -1)))
        difference = None if same else (
            f"{differences[i, worst]:.6g} at a random state (relative {relative[worst]:.2g}; "
            "the Newton-Euler side was formed numerically, so no expression is printed)")
        agreements.append(CoordinateAgreement(c.name, same, difference, None))
    notes = list(forces.notes)
    notes.append(f"a tree of {len(model.rigid_bodies)} bodies in space: Newton-Euler was formed "
                 f"numerically (second-order jets of each body's position and rotation) at "
                 f"{len(points.values)} random states and parameter values, not printed as "
                 "expressions; reactions are given at the initial state")
    reactions: tuple[Reaction, ...] = ()
    if forces.unattributed:
        notes.append("reactions not reported: the forces of "
                     + ", ".join(f"'{u}'" for u in forces.unattributed)
                     + " cannot be placed on a free body from the model")
    else:
        reactions = _reactions_at_initial_state(eom, bodies, notes)
    return CrosscheckReport(model.name, tuple(agreements), reactions, tuple(notes))


def _reactions_at_initial_state(eom: EquationsOfMotion, bodies: list[_FreeBody],
                                notes: list[str]) -> tuple[Reaction, ...]:
    """Each body's reaction (as the symbolic crosscheck defines it) in numbers at the model's
    initial state, the accelerations and multipliers solved from M, f there."""
    model = eom.model
    try:
        values = resolve_parameters(model).symbol_values(model)
        state = resolve_state(model).symbol_values(model)
    except LagrangianError:
        notes.append("reactions not reported: a parameter or initial value is not given")
        return ()
    n, m = len(model.q), eom.multipliers.shape[0]
    q = np.array([[float(state[s]) for s in model.q]])
    v = np.array([[float(state[s]) for s in model.q_dot]])
    t = float(state.get(model.time, 0.0))
    known = {s: float(x) for s, x in values.items()}
    zero = np.hstack([q, v, np.zeros((1, n)), [[t]]])
    lanes = _Lanes(model, zero, {**known, **{s: 0.0 for s in eom.multipliers}},
                   directions=False)
    try:
        M = np.array([[lanes.state(lanes.evaluate(e))[0] for e in row]
                      for row in eom.mass_matrix.tolist()])
        f = np.array([lanes.state(lanes.evaluate(e))[0] for e in eom.forcing])
        A = np.array([[lanes.state(lanes.evaluate(e))[0] for e in row]
                      for row in eom.constraint_jacobian.tolist()]).reshape(m, n)
        gamma = np.array([lanes.state(lanes.evaluate(e))[0] for e in eom.acceleration_rhs])
        K = np.block([[M, A.T], [A, np.zeros((m, m))]])
        solved = np.linalg.solve(K, np.concatenate([f, gamma]))
    except (UnsupportedExpression, np.linalg.LinAlgError, ValueError):
        notes.append("reactions not reported: M is singular at the initial state")
        return ()
    at = np.hstack([q, v, solved[None, :n], [[t]]])
    multipliers = dict(zip(eom.multipliers, solved[n:], strict=True))
    lanes = _Lanes(model, at, {**known, **multipliers})
    try:
        return tuple(_reactions(model, lanes, bodies))
    except UnsupportedExpression:
        notes.append("reactions not reported: a force holds a function not evaluated here")
        return ()


def _reactions(model: Model, lanes: _Lanes, bodies: list[_FreeBody]):
    _, kept = _inertial_terms(lanes, bodies)
    number = {fb.name: fb for fb in bodies}

    def value(expr) -> float:
        return float(lanes.state(lanes.evaluate(expr))[0])

    planar = not model.rigid_bodies and all(fb.position[2] == 0 and fb.force[2] == 0 for fb in bodies)
    for fb in bodies:
        if fb.rotation is not None:
            continue
        k = kept[fb.name]
        components = [float(k["mass"][0] * a[0]) - value(f) for a, f in zip(k["acceleration"],
                                                                      fb.force, strict=True)]
        components = components[:2] if planar else components
        labels = ["R_x", "R_y", "R_z"][:len(components)]
        if fb.angle is not None:
            components.append(float(k["inertia"][0] * k["alpha"][0]) - value(fb.moment))
            labels.append("M_z")
        yield Reaction(fb.name, tuple(labels), tuple(sp.Float(c) for c in components),
                       tuple(components))
    subtrees = carried(model)
    for body in model.rigid_bodies:
        joint = np.array([value(c) for c in body.origin])
        force, moment = np.zeros(3), np.zeros(3)
        for name in subtrees[body.name]:
            fb, k = number[name], kept[name]
            inertial = k["mass"][0] * k["acceleration"][:, 0] - np.array([value(c) for c in
                                                                         fb.force])
            position = np.array([value(c) for c in fb.position])
            force += inertial
            moment += np.cross(position - joint, inertial) + k["rotation"][:, :, 0] @ \
                k["euler"][:, 0] - np.array([value(c) for c in fb.moment3])
        numbers = tuple(float(x) for x in (*force, *moment))
        yield Reaction(body.name, ("R_x", "R_y", "R_z", "M_x", "M_y", "M_z"),
                       tuple(sp.Float(x) for x in numbers), tuple(numbers))


__all__ = ["NUMERIC_ABOVE", "numeric_crosscheck", "wants_numeric"]
