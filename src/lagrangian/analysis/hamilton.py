"""Hamilton's equations from the user's L: p = dL/dq_dot, H = p . q_dot - L.

For L = 1/2 q_dot^T M(q, t) q_dot + b(q, t) . q_dot + L0(q, t) the momenta are p = M q_dot + b,
H = 1/2 (p - b)^T M^-1 (p - b) - L0 (J), and q_dot = M^-1 (p - b), p_dot = -dH/dq + Q, where
-dH/dq at fixed p equals dL/dq at fixed q_dot (used numerically: no symbolic inverse needed).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import sympy as sp

from ..compile.lambdified import numpy_function
from ..derivation.equations import EquationsOfMotion
from ..derivation.regularity import vanishes
from ..errors import ModelError
from ..model.expressions import format_expression

# H written out needs M^-1 symbolically: kept to small models (the rhs is numeric always).
SYMBOLIC_MAX_COORDINATES = 4


def momentum_symbols(names: Sequence[str]) -> tuple[sp.Symbol, ...]:
    return tuple(sp.Symbol(f"p_{name}") for name in names)


@dataclass(frozen=True)
class Hamiltonian:
    """H(q, p, t) of a derived L, with Hamilton's equations compiled as numpy functions."""

    eom: EquationsOfMotion
    momenta: tuple[sp.Symbol, ...]
    inertia: sp.ImmutableMatrix  # M(q, t) = d^2L/dq_dot^2
    shift: sp.ImmutableMatrix  # b(q, t): p = M q_dot + b
    rest: sp.Expr  # L0(q, t) = L at q_dot = 0

    @property
    def coordinates(self) -> tuple[sp.Symbol, ...]:
        return self.eom.model.q

    @property
    def momentum_expressions(self) -> tuple[sp.Expr, ...]:
        """p_i = dL/dq_dot_i in q, q_dot (kg m/s or kg m^2/s)."""
        q_dot = sp.Matrix(self.eom.model.q_dot)
        return tuple(sp.expand(x) for x in self.inertia * q_dot + self.shift)

    @cached_property
    def H(self) -> sp.Expr:
        """H(q, p, t) in J, M^-1 formed symbolically (up to 4 coordinates)."""
        n = len(self.momenta)
        if n > SYMBOLIC_MAX_COORDINATES:
            raise ModelError(f"H is written out for up to {SYMBOLIC_MAX_COORDINATES} "
                             "coordinates (M^-1 by hand grows fast); rhs() works for any",
                             field="hamiltonian")
        M = sp.Matrix(self.inertia)
        d = sp.Matrix(self.momenta) - sp.Matrix(self.shift)
        if n == 1:
            return sp.factor_terms(d[0] ** 2 / (2 * M[0, 0])) - self.rest
        # M^-1 = adj(M) / det(M): the determinant tidied once (cos^2 + sin^2 folded)
        determinant = sp.factor_terms(sp.trigsimp(sp.expand(M.det())))
        quadratic = sp.expand((d.T * M.adjugate() * d)[0, 0])
        return sp.factor_terms(quadratic / (2 * determinant)) - self.rest

    @property
    def text(self) -> str:
        return format_expression(self.H)

    @cached_property
    def _functions(self):
        model = self.eom.model
        q, q_dot, t = model.q, model.q_dot, model.time
        values = {p.symbol: sp.Float(p.value) for p in model.parameters if p.value is not None}
        L = self.eom.lagrangian
        parts = [*self.inertia, *self.shift, *(L.diff(x) for x in q),
                 *self.eom.generalized_forces]
        parts = [sp.sympify(sp.sympify(e).xreplace(values)) for e in parts]  # safe: derived
        missing = set().union(*(e.free_symbols for e in parts)) - {*q, *q_dot, t}
        if missing:
            raise ModelError("parameters without a value: "
                             f"{', '.join(sorted(map(str, missing)))}", field="parameters")
        n = len(q)
        mass = numpy_function([*q, t], parts[:n * n + n])
        force = numpy_function([*q, *q_dot, t], parts[n * n + n:])
        return mass, force

    def velocities_of(self, q: Sequence[float], p: Sequence[float], t: float = 0.0) -> np.ndarray:
        """q_dot = M^-1 (p - b) (SI)."""
        n = len(self.momenta)
        q, p = _vector(q, n, "q"), _vector(p, n, "p")
        mass, _ = self._functions
        values = np.asarray(mass(*q, float(t)), dtype=float)
        M, b = values[:n * n].reshape(n, n), values[n * n:]
        return np.linalg.solve(M, p - b)

    def rhs(self, q: Sequence[float], p: Sequence[float], t: float = 0.0
            ) -> tuple[np.ndarray, np.ndarray]:
        """Hamilton's equations (q_dot, p_dot) at (q, p, t): q_dot = dH/dp = M^-1 (p - b),
        p_dot = -dH/dq + Q (SI)."""
        n = len(self.momenta)
        q = _vector(q, n, "q")
        q_dot = self.velocities_of(q, p, t)
        _, force = self._functions
        values = np.asarray(force(*q, *q_dot, float(t)), dtype=float)
        return q_dot, values[:n] + values[n:]

    def momenta_of(self, q: Sequence[float], q_dot: Sequence[float], t: float = 0.0
                   ) -> np.ndarray:
        """p = M q_dot + b at a state (SI)."""
        n = len(self.momenta)
        q, q_dot = _vector(q, n, "q"), _vector(q_dot, n, "q_dot")
        mass, _ = self._functions
        values = np.asarray(mass(*q, float(t)), dtype=float)
        return values[:n * n].reshape(n, n) @ q_dot + values[n * n:]

    def __repr__(self) -> str:
        try:
            return f"Hamiltonian(H = {self.text})"
        except ModelError:
            return f"Hamiltonian(in {', '.join(map(str, self.momenta))})"


