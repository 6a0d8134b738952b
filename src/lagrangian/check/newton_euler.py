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
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import singledispatch, singledispatchmethod

import numpy as np
import sympy as sp

from ..derivation.display import latex_with_rates
from ..derivation.equations import EquationsOfMotion
from ..errors import DerivationError, LagrangianError
from ..model.expressions import format_expression as fmt
from ..model.model import Attachment, Body, Damper, Model, Particle, PointForce, Spring, Torque
from ..model.rotations import Moment, RigidBody
from ..model.values import resolve_parameters, resolve_state
from . import equivalence as eq

SYMBOLIC_REACTIONS_MAX_UNKNOWNS = 3
SOLVED_MAX_OPS = 60  # beyond this, reactions read better in terms of the accelerations


@dataclass(frozen=True)
class CoordinateAgreement:
    """Newton-Euler vs Lagrange on one coordinate; ``difference`` = E_NE - E_Lagrange."""

    coordinate: str
    agree: bool
    difference: str | None
    newton_euler: sp.Expr


@dataclass(frozen=True)
class Reaction:
    """The resultant reaction on one body (the 'joint' is named after the body it acts on):
    force components (N) and, for a rigid body, the moment about its centre of mass (N m).
    For a body in space: the force and moment (about its joint, world axes x, y, z) at its
    joint, on it and the bodies it carries."""

    joint: str
    labels: tuple[str, ...]
    components: tuple[sp.Expr, ...]
    # N and N m at the model's initial state, the accelerations and multipliers from the
    # equations of motion there; None where a parameter has no value or M is singular there
    at_initial_state: tuple[float, ...] | None = None

    def _repr_latex_(self) -> str:
        rows = [rf"{label} &= {latex_with_rates(value)}" for label, value in zip(self.labels,
                                                                       self.components,
                                                                       strict=True)]
        return r"$\begin{aligned}" + r"\\ ".join(rows) + r"\end{aligned}$"


@dataclass(frozen=True)
class CrosscheckReport:
    """Whether Newton-Euler and Lagrange agree on every coordinate, with the reactions found."""

    model: str
    coordinates: tuple[CoordinateAgreement, ...]
    reactions: tuple[Reaction, ...]
    notes: tuple[str, ...]

    @property
    def agree(self) -> bool:
        return all(c.agree for c in self.coordinates)

    @property
    def passed(self) -> bool:
        """The crosscheck passed: the two derivations agree on every coordinate (``agree``)."""
        return self.agree

    def reaction(self, joint: str) -> Reaction:
        for r in self.reactions:
            if r.joint == joint:
                return r
        raise KeyError(joint)

    def __repr__(self) -> str:
        lines = [f"CrosscheckReport(agree={self.agree})"]
        lines += [f"  {c.coordinate}: {'agree' if c.agree else 'differ by ' + str(c.difference)}"
                  for c in self.coordinates]
        lines += [f"  reaction on {r.joint}: " + ", ".join(
            f"{label} = {fmt(v)}" for label, v in zip(r.labels, r.components, strict=True))
            for r in self.reactions]
        return "\n".join(lines)


@dataclass
class _FreeBody:
    name: str
    mass: sp.Expr
    position: tuple
    acceleration: list
    angle: sp.Expr | None = None
    inertia: sp.Expr = sp.S.Zero
    angular_acceleration: sp.Expr = sp.S.Zero
    force: list | None = None
    moment: sp.Expr = sp.S.Zero
    # a body in space: R (body -> world), I (body axes), omega and alpha (body axes), the moment
    # about G (world axes)
    rotation: sp.Matrix | None = None
    body_inertia: sp.Matrix | None = None
    omega: list | None = None
    alpha: list | None = None
    moment3: list | None = None


def crosscheck(eom: EquationsOfMotion) -> CrosscheckReport:
    """Derive by Newton-Euler and compare with ``eom`` (Lagrange) coordinate by coordinate."""
    model = eom.model
    _require_free_bodies(model)
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

    def number(matrix) -> np.ndarray:
        return np.array([[float(e.xreplace(values)) for e in row]
                         for row in sp.Matrix(matrix).tolist()], dtype=float).reshape(
                             sp.Matrix(matrix).shape)

    n, m = len(model.q), eom.multipliers.shape[0]
    try:
        M, f = number(eom.mass_matrix), number(eom.forcing).ravel()
        A = number(eom.constraint_jacobian) if m else np.zeros((0, n))
        gamma = number(eom.acceleration_rhs).ravel() if m else np.zeros(0)
        K = np.block([[M, A.T], [A, np.zeros((m, m))]])
        solved = np.linalg.solve(K, np.concatenate([f, gamma]))
    except (TypeError, ValueError, np.linalg.LinAlgError):
        return reactions  # symbols left (no value) or singular at this state
    if not np.all(np.isfinite(solved)):
        return reactions
    values.update({s: sp.Float(v) for s, v in zip([*model.q_ddot, *eom.multipliers], solved,
                                                   strict=True)})
    out = []
    for r in reactions:
        try:
            numbers = tuple(float(c.xreplace(values)) for c in r.components)
        except (TypeError, ValueError):
            out.append(r)
            continue
        out.append(Reaction(r.joint, r.labels, r.components, numbers))
    return tuple(out)


