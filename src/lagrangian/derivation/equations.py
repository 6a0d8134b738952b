"""The equations of motion, in the convention M(q, t) q_ddot + Phi_q^T lambda = f(q, q_dot, t),
and their working step by step (derivation_steps: the method steps() computes it here, the
steps' types in derivation/steps.py)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import sympy as sp

from ..kinds import InvariantKind, LoadStepKind
from ..model.model import Model
from ..model.notation import join_terms, model_latex_printer
from .display import ModelMatrix, model_scalar
from .kinematics import Differentiator
from .steps import (
    ConstraintStep,
    CoordinateStep,
    DerivationSteps,
    LoadStep,
    load_working,
    variation_symbols,
)
from .virtual_work import DISSIPATION_LOAD, LoadContribution


@dataclass(frozen=True)
class EquationsOfMotion:
    """Equations of motion M q_ddot + Phi_q^T lambda = f, with the energies they came from.

    ``mass_matrix`` is W = d^2L/dq_dot^2 (n x n), ``forcing`` f (n x 1) collects generalized
    forces, potential, velocity-product and explicit-time terms. With constraints,
    ``constraint_jacobian`` is Phi_q (or A), one ``multipliers`` entry per constraint, and the
    acceleration-level constraint reads Phi_q q_ddot = ``acceleration_rhs``.
    """

    model: Model
    kinetic_terms: tuple[sp.Expr, ...]
    component_mass_matrix: sp.ImmutableMatrix | None
    potential_energy: sp.Expr
    dissipation: sp.Expr
    mass_matrix: sp.ImmutableMatrix
    forcing: sp.ImmutableMatrix
    generalized_forces: sp.ImmutableMatrix
    load_contributions: tuple[LoadContribution, ...]
    constraint_jacobian: sp.ImmutableMatrix
    velocity_bias: sp.ImmutableMatrix
    acceleration_rhs: sp.ImmutableMatrix
    multipliers: sp.ImmutableMatrix

    def __post_init__(self):
        # Matrices that Jupyter shows with dots over the rates (not \theta_{dot}).
        for name in ("mass_matrix", "forcing", "generalized_forces", "constraint_jacobian",
                     "velocity_bias", "acceleration_rhs", "multipliers"):
            object.__setattr__(self, name, ModelMatrix.of(getattr(self, name)))
        for name in ("potential_energy", "dissipation"):  # and the scalars: theta_dot as a dot
            object.__setattr__(self, name, model_scalar(getattr(self, name)))

    @cached_property
    def kinetic_energy(self) -> sp.Expr:
        """T in J: 1/2 q_dot^T M q_dot of the particles and bodies (from the tidied M), their
        moving-support terms, and the user's own T. Formed on first use."""
        terms = list(self.kinetic_terms)
        mass, q_dot = self.component_mass_matrix, self.model.q_dot
        if mass is not None:
            n = len(q_dot)
            terms += [sp.Rational(1, 2) * mass[i, i] * q_dot[i] ** 2
                      for i in range(n) if mass[i, i] != 0]
            terms += [mass[i, j] * q_dot[i] * q_dot[j]
                      for i in range(n) for j in range(i + 1, n) if mass[i, j] != 0]
        return model_scalar(sp.Add(*terms))

    @cached_property
    def parameters_used(self) -> frozenset[str]:
        """The parameters M, f, the constraints (Phi and its Jacobian, gamma) and the energies
        contain: a parameter outside this set changes no result (computed on first use)."""
        parts = [self.mass_matrix, self.forcing, self.constraint_jacobian, self.acceleration_rhs,
                 self.potential_energy, self.dissipation, *self.kinetic_terms,
                 *(c.expression for c in self.model.constraints)]
        if self.component_mass_matrix is not None:
            parts.append(self.component_mass_matrix)
        symbols = set().union(*(sp.sympify(part).free_symbols  # safe: sympy objects, no text
                                for part in parts))
        return frozenset(p.name for p in self.model.parameters if p.symbol in symbols)

    @cached_property
    def _symbolic_accelerations(self):
        from .solve import solve_accelerations

        return solve_accelerations(self.mass_matrix, self.forcing, self.constraint_jacobian,
                                   self.acceleration_rhs)

    @property
    def accelerations(self) -> sp.ImmutableMatrix | None:
        """q_ddot solved symbolically (with the multipliers eliminated), or None where the solve
        would exceed its budget (see ``accelerations_note``); computed on first use."""
        accelerations = self._symbolic_accelerations.accelerations
        return None if accelerations is None else ModelMatrix.of(accelerations)

    @property
    def accelerations_note(self) -> str | None:
        """Why ``accelerations`` is None (None when they were solved)."""
        return self._symbolic_accelerations.note

    @property
    def coordinates(self) -> sp.ImmutableMatrix:
        return ModelMatrix.of(sp.ImmutableMatrix(self.model.q))

    @property
    def velocities(self) -> sp.ImmutableMatrix:
        return ModelMatrix.of(sp.ImmutableMatrix(self.model.q_dot))

    @property
    def acceleration_symbols(self) -> sp.ImmutableMatrix:
        return ModelMatrix.of(sp.ImmutableMatrix(self.model.q_ddot))

    @property
    def constraint_names(self) -> tuple[str, ...]:
        return tuple(c.name for c in self.model.constraints)

    @property
    def lagrangian(self) -> sp.Expr:
        """L = T - V (J)."""
        return model_scalar(self.kinetic_energy - self.potential_energy)

    # -- what is conserved, and the work that changes it --------------------------------------

    @cached_property
    def jacobi_integral(self) -> sp.Expr:
        """h = q_dot . dL/dq_dot - L (J); T + V when T is quadratic in q_dot and V has no q_dot."""
        L, q_dot = self.lagrangian, self.model.q_dot
        return model_scalar(sp.Add(*(v * L.diff(v) for v in q_dot if v in L.free_symbols)) - L)

    @cached_property
    def explicit_time_power(self) -> sp.Expr:
        """-dL/dt (W): what explicit time in L (a moving support, I(t)) adds to dh/dt."""
        t = self.model.time
        return -self.lagrangian.diff(t) if t in self.lagrangian.free_symbols else sp.S.Zero

    @cached_property
    def power(self) -> sp.Expr:
        """dh/dt along a motion (W): sum Q_i q_dot_i of the non-potential loads (dampers and
        dissipation included) - dL/dt (explicit time) + lambda . b of constraints that move
        (Phi_q q_dot + b = 0); in the multiplier symbols where there are constraints."""
        q_dot = self.model.q_dot
        terms = [Q * v for Q, v in zip(self.generalized_forces, q_dot, strict=True) if Q != 0]
        terms.append(self.explicit_time_power)
        terms += [lam * b for lam, b in zip(self.multipliers, self.velocity_bias, strict=True)
                  if b != 0]
        return model_scalar(sp.Add(*terms))

    @cached_property
    def invariant_kind(self) -> str:
        """'energy' (T + V is conserved), 'jacobi_integral' (h is, while T + V is not) or
        'work_balance' (h changes by the work of the loads: h(t) - h(0) - int P dt = 0)."""
        from .regularity import vanishes

        # By value, not by form: sin^2(Omega t) + cos^2(Omega t) left in L is no explicit t.
        # The numeric test comes first: expanding h - (T + V) of a large model (the bicycle's
        # four bodies) took minutes, evaluating it milliseconds.
        if not vanishes(self.power, self.model) and sp.expand(self.power) != 0:
            return InvariantKind.WORK_BALANCE
        # h = T + V exactly when T is a quadratic form in q_dot and V has none (Euler's
        # theorem); checked by value (T(2 q_dot) = 4 T) before h itself is formed, since
        # differentiating a large L for h takes seconds.
        T, V, q_dot = self.kinetic_energy, self.potential_energy, self.model.q_dot
        if not V.free_symbols & set(q_dot) and vanishes(
                T.xreplace({v: 2 * v for v in q_dot}) - 4 * T, self.model):
            return InvariantKind.ENERGY
        difference = self.jacobi_integral - self.kinetic_energy - self.potential_energy
        if vanishes(difference, self.model) or sp.expand(difference) == 0:
            return InvariantKind.ENERGY
        return InvariantKind.JACOBI_INTEGRAL

    @property
    def invariant(self) -> sp.Expr:
        """The monitored quantity (J): T + V for 'energy', the Jacobi integral h otherwise."""
        if self.invariant_kind == InvariantKind.ENERGY:
            return model_scalar(self.kinetic_energy + self.potential_energy)
        return self.jacobi_integral

    # -- statics ----------------------------------------------------------------------------

    @property
    def has_inertia(self) -> bool:
        """False for a mechanism with no mass, inertia or T at all (statics only)."""
        return any(x != 0 for x in self.mass_matrix)

    @property
    def coordinates_without_inertia(self) -> tuple[str, ...]:
        """Coordinates whose row of M is zero (no acceleration in their equation)."""
        M = self.mass_matrix
        return tuple(c.name for i, c in enumerate(self.model.coordinates)
                     if all(M[i, j] == 0 for j in range(M.cols)))

    @cached_property
    def rest_is_time_invariant(self) -> bool:
        """Whether M and f at rest (q_dot = 0) do not change with t, decided by value at random
        states and several times (a rotating frame written with Omega t may still be)."""
        from .regularity import independent_of_time

        rest = {v: sp.S.Zero for v in self.model.q_dot}
        return independent_of_time([*self.mass_matrix, *(f.xreplace(rest) for f in self.forcing)],
                                   self.model)

    @cached_property
    def static_conditions(self) -> sp.ImmutableMatrix:
        """Q_i - dV/dq_i at rest (q_dot = 0), one per coordinate: with Phi_q^T lambda on the
        left, the equilibrium conditions of virtual work (delta W = 0 for every admissible
        delta q)."""
        rest = {v: sp.S.Zero for v in self.model.q_dot}
        return sp.ImmutableMatrix(self.forcing.rows, 1, [f.xreplace(rest) for f in self.forcing])

    @property
    def equations(self) -> sp.ImmutableMatrix:
        """One expression per coordinate that equals zero: M q_ddot + Phi_q^T lambda - f."""
        # Summed term by term in one Add per row: the matrix product and subtraction build and
        # flatten every partial sum again (2.6 s for the 30-link pendulum, against 0.1 s).
        M, A, f = self.mass_matrix, self.constraint_jacobian, self.forcing
        q_ddot, multipliers = self.model.q_ddot, self.multipliers
        rows = []
        for i in range(M.rows):
            terms = [M[i, j] * a for j, a in enumerate(q_ddot) if M[i, j] != 0]
            terms += [A[k, i] * multipliers[k] for k in range(A.rows) if A[k, i] != 0]
            terms += [-term for term in sp.Add.make_args(f[i])]
            rows.append(sp.Add(*terms))
        return ModelMatrix(M.rows, 1, rows)

    def steps(self):
        """The working of Lagrange's method from L = T - V, coordinate by coordinate and load
        by load (a DerivationSteps; derivation/steps.py)."""
        return derivation_steps(self)

    def _repr_latex_(self) -> str:
        """Jupyter: M q_ddot + Phi_q^T lambda = f, one row per coordinate (named at the right),
        the accelerations on the left in coordinate order."""
        printer = model_latex_printer(self.model)
        M, A, f = self.mass_matrix, self.constraint_jacobian, self.forcing
        rows = []
        for i, coordinate in enumerate(self.model.coordinates):
            pairs = [(M[i, j], a) for j, a in enumerate(self.model.q_ddot)]
            pairs += [(A[k, i], self.multipliers[k]) for k in range(A.rows)]
            rows.append(rf"{join_terms(printer.product_terms(pairs))} &= {printer.doprint(f[i])}"
                        rf" &&({printer.doprint(coordinate.symbol)})")
        return r"$\begin{aligned}" + r" \\ ".join(rows) + r"\end{aligned}$"


