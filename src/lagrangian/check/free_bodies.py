"""Newton-Euler's free bodies (crosscheck, newton_euler.py): each particle and body with its
accelerations by sympy's own d/dt (a_G in m/s^2, alpha in rad/s^2; Euler's equations in body
axes for a body in space), the applied forces placed on the body they act on (N, N m), and the
equations E_i = sum_b [(m a_G - F) . dr_G/dq_i + (I alpha - M_G) dangle/dq_i] projected onto
the virtual displacements. One table entry per mass kind (``free_body``), element kind
(``_AppliedForces.add_element``) and load kind (``_AppliedForces.add_load``).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import singledispatch, singledispatchmethod

import sympy as sp

from ..errors import DerivationError
from ..model.model import Attachment, Body, Damper, Model, Particle, PointForce, Spring, Torque
from ..model.rotations import Moment, RigidBody
from . import equivalence as eq


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

    def turn(self, moment, holder: _FreeBody) -> None:
        """The virtual work M . d omega/d q_dot_i of a moment (world axes) on a body in space."""
        omega = list(holder.rotation * sp.Matrix(holder.omega))  # world axes
        for i, c in enumerate(self.model.coordinates):
            self.work[i].append(sp.Add(*(m * w.diff(c.velocity)
                                         for m, w in zip(moment, omega, strict=True))))

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
        self.turn(world, holder)
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


def carried(model: Model) -> dict[str, list[str]]:
    """Each body in space's name -> itself and every body it carries (the subtree it heads)."""
    children: dict[str | None, list[str]] = {}
    for body in model.rigid_bodies:
        children.setdefault(body.parent, []).append(body.name)

    def subtree(name: str) -> list[str]:  # depth first, without recursion (deep chains)
        found, stack = [], [name]
        while stack:
            found.append(stack.pop())
            stack.extend(reversed(children.get(found[-1], [])))
        return found
    return {body.name: subtree(body.name) for body in model.rigid_bodies}


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