def _vector(values, n: int, name: str) -> np.ndarray:
    array = np.asarray(values, dtype=float)
    if array.shape != (n,):
        raise ModelError(f"{name} takes {n} values, got shape {array.shape}", field=name)
    return array


def hamiltonian_of(eom: EquationsOfMotion) -> Hamiltonian:
    """The Hamiltonian of an unconstrained model whose L is quadratic in q_dot, M invertible."""
    model = eom.model
    if model.kinematic_tree is not None:
        raise ModelError("the Hamiltonian is formed from a derived L; a robot's tree has none",
                         field="hamiltonian")
    if model.constraints:
        raise ModelError("Hamilton's equations here are for unconstrained models (the "
                         "constraints' multipliers would enter p_dot)", field="hamiltonian")
    L = eom.lagrangian
    q_dot = model.q_dot
    zero = dict.fromkeys(q_dot, sp.S.Zero)
    gradient = [sp.expand(L.diff(v)) for v in q_dot]
    M = sp.ImmutableMatrix([[g.diff(v) for v in q_dot] for g in gradient])
    if any(entry.free_symbols & set(q_dot) for entry in M):
        raise ModelError("L is not quadratic in the velocities: p = dL/dq_dot cannot be "
                         "inverted in closed form", field="hamiltonian")
    if not eom.has_inertia or any(all(x == 0 for x in M.row(i)) for i in range(M.rows)):
        raise ModelError("a coordinate has no inertia: no Legendre transform", field="hamiltonian")
    b = sp.ImmutableMatrix([g.xreplace(zero) for g in gradient])
    rest = sp.expand(L.xreplace(zero))
    check = (sp.Matrix(q_dot).T * M * sp.Matrix(q_dot))[0, 0] / 2 \
        + (b.T * sp.Matrix(q_dot))[0, 0] + rest - L
    if not vanishes(check, model):
        raise ModelError("L is not quadratic in the velocities", field="hamiltonian")
    names = [c.name for c in model.coordinates]
    return Hamiltonian(eom, momentum_symbols(names), M, b, rest)


__all__ = ["Hamiltonian", "hamiltonian_of", "momentum_symbols"]
