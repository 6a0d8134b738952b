"""The model's own control laws ([control] in the file) closed into its equations:
M q_ddot + Phi_q^T lambda = f + B(q, q_dot, t) u(q, q_dot, t), u written as expressions (in t,
the coordinates, their rates and the parameters), so that the law is compiled into the same
generated C as the equations and the run takes the compiled DOP853 loop (no Python per step).

B as for a Python controller (simulation/control.py): e_i for a coordinate's generalized force
(u in N or N m), df/dp for a parameter or a load (u added to the parameter's value, in its
unit; the parameter must enter f linearly).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import sympy as sp

from ..compile.functions import NumericSystem, numeric
from ..compile.lambdified import StateFunction
from ..derivation.equations import EquationsOfMotion
from ..errors import InputError
from .control import input_columns

MODEL_LAW = "model"  # controller="model": the laws of the model's [control] table


class ModelLaw:
    """The closed-loop equations of a model with a [control] table, their numeric functions
    (compiled on first use), and its u and B u on a run's samples; built once per System."""

    def __init__(self, eom: EquationsOfMotion, substitution: dict):
        model = eom.model
        if not model.control:
            raise InputError("the model has no [control] table: no laws of its own to run",
                             field="controller")
        self.names = tuple(name for name, _ in model.control)
        laws = [law for _, law in model.control]
        columns = input_columns(eom, self.names, field="control", source=model.source)
        forces = [sp.Add(*(column[i] * law for column, law in zip(columns, laws, strict=True)))
                  for i in range(len(model.coordinates))]
        # The law enters f only: the model's own Q (and so derive's output) stays as written.
        self.equations = replace(eom, forcing=eom.forcing + sp.ImmutableMatrix(forces))
        self._laws = StateFunction(model, laws, substitution)
        self._forces = StateFunction(model, forces, substitution)
        self._substitution = substitution
        self._functions: NumericSystem | None = None

    def functions(self, values) -> NumericSystem:
        """The closed-loop equations compiled (generated C, or numpy) at ``values`` (the
        ParameterValues the law was built with)."""
        if self._functions is None:
            self._functions = numeric(self.equations, values)
        return self._functions

    def built_with(self, substitution: dict) -> bool:
        """Whether this law's numbers are those of ``substitution`` (parameter values)."""
        return substitution == self._substitution

    def on_samples(self, t: np.ndarray, q: np.ndarray, v: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
        """(u, B u) at each saved sample: (N, r) and (N, n)."""
        count = len(t)
        u = self._laws(q, v, t).reshape(count, len(self.names))
        return u, self._forces(q, v, t).reshape(count, q.shape[1])
