"""Numeric functions compiled once from the symbolic equations (numpy backend).

Every function takes q and q_dot of shape (..., n) and t broadcastable to the batch shape, and
returns arrays with that leading batch shape: one state or many at once.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..errors import ModelError


@dataclass(frozen=True)
class NumericSystem:
    """Mass matrix, forcing, constraint terms and energy as numeric callables (SI units)."""

    coordinates: tuple[str, ...]
    constraint_names: tuple[str, ...]
    constraint_kinds: tuple[str, ...]
    parameters: dict[str, float]
    _evaluate: Callable
    _energy: Callable
    _residual: Callable

    @property
    def n(self) -> int:
        return len(self.coordinates)

    @property
    def m(self) -> int:
        return len(self.constraint_names)

    def _parts(self, q, q_dot, t):
        q, q_dot, batch = _batch(q, q_dot, self.n)
        t = np.broadcast_to(np.asarray(t, dtype=float), batch)
        entries = self._evaluate(*np.moveaxis(q, -1, 0), *np.moveaxis(q_dot, -1, 0), t)
        n, m = self.n, self.m
        flat = np.stack([np.broadcast_to(np.asarray(e, dtype=float), batch) for e in entries],
                        axis=-1)
        mass = flat[..., : n * n].reshape(batch + (n, n))
        forcing = flat[..., n * n: n * n + n]
        jacobian = flat[..., n * n + n: n * n + n + m * n].reshape(batch + (m, n))
        gamma = flat[..., n * n + n + m * n:]
        return mass, forcing, jacobian, gamma

    def mass_matrix(self, q, q_dot, t=0.0) -> np.ndarray:
        """M(q, t), shape (..., n, n), in kg, kg m or kg m^2 per entry."""
        return self._parts(q, q_dot, t)[0]

    def forcing(self, q, q_dot, t=0.0) -> np.ndarray:
        """f(q, q_dot, t), shape (..., n)."""
        return self._parts(q, q_dot, t)[1]

    def constraint_jacobian(self, q, q_dot, t=0.0) -> np.ndarray:
        """Phi_q (or A for velocity constraints), shape (..., m, n)."""
        return self._parts(q, q_dot, t)[2]

    def acceleration_rhs(self, q, q_dot, t=0.0) -> np.ndarray:
        """gamma with Phi_q q_ddot = gamma, shape (..., m)."""
        return self._parts(q, q_dot, t)[3]

    def constraint_residual(self, q, q_dot, t=0.0) -> np.ndarray:
        """Phi(q, t) for holonomic constraints, A q_dot + b for velocity ones; shape (..., m)."""
        q, q_dot, batch = _batch(q, q_dot, self.n)
        t = np.broadcast_to(np.asarray(t, dtype=float), batch)
        values = self._residual(*np.moveaxis(q, -1, 0), *np.moveaxis(q_dot, -1, 0), t)
        return np.stack([np.broadcast_to(np.asarray(v, dtype=float), batch) for v in values],
                        axis=-1) if self.m else np.zeros(batch + (0,))

    def energy(self, q, q_dot, t=0.0) -> np.ndarray:
        """Total mechanical energy T + V in J, shape (...)."""
        q, q_dot, batch = _batch(q, q_dot, self.n)
        t = np.broadcast_to(np.asarray(t, dtype=float), batch)
        value = self._energy(*np.moveaxis(q, -1, 0), *np.moveaxis(q_dot, -1, 0), t)
        return np.broadcast_to(np.asarray(value, dtype=float), batch).copy()

    def accelerations(self, q, q_dot, t=0.0) -> tuple[np.ndarray, np.ndarray]:
        """Solve [[M, Phi_q^T], [Phi_q, 0]] [q_ddot; lambda] = [f; gamma]: (q_ddot, lambda)."""
        mass, forcing, jacobian, gamma = self._parts(q, q_dot, t)
        n, m = self.n, self.m
        if not m:
            return np.linalg.solve(mass, forcing[..., None])[..., 0], forcing[..., :0]
        batch = mass.shape[:-2]
        system = np.zeros(batch + (n + m, n + m))
        system[..., :n, :n] = mass
        system[..., :n, n:] = np.swapaxes(jacobian, -1, -2)
        system[..., n:, :n] = jacobian
        rhs = np.concatenate([forcing, gamma], axis=-1)
        solution = np.linalg.solve(system, rhs[..., None])[..., 0]
        return solution[..., :n], solution[..., n:]

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """First-order right-hand side for y = [q, q_dot]; always returns a fresh array."""
        n = self.n
        q_ddot, _ = self.accelerations(y[:n], y[n:], t)
        return np.concatenate([y[n:], q_ddot])


def _batch(q, q_dot, n: int):
    q = np.asarray(q, dtype=float)
    q_dot = np.asarray(q_dot, dtype=float)
    if q.shape[-1:] != (n,) or q_dot.shape[-1:] != (n,):
        raise ValueError(f"q and q_dot must have a last axis of length {n}")
    batch = np.broadcast_shapes(q.shape[:-1], q_dot.shape[:-1])
    return np.broadcast_to(q, batch + (n,)), np.broadcast_to(q_dot, batch + (n,)), batch


def parameter_substitution(
    eom: EquationsOfMotion, parameters: Mapping[str, float] | None = None
) -> dict[sp.Symbol, sp.Float]:
    """Parameter symbol -> value (model values overridden by ``parameters``); all must be set."""
    overrides = dict(parameters or {})
    values = {}
    for p in eom.model.parameters:
        value = overrides.pop(p.name, p.value)
        if value is None:
            raise ModelError(f"parameter '{p.name}' has no value; give one (--set {p.name}=...)",
                             field=f"parameters.{p.name}")
        values[p.symbol] = sp.Float(float(value))
    if overrides:
        raise ModelError(f"'{sorted(overrides)[0]}' is not a parameter of this model",
                         field="parameters")
    return values


def numeric(eom: EquationsOfMotion, parameters: Mapping[str, float] | None = None) -> NumericSystem:
    """Compile the equations once (common-subexpression elimination, numpy backend)."""
    model = eom.model
    values = parameter_substitution(eom, parameters)
    args = [*model.q, *model.q_dot, model.time]

    def numeric_list(exprs):
        return [sp.sympify(e).xreplace(values) for e in exprs]  # safe: sympy objects

    entries = numeric_list([*eom.mass_matrix, *eom.forcing, *eom.constraint_jacobian,
                            *eom.acceleration_rhs])
    residuals = numeric_list([
        c.expression for c in model.constraints
    ])
    energy = (eom.kinetic_energy + eom.potential_energy).xreplace(values)
    return NumericSystem(
        coordinates=tuple(c.name for c in model.coordinates),
        constraint_names=tuple(c.name for c in model.constraints),
        constraint_kinds=tuple(c.kind for c in model.constraints),
        parameters={str(k): float(v) for k, v in values.items()},
        _evaluate=sp.lambdify(args, entries, modules="numpy", cse=True),
        _energy=sp.lambdify(args, energy, modules="numpy", cse=True),
        _residual=sp.lambdify(args, residuals, modules="numpy", cse=True),
    )