# -- the working (derive --steps) ------------------------------------------------------------


def derivation_steps(eom: EquationsOfMotion) -> DerivationSteps:
    """Differentiate L = T - V of ``eom`` step by step and project each load (derivation/steps.py)."""
    model = eom.model
    q, q_dot, q_ddot, t = model.q, model.q_dot, model.q_ddot, model.time
    d = Differentiator()
    T, V = eom.kinetic_energy, eom.potential_energy
    L = T - V
    A, multipliers = eom.constraint_jacobian, eom.multipliers
    coordinates = []
    for i, c in enumerate(model.coordinates):
        momentum = d(L, q_dot[i])
        rate = sp.Add(*(d(momentum, qj) * vj for qj, vj in zip(q, q_dot, strict=True)),
                      *(d(momentum, vj) * aj for vj, aj in zip(q_dot, q_ddot, strict=True)),
                      d(momentum, t))
        gradient = d(L, q[i])
        Q = eom.generalized_forces[i]
        lam = sp.Add(*(A[k, i] * multipliers[k] for k in range(A.rows) if A[k, i] != 0))
        coordinates.append(CoordinateStep(c.name, momentum, rate, gradient, Q, lam,
                                          rate - gradient - Q + lam))
    variations = variation_symbols(model)
    constraints = tuple(
        ConstraintStep(constraint.name, str(constraint.kind), constraint.expression,
                       tuple(A.row(k)), multipliers[k])
        for k, constraint in enumerate(model.constraints))
    return DerivationSteps(model, T, V, L, variations, tuple(coordinates),
                           tuple(_load_steps(eom, variations, d)), constraints)