def _require_free_bodies(model: Model) -> None:
    """Newton-Euler draws free bodies: the inertia must come as particles and bodies."""
    if model.kinetic_energy != 0:
        raise DerivationError(
            "Newton-Euler needs the inertia as particles and bodies, but this model gives T as "
            "an expression ([energy] T): there is no free body to draw (build it from "
            "[[particles]]/[[bodies]], e.g. the example 'ladder_pendulum')")
    if not model.particles and not model.bodies and not model.rigid_bodies:
        raise DerivationError("Newton-Euler needs at least one particle or body")
    # F = m a and M = I alpha hold for a constant mass and inertia only; Lagrange's equations
    # of the printed L have m_dot and dm/dq terms that Newton-Euler would not reproduce.
    changing = set(model.q) | {model.time}
    for kind, item, quantity, value in (
        *(("particle", p, "mass", p.mass) for p in model.particles),
        *(("body", b, "mass", b.mass) for b in model.bodies),
        *(("body", b, "inertia", b.inertia) for b in model.bodies),
    ):
        found = sorted(str(s) for s in value.free_symbols & changing)
        if found:
            raise DerivationError(
                f"Newton-Euler (F = m a, M = I alpha) does not model {quantity} that changes "
                f"with {found[0]}: the {quantity} of {kind} '{item.name}' is {value}, so "
                "crosscheck cannot check this model (derive gives its Euler-Lagrange equations)")


class _Clock:
    """Time derivatives by sympy's own d/dt (q -> q(t)), independent of the Lagrange kinematics,
    written back in the plain symbols q, q_dot, q_ddot."""

    def __init__(self, model: Model):
        self.model = model
        self.to_time = {c.symbol: sp.Function(c.name)(model.time) for c in model.coordinates}
        self.velocities = {self.to_time[c.symbol].diff(model.time): c.velocity
                           for c in model.coordinates}
        self.accelerations = {self.to_time[c.symbol].diff(model.time, 2): c.acceleration
                              for c in model.coordinates}
        self.back = {f: s for s, f in self.to_time.items()}

    def first(self, expr: sp.Expr) -> sp.Expr:
        """d/dt of an expression in q (and t)."""
        moving = expr.xreplace(self.to_time).diff(self.model.time)
        return moving.xreplace(self.velocities).xreplace(self.back)

    def first_with_velocities(self, expr: sp.Expr) -> sp.Expr:
        """d/dt of an expression in q, q_dot (and t), written with q_ddot."""
        to_time = dict(self.to_time)
        to_time.update({c.velocity: self.to_time[c.symbol].diff(self.model.time)
                        for c in self.model.coordinates})
        moving = expr.xreplace(to_time).diff(self.model.time)
        return moving.xreplace(self.accelerations).xreplace(self.velocities).xreplace(self.back)

    def second(self, expr: sp.Expr) -> sp.Expr:
        """d^2/dt^2 of an expression in q (and t)."""
        moving = expr.xreplace(self.to_time).diff(self.model.time, 2)
        return moving.xreplace(self.accelerations).xreplace(self.velocities).xreplace(self.back)


def _free_bodies(model: Model, clock: _Clock) -> list[_FreeBody]:
    """One free body per particle and rigid body, with its accelerations a_G (and alpha)."""
    return [free_body(item, clock)
            for item in (*model.particles, *model.bodies, *model.rigid_bodies)]


# one entry per mass-carrying kind (tests/model/test_component_tables.py walks every kind)
@singledispatch
def free_body(component, clock: _Clock) -> _FreeBody:
    """The free body of ``component``: its mass, position and accelerations (m/s^2, rad/s^2)."""
    raise TypeError(f"no free body for a component of kind {type(component).__name__}")


@free_body.register
def _(particle: Particle, clock: _Clock) -> _FreeBody:
    return _FreeBody(particle.name, particle.mass, particle.position,
                     [clock.second(r) for r in particle.position], force=[sp.S.Zero] * 3)


