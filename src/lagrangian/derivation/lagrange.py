"""Lagrange's equations, d/dt(dL/dq_dot) - dL/dq = Q, in the form M q_ddot + Phi_q^T lambda = f.

Structure is used instead of generic time differentiation: each particle and body contributes
M += m J^T J and f -= m J^T a_rest (its velocity Jacobian J and the acceleration at q_ddot = 0),
which is exactly the Euler-Lagrange operator applied to its 1/2 m v.v for a constant m; a mass or
inertia that depends on q or t adds 1/2 dm/dq_i v.v - m_dot v.J_i to f (and g dm/dq_i d.r to the
weight), so the equations stay those of the printed L. A rigid body in space with constant
inertia and no explicit t whose expanded kinematics would be large goes through its Jacobians
instead, unexpanded (body_jacobians.py). A user-given L(q, q_dot, t)
goes through the general formula W q_ddot = dL/dq - (d^2L/dq_dot dq) q_dot - d^2L/dq_dot dt.
"""

from __future__ import annotations

from collections import defaultdict

import sympy as sp

from ..model.model import Model, multiplier_name
from .body_jacobians import jacobian_equations, takes_jacobian_form
from .constraints import constraint_terms
from .energies import dissipation_terms as component_dissipation
from .energies import potential_terms as component_potential
from .equations import EquationsOfMotion
from .kinematics import Differentiator
from .regularity import check_regularity
from .rigid_bodies import rotational_equations, rotational_kinetic_energy
from .trig import combined_terms, parts, product
from .virtual_work import generalized_forces, load_contributions


class _Accumulator:
    """Collects the terms of M and f, grouped by shape, and adds each entry once.

    A chain repeats the same column products for every body further out; grouping term -> list
    of coefficients (masses) forms each product once and gives the textbook (m1 + m2) l1^2.
    """

    def __init__(self, n: int):
        self.n = n
        self.mass = [[defaultdict(list) for _ in range(n)] for _ in range(n)]
        self.forcing = [defaultdict(list) for _ in range(n)]
        self._dots: dict[tuple, sp.Expr] = {}
        self._collected: dict[tuple[int, int], sp.Expr] = {}  # M entries already summed

    def add_force(self, i: int, expr: sp.Expr) -> None:
        self.forcing[i][expr].append(sp.S.One)

    def add_mass(self, i: int, j: int, expr: sp.Expr) -> None:
        self.mass[i][j][expr].append(sp.S.One)
        self._collected.pop((i, j), None)

    def _dot(self, column_i: tuple, column_j: tuple) -> sp.Expr:
        key = (column_i, column_j)
        found = self._dots.get(key)
        if found is None:
            found = self._dots[key] = sp.Add(*combined_terms(
                product(parts(x), parts(y))
                for a, b in zip(column_i, column_j, strict=True) if a != 0 and b != 0
                for x in sp.Add.make_args(a) for y in sp.Add.make_args(b)))
        return found

    def _projection(self, column: tuple, vector: list[sp.Expr]) -> list[sp.Expr]:
        """column . vector distributed term by term, then tidied (no intermediate products)."""
        return combined_terms(
            product(parts(x), parts(term))
            for a, v in zip(column, vector, strict=True) if a != 0 and v != 0
            for x in sp.Add.make_args(a) for term in sp.Add.make_args(v))

    def inertia(self, mass: sp.Expr, jacobian: list[list[sp.Expr]], rest: list[sp.Expr]) -> None:
        """Add m J^T J to M and -m J^T a_rest to f for J (rows: components, cols: coordinates)."""
        n = self.n
        columns = [tuple(row[i] for row in jacobian) for i in range(n)]
        for i in range(n):
            if not any(c != 0 for c in columns[i]):
                continue
            for j in range(i, n):
                dot = self._dot(columns[i], columns[j])
                if dot != 0:
                    self.mass[i][j][dot].append(mass)
                    self._collected.pop((i, j), None)
            for term in self._projection(columns[i], rest):
                self.forcing[i][term].append(-mass)

    def mass_matrix(self) -> sp.ImmutableMatrix:
        n = self.n
        mass = [[sp.S.Zero] * n for _ in range(n)]
        for i in range(n):
            for j in range(i, n):
                entry = self._collected.get((i, j))
                if entry is None:
                    entry = self._collected[(i, j)] = _collect(self.mass[i][j])
                mass[i][j] = mass[j][i] = entry
        return sp.ImmutableMatrix(mass)

    def forcing_vector(self) -> sp.ImmutableMatrix:
        return sp.ImmutableMatrix(self.n, 1, [_collect(terms) for terms in self.forcing])


