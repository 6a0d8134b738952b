"""The equations at rest with the parameters as runtime inputs, for parameter studies.

``StaticFunctions`` (compile/at_rest.py) puts the parameter values in before compiling, which is
right for one system and wrong for a study of thousands of parameter points: here the same
entries (M, f, -df/dq, -df/dq_dot, Phi_q, its q-derivatives, the static residuals) are compiled
once with the parameters as arguments, and evaluated batched over configurations and parameter
points together. ``at(values)`` gives a view with StaticFunctions' interface for one point, so
the single-point analysis (equilibria, linearization) runs on it unchanged. Members of an
ensemble are integrated by the compiled DOP853 loop of the model's C module, parameters per
member, a whole chunk of them in one C call (``integrate_ensemble``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..derivation.kinematics import jacobian_row
from ..errors import ModelError
from ..kinds import ConstraintKind
from ..model.expressions import as_expression
from ..model.model import Model
from .at_rest import linear_velocity_row
from .lambdified import numpy_function


class ParametricStaticFunctions:
    """StaticFunctions' entries at q_dot = 0 as one numpy function of (q, t, parameters)."""

    def __init__(self, eom: EquationsOfMotion):
        model = eom.model
        self.model = model
        self.eom = eom
        q, q_dot, t = model.q, model.q_dot, model.time
        n, m = len(q), len(model.constraints)
        self.n, self.m = n, m
        self.parameter_names = tuple(p.name for p in model.parameters)
        symbols = [p.symbol for p in model.parameters]
        at_rest = {v: sp.S.Zero for v in q_dot}
        forcing = [as_expression(e) for e in eom.forcing]
        forcing_at_rest = [e.xreplace(at_rest) for e in forcing]
        stiffness = [[-d for d in jacobian_row(e, q)] for e in forcing_at_rest]
        damping = [[-d.xreplace(at_rest) for d in linear_velocity_row(e, q_dot)] for e in forcing]
        jacobian = [[as_expression(e).xreplace(at_rest) for e in eom.constraint_jacobian.row(i)]
                    for i in range(m)]
        hessians = [[jacobian_row(e, q) for e in row] for row in jacobian]
        static = []
        for c in model.constraints:
            residual = as_expression(c.expression)
            residual = residual if c.kind == ConstraintKind.HOLONOMIC else residual.xreplace(at_rest)
            if residual != 0:
                static.append((c.name, residual))
        self.static_names = tuple(name for name, _ in static)
        static_jacobian = [jacobian_row(e, q) for _, e in static]
        self.depends_on = frozenset(
            s for e in [*forcing_at_rest, *(e for _, e in static)] for s in e.free_symbols)
        mass = [as_expression(e).xreplace(at_rest) for e in eom.mass_matrix]
        rest = [*mass, *forcing_at_rest, *_flat(damping), *(e for _, e in static)]
        if any(t in e.free_symbols for e in rest):
            raise ModelError("the equations at rest depend on time t explicitly, so the model has "
                             "no fixed equilibrium to analyse", field="equilibria")
        entries = [*mass, *forcing_at_rest, *_flat(stiffness), *_flat(damping), *_flat(jacobian),
                   *_flat(_flat(hessians)), *(e for _, e in static), *_flat(static_jacobian)]
        entries = [as_expression(e) for e in entries]
        self._layout = [("mass", (n, n)), ("forcing", (n,)), ("stiffness", (n, n)),
                        ("damping", (n, n)), ("jacobian", (m, n)), ("hessians", (m, n, n)),
                        ("static", (len(static),)), ("static_jacobian", (len(static), n))]
        # The parameters the search for equilibria sees (forces and constraints at rest): points
        # that agree in these have the same equilibria, whatever their masses.
        search = [*forcing_at_rest, *_flat(stiffness), *_flat(jacobian), *_flat(_flat(hessians)),
                  *(e for _, e in static), *_flat(static_jacobian)]
        present = set().union(*(as_expression(e).free_symbols for e in search)) if search else set()
        self.search_parameters = tuple(i for i, p in enumerate(model.parameters)
                                       if p.symbol in present)
        self._constants = np.zeros(len(entries))
        varying = []
        for i, e in enumerate(entries):
            if e.free_symbols:
                varying.append(i)
            else:
                self._constants[i] = float(e)
        self._varying = np.array(varying, dtype=int)
        compiled = [entries[i] for i in varying]
        self._function = numpy_function([*q, t, *symbols], compiled) if varying else None

    def evaluate(self, q: np.ndarray, parameters: np.ndarray, t: float = 0.0
                 ) -> dict[str, np.ndarray]:
        """Every matrix at configurations q (..., n) and parameter values (..., k), broadcast."""
        q = np.asarray(q, dtype=float)
        parameters = np.asarray(parameters, dtype=float)
        batch = np.broadcast_shapes(q.shape[:-1], parameters.shape[:-1])
        # Entry-major: each entry is one contiguous write (a strided column write of a big
        # batch costs more than the arithmetic).
        flat = np.empty(self._constants.shape + batch)
        flat[...] = self._constants.reshape(self._constants.shape + (1,) * len(batch))
        if self._function is not None:
            raw = self._function(*np.moveaxis(q, -1, 0), np.broadcast_to(float(t), batch),
                                 *np.moveaxis(parameters, -1, 0))
            for i, value in zip(self._varying, raw, strict=True):
                flat[i] = value
        out, start = {}, 0
        for name, shape in self._layout:
            size = int(np.prod(shape))
            block = flat[start:start + size].reshape(shape + batch)
            out[name] = np.moveaxis(block, tuple(range(len(shape))),
                                    tuple(range(len(batch), len(batch) + len(shape))))
            start += size
        return out

    def parameter_vector(self, values: Mapping[str, float]) -> np.ndarray:
        """The model's parameter values (SI) with ``values`` put in, in the model's order."""
        out = []
        for p in self.model.parameters:
            value = values.get(p.name, p.value)
            if value is None:
                raise ModelError(f"parameter '{p.name}' has no value; give one",
                                 field=f"parameters.{p.name}")
            out.append(float(value))
        return np.array(out, dtype=float)

    def at(self, values: Mapping[str, float] | np.ndarray, model: Model | None = None
           ) -> StaticFunctionsAt:
        """StaticFunctions' interface at one parameter point (name -> SI value, or the vector)."""
        vector = values if isinstance(values, np.ndarray) else self.parameter_vector(values)
        if model is None:
            model = self.model.with_parameter_values(
                dict(zip(self.parameter_names, map(float, vector), strict=True)))
        return StaticFunctionsAt(self, np.asarray(vector, float), model)