@free_body.register
def _(body: Body, clock: _Clock) -> _FreeBody:
    return _FreeBody(body.name, body.mass, body.position,
                     [clock.second(r) for r in body.position], body.angle, body.inertia,
                     clock.second(body.angle), [sp.S.Zero] * 3)


@free_body.register
def _(rigid: RigidBody, clock: _Clock) -> _FreeBody:
    R = sp.Matrix(rigid.rotation)
    rate = R.applyfunc(clock.first)
    skew = R.T * rate  # omega~ in body axes
    omega = [skew[2, 1], skew[0, 2], skew[1, 0]]
    return _FreeBody(rigid.name, rigid.mass, rigid.position,
                     [clock.second(r) for r in rigid.position], force=[sp.S.Zero] * 3,
                     rotation=R, body_inertia=sp.Matrix(rigid.inertia), omega=omega,
                     alpha=[clock.first_with_velocities(w) for w in omega],
                     moment3=[sp.S.Zero] * 3)


class _AppliedForces:
    """The applied forces: their virtual work per coordinate, and each force put on the free
    body it acts on. Loads that cannot be put on a free body are still projected, but then the
    reactions cannot be reported (they are listed in ``unattributed``)."""

    def __init__(self, model: Model, bodies: list[_FreeBody], points: eq.Points):
        self.model, self.bodies, self.points = model, bodies, points
        self.work: list[list[sp.Expr]] = [[] for _ in model.q]
        self.notes: list[str] = []
        self.unattributed: list[str] = []

    def project(self, force, point) -> None:
        """The virtual work F . dr/dq_i of ``force`` acting at ``point``."""
        for i, qi in enumerate(self.model.q):
            dr = [r.diff(qi) for r in point]
            self.work[i].append(sp.Add(*(f * d for f, d in zip(force, dr, strict=True))))

    def place(self, force, point, holder: _FreeBody) -> None:
        """Add ``force`` acting at ``point`` to ``holder``: force, and moment about G for a body."""
        holder.force = [a + b for a, b in zip(holder.force, force, strict=True)]
        if holder.rotation is not None:
            s = [p - r for p, r in zip(point, holder.position, strict=True)]
            arm = (s[1] * force[2] - s[2] * force[1], s[2] * force[0] - s[0] * force[2],
                   s[0] * force[1] - s[1] * force[0])
            holder.moment3 = [a + b for a, b in zip(holder.moment3, arm, strict=True)]
        elif holder.angle is not None:
            s = [p - r for p, r in zip(point, holder.position, strict=True)]
            holder.moment += s[0] * force[1] - s[1] * force[0]

    def attach(self, force, end: Attachment) -> bool:
        """Put ``force`` on the free body ``end`` is fixed to; False when there is none to find."""
        self.project(force, end.point)
        if end.body is not None:
            holder = next((fb for fb in self.bodies if fb.name == end.body), None)
        elif any(c.has(*self.model.q) for c in end.point):  # a moving point given as a vector
            holder = _holder(end.point, self.bodies, self.model, self.points)
        else:  # the ground (or a prescribed point): its reaction is not asked for
            return True
        if holder is None:
            return False
        self.place(force, end.point, holder)
        return True

    def pull(self, a: Attachment, b: Attachment, force_on_a: list) -> bool:
        """Apply ``force_on_a`` at end a and its opposite at end b; True when both are placed."""
        placed_a = self.attach(force_on_a, a)
        placed_b = self.attach([-c for c in force_on_a], b)
        return placed_a and placed_b

    def add_gravity(self) -> None:
        """The weight m g of every free body, at its centre of mass."""
        if self.model.gravity is None:
            return
        g, direction = self.model.gravity.magnitude, self.model.gravity.direction
        for fb in self.bodies:
            weight = [fb.mass * g * d for d in direction]
            fb.force = [a + b for a, b in zip(fb.force, weight, strict=True)]
            self.project(weight, fb.position)

    def add_loads(self) -> None:
        """Point forces (N), moments and torques (N m) on the body they act on."""
        for load in self.model.loads:
            self.add_load(load)

    # one entry per load kind (tests/model/test_component_tables.py walks every kind)
    @singledispatchmethod
    def add_load(self, load) -> None:
        raise TypeError(f"no free-body force for a load of kind {type(load).__name__}")

    @add_load.register
    def _(self, load: PointForce) -> None:
        self.project(load.force, load.point)
        holder = _holder(load.point, self.bodies, self.model, self.points)
        if holder is None:
            self.unattributed.append(load.name)
            return
        self.place(load.force, load.point, holder)

    @add_load.register
    def _(self, load: Moment) -> None:
        holder = next(fb for fb in self.bodies if fb.name == load.body)
        world = list(holder.rotation * sp.Matrix(load.moment)) \
            if load.axes == "body" else list(load.moment)
        omega = list(holder.rotation * sp.Matrix(holder.omega))  # world axes
        for i, c in enumerate(self.model.coordinates):
            self.work[i].append(sp.Add(*(m * w.diff(c.velocity)
                                         for m, w in zip(world, omega, strict=True))))
        holder.moment3 = [a + b for a, b in zip(holder.moment3, world, strict=True)]

    @add_load.register
    def _(self, load: Torque) -> None:
        for i, qi in enumerate(self.model.q):
            self.work[i].append(load.torque * load.angle.diff(qi))
        holder = next((fb for fb in self.bodies if fb.angle is not None
                       and eq.identical(fb.angle, load.angle, self.points)), None)
        if holder is None:
            self.unattributed.append(load.name)
            return
        holder.moment += load.torque

    def add_springs(self) -> None:
        """Tension k (l - l0) (N) along each spring, on the ends it joins."""
        for spring in self.model.springs:
            self.add_element(spring, None)

    def add_dampers(self, clock: _Clock) -> None:
        """Force -c l_dot (N) along each damper, on the ends it joins."""
        for damper in self.model.dampers:
            self.add_element(damper, clock)

    # one entry per two-point element kind (tests/model/test_component_tables.py)
    @singledispatchmethod
    def add_element(self, element, clock) -> None:
        raise TypeError(f"no free-body force for an element of kind {type(element).__name__}")

    @add_element.register
    def _(self, spring: Spring, clock) -> None:
        if spring.ends is not None:
            # Tension k (l - l0) pulls each end towards the other along u = (r_a - r_b)/l.
            a, b, u, length = _line(spring.ends)
            tension = spring.stiffness * (length - spring.rest_length)
            if not self.pull(a, b, [-tension * c for c in u]):
                self.unattributed.append(spring.name)
            return
        self.unattributed.append(spring.name)
        tension = spring.stiffness * (spring.length - spring.rest_length)
        squared = _squared_separation(spring.length)
        for i, qi in enumerate(self.model.q):
            if squared is not None:
                # Force -k (l - l0) d/|d| on one end along d = r_a - r_b and the opposite on
                # the other: virtual work -k (l - l0)/l d.(dd/dq_i) = -k (l - l0)/l * 1/2
                # d|d|^2/dq_i.
                self.work[i].append(-tension / spring.length * squared.diff(qi) / 2)
            else:  # a spring along its own length coordinate
                self.work[i].append(-tension * spring.length.diff(qi))

    @add_element.register
    def _(self, damper: Damper, clock) -> None:
        if damper.ends is not None:
            # -c l_dot along u on end a, with l_dot = u . d(r_a - r_b)/dt (own time derivative).
            a, b, u, _ = _line(damper.ends)
            separation_rate = [clock.first(pa - pb)
                               for pa, pb in zip(a.point, b.point, strict=True)]
            rate = sp.Add(*(ui * di for ui, di in zip(u, separation_rate, strict=True)))
            if not self.pull(a, b, [-damper.coefficient * rate * c for c in u]):
                self.unattributed.append(damper.name)
            return
        self.unattributed.append(damper.name)
        # Force -c l_dot along the line, projected by dl/dq_i = d(l_dot)/d(q_dot_i).
        for i, c in enumerate(self.model.coordinates):
            self.work[i].append(-damper.coefficient * damper.rate * damper.rate.diff(c.velocity))

    def add_given_generalized_forces(self) -> None:
        """V, D and generalized forces the model gives directly: no force vector to place."""
        model, given = self.model, []
        if model.potential_energy != 0:
            given.append("[energy] V")
            for i, qi in enumerate(model.q):
                self.work[i].append(-model.potential_energy.diff(qi))
        if model.dissipation != 0:
            given.append("[energy] D")
            for i, c in enumerate(model.coordinates):
                self.work[i].append(-model.dissipation.diff(c.velocity))
        for name, value in model.generalized_forces:
            given.append(f"[generalized_forces] {name}")
            self.work[[c.name for c in model.coordinates].index(name)].append(value)
        if given:
            self.notes.append("taken as given generalized forces (no force vector in the model): "
                              + ", ".join(given))
            self.unattributed += given


