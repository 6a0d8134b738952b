"""A controller in the loop: generalized forces from a Python callable (t, q, q_dot) -> u, added
to the model's own, M q_ddot + Phi_q^T lambda = f + B(q, q_dot, t) u.

u is the vector of generalized forces (B = I), or one value per named input: a coordinate (a
generalized force on it), a parameter or a load (B's column df/dp, the parameter entering f
linearly; u is then added to the parameter's own value). The callable runs once per right-hand
side evaluation, in Python: the loop is scipy's, stepped by hand (integration_loops.py), never
the compiled DOP853 loop. Units SI (N m or N per coordinate, or the parameter's unit).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import sympy as sp

from ..compile.functions import NumericSystem
from ..compile.lambdified import StateFunction
from ..derivation.equations import EquationsOfMotion
from ..errors import InputError, ModelError
from ..model.expressions import as_expression
from ..model.inputs import input_parameter

Controller = Callable[[float, np.ndarray, np.ndarray], object]


class ControlLoop:
    """The controller's forces and the right-hand side they enter, for one run."""

    def __init__(self, functions: NumericSystem, controller: Controller,
                 inputs: Sequence[str] = (), eom: EquationsOfMotion | None = None,
                 substitution: dict | None = None):
        if not callable(controller):
            raise InputError("the controller must be a callable (t, q, q_dot) -> u",
                             field="controller")
        self.functions = functions
        self.controller = controller
        self.n, self.m = functions.n, functions.m
        self.inputs = tuple(inputs)
        self.names = self.inputs or tuple(functions.coordinates)
        self._columns = None if not self.inputs else _input_matrix(eom, self.inputs,
                                                                   substitution or {})

    def output(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """u at one state, checked: one finite number per input (or per coordinate)."""
        u = np.asarray(self.controller(t, q, v), dtype=float)
        if u.ndim == 0 and len(self.names) == 1:
            u = u.reshape(1)
        if u.shape != (len(self.names),):
            raise InputError(f"the controller returned shape {u.shape}; expected "
                             f"({len(self.names)},): one value per "
                             f"{'input' if self.inputs else 'coordinate'} "
                             f"({', '.join(self.names)})", field="controller")
        if not np.all(np.isfinite(u)):
            raise InputError(f"the controller returned a value that is not finite at "
                             f"t = {t:.9g} s", field="controller")
        return u

    def input_matrix(self, q, v, t) -> np.ndarray:
        """B(q, q_dot, t): the generalized forces per unit of each input, (n, r)."""
        if self._columns is None:
            return np.eye(self.n)
        return self._columns.at(q, v, t).reshape(self.n, len(self.inputs))

    def forces(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The controller's generalized forces B u at one state (n,)."""
        u = self.output(t, q, v)
        return u if self._columns is None else self.input_matrix(q, v, t) @ u

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """y' = [q_dot, q_ddot] with the controller's forces on top of f (the index-1 form
        [[M, Phi_q^T], [Phi_q, 0]] [q_ddot; lambda] = [f + B u; gamma] for a constrained model)."""
        n = self.n
        q, v = y[:n], y[n:]
        tau = self.forces(t, q, v)
        mass, forcing, jacobian, gamma = self.functions._parts(q, v, t)
        if self.m:
            mass = np.block([[mass, jacobian.T], [jacobian, np.zeros((self.m, self.m))]])
            forcing = np.concatenate([forcing + tau, gamma])
            return np.concatenate([v, np.linalg.solve(mass, forcing)[:n]])
        return np.concatenate([v, np.linalg.solve(mass, forcing + tau)])

    def on_samples(self, t: np.ndarray, q: np.ndarray, v: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
        """(u, B u) at each saved sample: (N, r) and (N, n)."""
        u = np.array([self.output(float(tk), qk, vk) for tk, qk, vk in zip(t, q, v, strict=True)]
                     ).reshape(len(t), len(self.names))
        tau = u if self._columns is None else np.stack([
            self.input_matrix(qk, vk, float(tk)) @ uk
            for tk, qk, vk, uk in zip(t, q, v, u, strict=True)]) if len(t) else np.zeros((0, self.n))
        return u, tau

    def multipliers(self, t, q, v, tau) -> np.ndarray:
        """lambda on the samples with the controller's forces included, (N, m)."""
        mass, forcing, jacobian, gamma = self.functions._parts(q, v, t)
        n, m = self.n, self.m
        kkt = np.zeros((len(t), n + m, n + m))
        kkt[:, :n, :n] = mass
        kkt[:, :n, n:] = np.swapaxes(jacobian, -1, -2)
        kkt[:, n:, :n] = jacobian
        rhs = np.concatenate([forcing + tau, gamma], axis=-1)
        return np.linalg.solve(kkt, rhs[..., None])[..., n:, 0]


def _input_matrix(eom: EquationsOfMotion, inputs: Sequence[str], substitution: dict
                  ) -> StateFunction:
    """B's entries (row-major, n x r) as one compiled function."""
    columns = input_columns(eom, inputs)
    entries = [columns[k][i] for i in range(len(eom.model.coordinates))
               for k in range(len(inputs))]
    return StateFunction(eom.model, entries, substitution)


def input_columns(eom: EquationsOfMotion, inputs: Sequence[str], field: str = "inputs",
                  source: str | None = None) -> list[list[sp.Expr]]:
    """B's columns, one per input (n entries each): df/dp for a parameter (which must enter f
    linearly, so that B u is exactly f(p + u) - f(p)), e_i for a coordinate."""
    model = eom.model
    names = [c.name for c in model.coordinates]
    forcing = [as_expression(e) for e in eom.forcing]
    symbols = [input_parameter(model, name, field=field) for name in inputs]
    columns = []
    for name, symbol in zip(inputs, symbols, strict=True):
        if symbol is None:
            columns.append([sp.S.One if i == names.index(name) else sp.S.Zero
                            for i in range(len(names))])
            continue
        if any(symbol in as_expression(e).free_symbols for e in eom.mass_matrix):
            raise ModelError(f"input '{name}' enters the mass matrix; an input must be a force "
                             "or torque (a load's magnitude), not an inertia", field=field,
                             source=source)
        column = [f.diff(symbol) for f in forcing]
        for other in (s for s in symbols if s is not None):
            if any(sp.expand(d.diff(other)) != 0 for d in column):
                raise ModelError(f"input '{name}' does not enter the generalized forces "
                                 "linearly; a controller's input must (a load's magnitude)",
                                 field=field, source=source)
        if all(d == 0 for d in column):
            raise ModelError(f"input '{name}' does not act on any coordinate", field=field,
                             source=source)
        columns.append(column)
    return columns
