"""Each mass-carrying component's share of M and f (and of the printed T), one table entry per
kind (tests/model/test_component_tables.py walks every kind).

Two passes, in the model's order: ``add_translation`` (1/2 m v.v, and a planar body's whole
1/2 I theta_dot^2), after which derive() keeps M so far as the components' printed mass matrix,
then ``add_rotation`` (a body in space's 1/2 omega^T I omega, or its whole share through its
Jacobians where the expanded kinematics would be large)."""

from __future__ import annotations

from functools import singledispatch

import sympy as sp

from ..model.model import Body, Gravity, Particle
from ..model.rotations import RigidBody
from .body_jacobians import jacobian_equations
from .chains import add_chain_inertia, particle_chains
from .kinematics import Differentiator
from .rigid_bodies import rotational_equations, rotational_kinetic_energy
from .trig import combined_terms, parts, product


class InertiaAssembly:
    """What the passes add to: the accumulator of M and f, the printed T's terms, and the
    derivatives and gravity they need (SI units)."""

    def __init__(self, acc, d: Differentiator, q, q_dot, t, gravity: Gravity | None,
                 unexpanded: frozenset[str]):
        self.acc, self.d = acc, d
        self.q, self.q_dot, self.t = q, q_dot, t
        self.n = len(q)
        self.gravity = gravity
        self.unexpanded = unexpanded  # rigid bodies taken through their Jacobians, by name
        self.kinetic_terms: list[sp.Expr] = []
        self.chained: frozenset[str] = frozenset()  # particles added through their chain

    def add_chains(self, particles) -> None:
        """Particles in a chain (an n-link pendulum) by its segments (chains.py), before the
        first pass, which then passes them by."""
        segments = particle_chains(particles, self.q, self.q_dot, self.t, self.d)
        if segments:
            add_chain_inertia(segments, self.acc, self.d, self.q, self.q_dot, self.t,
                              self.gravity)
            self.chained = frozenset(s.particle.name for s in segments)

    def varying_inertia(self, inertia: sp.Expr, jacobian, velocity) -> None:
        """The Euler-Lagrange operator on 1/2 m v.v is m J_i.a + m_dot v.J_i - 1/2 dm/dq_i v.v:
        for m(q, t) f_i gets the last two terms, which m J^T J and m J^T a_rest leave out (the
        same with I and omega for a body's rotation)."""
        gradient = self.d.row(inertia, self.q)
        rate = self.d.rate(inertia, self.q, self.q_dot, self.t)
        if rate == 0 and all(g == 0 for g in gradient):
            return
        speed_squared = sp.Add(*(v**2 for v in velocity if v != 0))
        for i in range(self.n):
            projection = sp.Add(*(row[i] * v for row, v in zip(jacobian, velocity, strict=True)
                                  if row[i] != 0 and v != 0))
            term = sp.expand(gradient[i] * speed_squared / 2 - rate * projection)
            if term != 0:
                self.acc.add_force(i, term)

    def translate(self, mass: sp.Expr, position) -> None:
        """1/2 m v.v of a point mass at ``position`` (and its weight's virtual work)."""
        acc, q, q_dot, t, d, n = self.acc, self.q, self.q_dot, self.t, self.d, self.n
        jacobian_row, time_rate = d.row, d.rate
        jacobian = [jacobian_row(component, q) for component in position]
        gravity = self.gravity
        if gravity is not None:
            # With a mass that depends on q, -dV/dq_i of V = -m g d.r also has g dm/dq_i d.r.
            height = sp.Add(*(dc * r for dc, r in zip(gravity.direction, position, strict=True)
                              if dc != 0))
            for i, gradient in enumerate(jacobian_row(mass, q)):
                if gradient != 0 and height != 0:
                    acc.add_force(i, gravity.magnitude * gradient * height)
            # Weight m g d enters as its virtual work m g d . dr/dq_i, grouped by shape like the
            # inertia terms (so a chain shows (m1 + m2) g l1 sin(theta1)); V still shows -m g h.
            for i in range(n):
                lever = sp.Add(*(dc * row[i] for dc, row in zip(gravity.direction, jacobian,
                                                                 strict=True)
                                 if dc != 0 and row[i] != 0))
                if lever != 0:
                    acc.forcing[i][gravity.magnitude * lever].append(mass)
        # v = J q_dot + dr/dt, reusing J rather than differentiating r again.
        moving = [d(component, t) for component in position]
        velocity = [
            sp.Add(*(j * v for j, v in zip(row, q_dot, strict=True) if j != 0), r_t)
            for row, r_t in zip(jacobian, moving, strict=True)
        ]
        rest = [time_rate(v, q, q_dot, t) for v in velocity]
        acc.inertia(mass, jacobian, rest)
        self.varying_inertia(mass, jacobian, velocity)
        # T = 1/2 q_dot^T M q_dot (from the tidied M) + what a moving support adds,
        # m (J q_dot).r_t + 1/2 m r_t.r_t, tidied like M (sin^2 + cos^2 of a spin angle).
        half = parts(sp.Rational(1, 2))
        items = []
        for v, r_t in zip(velocity, moving, strict=True):
            if r_t == 0:
                continue
            moved = [parts(y) for y in sp.Add.make_args(r_t)]
            items += [product(parts(x), y) for x in sp.Add.make_args(v - r_t) for y in moved]
            items += [product(half, product(x, y)) for x in moved for y in moved]
        if items:
            self.kinetic_terms.extend(mass * term for term in combined_terms(items))

    def add_matrices(self, mass: dict, forcing) -> None:
        for (i, j), entry in mass.items():
            self.acc.add_mass(i, j, entry)
        for i, entry in enumerate(forcing):
            if entry != 0:
                self.acc.add_force(i, entry)