def _projected_equations(model: Model, bodies: list[_FreeBody],
                         work: list[list[sp.Expr]]) -> list[sp.Expr]:
    """E_i = sum_b [m a_G . dr_G/dq_i + I alpha dangle/dq_i] - (virtual work of the forces)_i."""
    equations = []
    for i, qi in enumerate(model.q):
        terms = []
        for fb in bodies:
            terms += [fb.mass * a * r.diff(qi) for a, r in zip(fb.acceleration, fb.position,
                                                               strict=True) if r.has(qi)]
            if fb.angle is not None and fb.angle.has(qi):
                terms.append(fb.inertia * fb.angular_acceleration * fb.angle.diff(qi))
            if fb.rotation is not None:
                # (I alpha + omega x I omega - M_G) . d omega/d q_dot_i, in body axes; the
                # applied moments' part is in ``work`` (M . d omega/d q_dot_i).
                I, w = fb.body_inertia, sp.Matrix(fb.omega)
                euler = I * sp.Matrix(fb.alpha) + w.cross(I * w)
                velocity = model.q_dot[i]
                terms += [e * wk.diff(velocity) for e, wk in zip(euler, fb.omega, strict=True)
                          if wk.has(velocity)]
        equations.append(sp.Add(*terms) - sp.Add(*work[i]))
    return equations