def _collect(groups: dict[sp.Expr, list[sp.Expr]]) -> sp.Expr:
    return sp.Add(*(term if coefficients == [sp.S.One] else term * sp.Add(*coefficients)
                    for term, coefficients in groups.items()))


def derive(model: Model, *, check: bool = True,
           jacobian_form: bool | None = None) -> EquationsOfMotion:
    """Form the equations of motion of ``model`` by Lagrange's method (units: SI).

    ``jacobian_form``: derive the scleronomic rigid bodies of constant inertia through their
    Jacobians, unexpanded (True), term by term (False), or by the size of their expanded
    kinematics (None; see body_jacobians.py). Every other body takes the term-by-term path.
    """
    q, q_dot, t = model.q, model.q_dot, model.time
    n = len(q)
    acc = _Accumulator(n)
    d = Differentiator()
    sizes: dict = {}
    unexpanded = {k for k, rigid in enumerate(model.rigid_bodies)
                  if takes_jacobian_form(rigid, q, t, d, sizes, jacobian_form)}
    jacobian_row, time_rate = d.row, d.rate
    kinetic_terms: list[sp.Expr] = []
    potential_terms: list[sp.Expr] = [model.potential_energy]
    dissipation_terms: list[sp.Expr] = [model.dissipation]

    gravity = model.gravity

    def varying_inertia(inertia: sp.Expr, jacobian, velocity) -> None:
        """The Euler-Lagrange operator on 1/2 m v.v is m J_i.a + m_dot v.J_i - 1/2 dm/dq_i v.v:
        for m(q, t) f_i gets the last two terms, which m J^T J and m J^T a_rest leave out (the
        same with I and omega for a body's rotation)."""
        gradient = jacobian_row(inertia, q)
        rate = time_rate(inertia, q, q_dot, t)
        if rate == 0 and all(g == 0 for g in gradient):
            return
        speed_squared = sp.Add(*(v**2 for v in velocity if v != 0))
        for i in range(n):
            projection = sp.Add(*(row[i] * v for row, v in zip(jacobian, velocity, strict=True)
                                  if row[i] != 0 and v != 0))
            term = sp.expand(gradient[i] * speed_squared / 2 - rate * projection)
            if term != 0:
                acc.add_force(i, term)

    def translate(mass: sp.Expr, position) -> None:
        jacobian = [jacobian_row(component, q) for component in position]
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
        varying_inertia(mass, jacobian, velocity)
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
            kinetic_terms.extend(mass * term for term in combined_terms(items))

    for particle in model.particles:
        translate(particle.mass, particle.position)
    for body in model.bodies:
        translate(body.mass, body.position)
        omega = time_rate(body.angle, q, q_dot, t)
        turning = [jacobian_row(body.angle, q)]
        acc.inertia(body.inertia, turning, [time_rate(omega, q, q_dot, t)])
        varying_inertia(body.inertia, turning, [omega])
        spin = d(body.angle, t)
        if spin != 0:
            kinetic_terms.append(body.inertia * (omega - spin) * spin
                                 + sp.Rational(1, 2) * body.inertia * spin**2)
    for k, rigid in enumerate(model.rigid_bodies):
        if k not in unexpanded:
            translate(rigid.mass, rigid.position)
    component_mass = (acc.mass_matrix() if model.particles or model.bodies or model.rigid_bodies
                      else None)
    for k, rigid in enumerate(model.rigid_bodies):
        if k in unexpanded:
            # M, f and the weight through the body's Jacobians; its T is printed as
            # 1/2 m v.v + 1/2 omega^T I omega (component_mass holds none of it).
            rigid_mass, rigid_forcing, kinetic = jacobian_equations(rigid, q, q_dot, t,
                                                                     gravity, d)
            kinetic_terms.append(kinetic)
            for (i, j), entry in rigid_mass.items():
                acc.add_mass(i, j, entry)
            for i, entry in enumerate(rigid_forcing):
                if entry != 0:
                    acc.add_force(i, entry)
            continue
        # 1/2 omega^T I omega by the general formula written with omega's structure (after
        # component_mass, which holds only 1/2 m v.v: the printed T shows this term as written).
        kinetic_terms.append(rotational_kinetic_energy(rigid))
        rotation_mass, rotation_forcing = rotational_equations(rigid, q, q_dot, t, d)
        for (i, j), entry in rotation_mass.items():
            acc.add_mass(i, j, entry)
        for i, entry in enumerate(rotation_forcing):
            if entry != 0:
                acc.add_force(i, entry)

    for item in (*model.particles, *model.bodies, *model.rigid_bodies, *model.springs,
                 *model.dampers):
        potential_terms.extend(component_potential(item, gravity))
        dissipation_terms.extend(component_dissipation(item))

    # The user's T and V go through the general Euler-Lagrange formula.
    user_lagrangian = model.kinetic_energy - model.potential_energy
    if user_lagrangian != 0:
        _general_lagrangian(acc, d, user_lagrangian, q, q_dot, t)
    for spring in model.springs:
        # -dV/dq_i of V = 1/2 k s^2 (s = length - rest length), in the textbook form
        # -k s ds/dq_i (and -1/2 dk/dq_i s^2 for a stiffness that depends on q).
        stretch = spring.length - spring.rest_length
        for i, (rate, stiffening) in enumerate(zip(jacobian_row(stretch, q),
                                                    jacobian_row(spring.stiffness, q),
                                                    strict=True)):
            if rate != 0:
                acc.add_force(i, -spring.stiffness * stretch * rate)
            if stiffening != 0:
                acc.add_force(i, -stiffening * stretch**2 / 2)

    contributions = load_contributions(model)
    Q = generalized_forces(model, contributions)
    for i, value in enumerate(Q):
        if value != 0:
            acc.add_force(i, value)
    mass_matrix, forcing = acc.mass_matrix(), acc.forcing_vector()

    jacobian, bias, gamma = constraint_terms(model)
    multipliers = sp.ImmutableMatrix(
        len(model.constraints), 1, [sp.Symbol(multiplier_name(c.name)) for c in model.constraints]
    )
    if check:
        check_regularity(model, mass_matrix, jacobian)
    return EquationsOfMotion(
        model=model,
        kinetic_terms=(model.kinetic_energy, *kinetic_terms),
        component_mass_matrix=component_mass,
        potential_energy=sp.Add(*potential_terms),
        dissipation=sp.Add(*dissipation_terms),
        mass_matrix=mass_matrix,
        forcing=forcing,
        generalized_forces=sp.ImmutableMatrix(n, 1, Q),
        load_contributions=tuple(contributions),
        constraint_jacobian=jacobian,
        velocity_bias=bias,
        acceleration_rhs=gamma,
        multipliers=multipliers,
    )


def _general_lagrangian(acc: _Accumulator, d: Differentiator, L: sp.Expr, q, q_dot, t) -> None:
    """W q_ddot = dL/dq - (d^2L/dq_dot dq) q_dot - d^2L/dq_dot dt, added term by term."""
    jacobian_row, time_rate = d.row, d.rate
    momenta = jacobian_row(L, q_dot)
    forces = jacobian_row(L, q)
    for i, p in enumerate(momenta):
        if forces[i] != 0:
            acc.add_force(i, forces[i])
        if p == 0:
            continue
        # W is symmetric: only its upper triangle is accumulated.
        for j, w in enumerate(jacobian_row(p, q_dot)[i:], start=i):
            if w != 0:
                acc.add_mass(i, j, w)
        rate = time_rate(p, q, q_dot, t)
        if rate != 0:
            acc.add_force(i, -rate)