@singledispatch
def add_translation(component, assembly: InertiaAssembly) -> None:
    """The first pass: ``component``'s 1/2 m v.v (a planar body's turning too)."""
    raise TypeError(f"no inertia for a component of kind {type(component).__name__}")


@add_translation.register
def _(particle: Particle, assembly: InertiaAssembly) -> None:
    if particle.name not in assembly.chained:
        assembly.translate(particle.mass, particle.position)


@add_translation.register
def _(body: Body, assembly: InertiaAssembly) -> None:
    """1/2 m v.v of its centre of mass and 1/2 I omega^2 about it (omega = d(angle)/dt)."""
    a = assembly
    a.translate(body.mass, body.position)
    omega = a.d.rate(body.angle, a.q, a.q_dot, a.t)
    turning = [a.d.row(body.angle, a.q)]
    a.acc.inertia(body.inertia, turning, [a.d.rate(omega, a.q, a.q_dot, a.t)])
    a.varying_inertia(body.inertia, turning, [omega])
    spin = a.d(body.angle, a.t)
    if spin != 0:
        a.kinetic_terms.append(body.inertia * (omega - spin) * spin
                               + sp.Rational(1, 2) * body.inertia * spin**2)


@add_translation.register
def _(rigid: RigidBody, assembly: InertiaAssembly) -> None:
    if rigid.name not in assembly.unexpanded:  # else all of it in the second pass
        assembly.translate(rigid.mass, rigid.position)


@singledispatch
def add_rotation(component, assembly: InertiaAssembly) -> None:
    """The second pass: a body in space's rotation (nothing for the other kinds)."""
    raise TypeError(f"no inertia for a component of kind {type(component).__name__}")


@add_rotation.register(Particle)
@add_rotation.register(Body)
def _(component, assembly: InertiaAssembly) -> None:
    return None


@add_rotation.register
def _(rigid: RigidBody, assembly: InertiaAssembly) -> None:
    a = assembly
    if rigid.name in a.unexpanded:
        # M, f and the weight through the body's Jacobians; its T is printed as
        # 1/2 m v.v + 1/2 omega^T I omega (the components' printed M holds none of it).
        mass, forcing, kinetic = jacobian_equations(rigid, a.q, a.q_dot, a.t, a.gravity, a.d)
        a.kinetic_terms.append(kinetic)
        a.add_matrices(mass, forcing)
        return
    # 1/2 omega^T I omega by the general formula written with omega's structure (after the
    # components' printed M, which holds only 1/2 m v.v: the printed T shows this term as written).
    a.kinetic_terms.append(rotational_kinetic_energy(rigid))
    a.add_matrices(*rotational_equations(rigid, a.q, a.q_dot, a.t, a.d))


__all__ = ["InertiaAssembly", "add_rotation", "add_translation"]