def _compare(eom: EquationsOfMotion, newton_euler: list[sp.Expr],
             points: eq.Points) -> tuple[CoordinateAgreement, ...]:
    """Each E_i against Lagrange's (M q_ddot - f)_i, identically (at random points)."""
    lagrange = list(eom.mass_matrix * eom.acceleration_symbols - eom.forcing)
    agreements = []
    for c, ne, la in zip(eom.model.coordinates, newton_euler, lagrange, strict=True):
        same = eq.identical(ne, la, points)
        difference = None if same else fmt(eq.display(sp.expand(ne - la)) if eq.is_small(ne - la)
                                           else ne - la)
        agreements.append(CoordinateAgreement(c.name, same, difference, ne))
    return tuple(agreements)


def _holder(point, bodies: list[_FreeBody], model: Model, points: eq.Points) -> _FreeBody | None:
    """The particle at ``point``, or the body that ``point`` moves rigidly with."""
    for fb in bodies:
        if fb.angle is None and fb.rotation is None and all(eq.identical(a, b, points)
                                    for a, b in zip(point, fb.position, strict=True)):
            return fb
    q, q_dot = model.q, model.q_dot
    for fb in bodies:  # a point fixed in a body in space: R^T (point - G) is constant
        if fb.rotation is None:
            continue
        local = fb.rotation.T * sp.Matrix([p - r for p, r in zip(point, fb.position,
                                                                 strict=True)])
        if all(eq.zero(c.diff(qi), points) for c in local for qi in q):
            return fb
    for fb in bodies:
        if fb.angle is None:
            continue
        s = [p - r for p, r in zip(point, fb.position, strict=True)]
        rate = [sp.Add(*(si.diff(qi) * vi for qi, vi in zip(q, q_dot, strict=True))) + si.diff(model.time)
                for si in s]
        omega = sp.Add(*(fb.angle.diff(qi) * vi for qi, vi in zip(q, q_dot, strict=True))) \
            + fb.angle.diff(model.time)
        # A point fixed in a planar body: ds/dt = omega k x s.
        if (eq.identical(rate[0], -omega * s[1], points) and eq.identical(rate[1], omega * s[0], points)
                and eq.zero(rate[2], points)):
            return fb
    return None


def _line(ends: tuple[Attachment, Attachment]):
    """(end a, end b, unit vector from b to a, distance) of a two-point element."""
    a, b = ends
    d = [pa - pb for pa, pb in zip(a.point, b.point, strict=True)]
    length = sp.sqrt(sp.Add(*(c**2 for c in d)))
    return a, b, [c / length for c in d], length


def _squared_separation(length: sp.Expr) -> sp.Expr | None:
    """|d|^2 for a length written sqrt(|d|^2), as a spring 'between' two points is."""
    if isinstance(length, sp.Pow) and length.exp == sp.S.Half:
        return length.base
    return None


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
    children: dict[str | None, list[str]] = {}
    for body in model.rigid_bodies:
        children.setdefault(body.parent, []).append(body.name)

    def subtree(name: str) -> list[str]:
        return [name] + [d for child in children.get(name, []) for d in subtree(child)]

    for body in model.rigid_bodies:
        joint = sp.Matrix(body.origin)
        force, moment = sp.zeros(3, 1), sp.zeros(3, 1)
        for name in subtree(body.name):
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


__all__ = ["CoordinateAgreement", "CrosscheckReport", "Reaction", "crosscheck"]
