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

from ..errors import ModelError
from ..model.model import Model, multiplier_name
from ..model.rotations import MAX_CHAIN_ROTATIONS
from .body_jacobians import takes_jacobian_form
from .constraints import constraint_terms
from .energies import dissipation_terms as component_dissipation
from .energies import potential_terms as component_potential
from .equations import EquationsOfMotion
from .inertia import InertiaAssembly, add_rotation, add_translation
from .kinematics import Differentiator
from .regularity import check_regularity
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
        self._sums: dict[tuple, sp.Expr] = {}  # sums of coefficients, see _collect

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
                    entry = self._collected[(i, j)] = _collect(self.mass[i][j], self._sums)
                mass[i][j] = mass[j][i] = entry
        return sp.ImmutableMatrix(mass)

    def forcing_vector(self) -> sp.ImmutableMatrix:
        return sp.ImmutableMatrix(self.n, 1, [_collect(terms, self._sums) for terms in self.forcing])


def _collect(groups: dict[sp.Expr, list[sp.Expr]], sums: dict[tuple, sp.Expr]) -> sp.Expr:
    """sum of term * (sum of its coefficients); ``sums`` keeps each sum of coefficients formed
    (a chain gives the same m_k + ... + m_n to many terms of many entries)."""
    items = []
    for term, coefficients in groups.items():
        if coefficients == [sp.S.One]:
            items.append(term)
            continue
        key = tuple(coefficients)
        total = sums.get(key)
        if total is None:
            total = sums[key] = sp.Add(*coefficients)
        items.append(term * total)
    return sp.Add(*items)


def derive(model: Model, *, check: bool = True,
           jacobian_form: bool | None = None) -> EquationsOfMotion:
    """Form the equations of motion of ``model`` by Lagrange's method (units: SI).

    ``jacobian_form``: derive the scleronomic rigid bodies of constant inertia through their
    Jacobians, unexpanded (True), term by term (False), or by the size of their expanded
    kinematics (None; see body_jacobians.py). Every other body takes the term-by-term path.
    """
    tree = model.kinematic_tree
    if tree is not None and tree.floating_base:  # its base moves by a quaternion, not by q
        raise ModelError("a floating-base robot has no equations in its joint coordinates "
                         "(derive and the other symbolic commands need them): use dynamics(), "
                         "its kinematics, simulate and integrate(q, v, dt), or load it with a "
                         "fixed base")
    refuse_deep_chain(model)
    q, q_dot, t = model.q, model.q_dot, model.time
    n = len(q)
    acc = _Accumulator(n)
    d = Differentiator()
    sizes: dict = {}
    unexpanded = frozenset(rigid.name for rigid in model.rigid_bodies
                           if takes_jacobian_form(rigid, q, t, d, sizes, jacobian_form))
    jacobian_row = d.row
    potential_terms: list[sp.Expr] = [model.potential_energy]
    dissipation_terms: list[sp.Expr] = [model.dissipation]
    gravity = model.gravity

    # Each mass-carrying component by its kind's table (inertia.py), in two passes: the
    # components' printed M is taken between them (it holds no body in space's rotation).
    assembly = InertiaAssembly(acc, d, q, q_dot, t, gravity, unexpanded)
    carriers = (*model.particles, *model.bodies, *model.rigid_bodies)
    assembly.add_chains(model.particles)
    for item in carriers:
        add_translation(item, assembly)
    component_mass = acc.mass_matrix() if carriers else None
    for item in carriers:
        add_rotation(item, assembly)
    kinetic_terms = assembly.kinetic_terms

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


def refuse_deep_chain(model: Model) -> None:
    """Refuse, before any work, a chain of bodies too deep to derive symbolically (the size
    named in one line); its numbers go down the tree (dynamics/recursive.py) instead."""
    deep = next((b for b in model.rigid_bodies if b.depth > MAX_CHAIN_ROTATIONS), None)
    if deep is not None:
        raise ModelError(
            f"body '{deep.name}' is {deep.depth} elementary rotations from the ground (at most "
            f"{MAX_CHAIN_ROTATIONS} to derive: the symbolic equations of a longer chain take "
            "minutes; its dynamics, simulation and modes use the recursive algorithms)",
            field=f"body '{deep.name}'.joint", source=model.source)


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