class StaticFunctionsAt:
    """A ParametricStaticFunctions at fixed parameter values (a vector of shape (k,), or one
    broadcastable against the configurations' batch, (..., k)), read like StaticFunctions."""

    def __init__(self, parametric: ParametricStaticFunctions, vector: np.ndarray, model: Model):
        self.parametric = parametric
        self.vector = vector
        self.model = model
        self.eom = parametric.eom
        self.n, self.m = parametric.n, parametric.m
        self.static_names = parametric.static_names
        self.depends_on = parametric.depends_on
        if vector.ndim == 1:
            self.parameters = {str(p.symbol): float(v)
                               for p, v in zip(model.parameters, vector, strict=True)}

    def evaluate(self, q: np.ndarray, t: float = 0.0) -> dict[str, np.ndarray]:
        return self.parametric.evaluate(q, self.vector, t)


def integrate_member(module, parameters: np.ndarray, y0: np.ndarray, grid: np.ndarray,
                     rtol: float, atol: float, max_steps: int = 10_000_000):
    """One ensemble member by the compiled DOP853 loop onto ``grid`` (s): (t, y, status, t_reached);
    status 0 when it reached the end (the codes of simulation/compiled_loop.py otherwise)."""
    t, y, _, _, status, t_reached = module.dop853(
        np.ascontiguousarray(parameters, float), float(grid[0]), float(grid[-1]),
        np.ascontiguousarray(y0, float), float(rtol), float(atol), grid, int(max_steps))
    return t, np.asarray(y).reshape(len(t), -1), int(status), float(t_reached)


@dataclass(frozen=True)
class EnsembleRun:
    """Per-member summaries of an ensemble integrated onto a common grid (SI; NaN where a member
    failed): final state, extremes over the samples, end time (s), energy drift, the loop's status
    code (0: reached the end; simulation/compiled_loop.py's codes otherwise), the time reached (s), and the
    samples (members x times x 2n) when asked."""

    final: np.ndarray
    minimum: np.ndarray
    maximum: np.ndarray
    t_final: np.ndarray
    drift: np.ndarray
    status: np.ndarray
    t_reached: np.ndarray
    trajectory: np.ndarray | None


def integrate_ensemble(module, parameters: np.ndarray, y0: np.ndarray, grid: np.ndarray,
                       rtol: float, atol: float, max_steps: int = 10_000_000,
                       trajectories: bool = False, vector: bool = True) -> EnsembleRun:
    """Every member (rows of ``parameters`` and ``y0``) by the module's DOP853 loop onto
    ``grid`` (s) in one C call without the GIL: the same steps as ``integrate_member`` per
    member, several members per vector instruction where the module has a vector kernel
    (``module.lanes`` > 1, unless ``vector`` is False)."""
    parameters = np.ascontiguousarray(parameters, float)
    y0 = np.ascontiguousarray(y0, float)
    grid = np.ascontiguousarray(grid, float)
    run = module.ensemble(parameters, y0, grid, float(rtol), float(atol), int(max_steps),
                          bool(trajectories), bool(vector))
    return EnsembleRun(*run)


def _flat(rows):
    return [x for row in rows for x in row]