def _load_steps(eom: EquationsOfMotion, variations, d: Differentiator) -> list[LoadStep]:
    """Each load's virtual displacement and virtual work, in the order of derive's breakdown."""
    model = eom.model
    q, q_dot = model.q, model.q_dot
    names = [c.name for c in model.coordinates]
    by_load: dict[str, list[tuple[str, sp.Expr]]] = {}
    for part in eom.load_contributions:
        by_load.setdefault(part.load, []).append((part.coordinate, part.expression))
    loads = {load.name: load for load in model.loads}
    dampers = {damper.name: damper for damper in model.dampers}

    def moved(expr, variables) -> sp.Expr:
        return sp.Add(*(d(expr, x) * dq for x, dq in zip(variables, variations, strict=True)))

    steps = []
    for name, shares in by_load.items():
        work = sp.Add(*(value * variations[names.index(c)] for c, value in shares))
        component = loads.get(name, dampers.get(name))
        if component is not None:
            kind, acts_at, displacement, form = load_working(component, q, q_dot, moved)
        else:
            kind, acts_at, displacement, form = (
                LoadStepKind.DISSIPATION if name == DISSIPATION_LOAD else LoadStepKind.GIVEN,
                (), (), None)
        steps.append(LoadStep(name, kind, acts_at, displacement, form, work, tuple(shares)))
    return steps
