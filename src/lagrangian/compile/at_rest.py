"""The equations at rest as numbers: M, f, -df/dq, -df/dq_dot, Phi_q and its q-derivatives.

What equilibria, linearization and modes evaluate (analysis/), at q_dot = 0, batched over many
configurations q; compiled once per set of parameter values, or once with the parameters as
inputs for a parameter study (thousands of points: evaluated batched over the points too).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence

import numpy as np
import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..derivation.kinematics import jacobian_row
from ..derivation.regularity import independent_of_time
from ..errors import ModelError
from ..kinds import ConstraintKind
from ..model.expressions import as_expression
from ..model.model import Model
from ..model.values import ParameterValues, resolve_parameters
from .functions import refuse_large_chain
from .lambdified import numpy_function


class AtRestFunctions:
    """M, f, K0 = -df/dq, C = -df/dq_dot, Phi_q, its q-derivatives and the static constraint
    residuals, all at q_dot = 0, compiled once (compile.lambdified) and batched over q.

    Parameters either go in as numbers before compiling (``parameters``, or the model's values:
    one system; differentiating numbers is much cheaper than symbols), or stay inputs
    (``parametric=True``: one function of q, t and the parameter vector for a study of many
    parameter points, evaluated batched over both; ``at(values)`` fixes them again)."""

    def __init__(self, eom: EquationsOfMotion,
                 parameters: Mapping[str, float] | ParameterValues | None = None, *,
                 parametric: bool = False):
        model = eom.model
        refuse_large_chain(model)
        self.model = model
        self.eom = eom
        self.parametric = parametric
        q, q_dot, t = model.q, model.q_dot, model.time
        n, m = len(q), len(model.constraints)
        self.n, self.m = n, m
        self.parameter_names = tuple(p.name for p in model.parameters)
        symbols = [p.symbol for p in model.parameters]
        if parametric:
            values: dict = {}
            self._fixed: np.ndarray | None = None
        else:
            values = resolve_parameters(model, parameters).symbol_values(model)
            self.parameters = {str(k): float(v) for k, v in values.items()}
            self._fixed = np.zeros(0)  # the numbers are in the compiled entries

        def numbers_in(e) -> sp.Expr:
            return _floats(as_expression(e).xreplace(values)) if values else as_expression(e)

        at_rest = {v: sp.S.Zero for v in q_dot}
        forcing = [numbers_in(e) for e in eom.forcing]
        forcing_at_rest = [e.xreplace(at_rest) for e in forcing]
        stiffness = [[-d for d in jacobian_row(e, q)] for e in forcing_at_rest]
        damping = [[-d.xreplace(at_rest) for d in linear_velocity_row(e, q_dot)]
                   for e in forcing]
        jacobian = [[numbers_in(e).xreplace(at_rest) for e in eom.constraint_jacobian.row(i)]
                    for i in range(m)]
        hessians = [[jacobian_row(e, q) for e in row] for row in jacobian]
        # At rest a holonomic constraint reads Phi(q) = 0, a velocity one b(q) = 0.
        static = []
        for c in model.constraints:
            residual = numbers_in(c.expression)
            residual = residual if c.kind == ConstraintKind.HOLONOMIC else residual.xreplace(at_rest)
            if residual != 0:
                static.append((c.name, residual))
        self.static_names = tuple(name for name, _ in static)
        static_jacobian = [jacobian_row(e, q) for _, e in static]
        self.depends_on = frozenset(
            s for e in [*forcing_at_rest, *(e for _, e in static)] for s in e.free_symbols
        )
        mass = [numbers_in(e).xreplace(at_rest) for e in eom.mass_matrix]
        rest = [*mass, *forcing_at_rest, *_flat(damping), *(e for _, e in static)]
        by_form = any(t in as_expression(e).free_symbols for e in rest)
        # Decided by value: t written as sin^2(Omega t) + cos^2(Omega t) changes nothing.
        if by_form and not independent_of_time([as_expression(e) for e in rest], model):
            raise ModelError("the equations at rest depend on time t explicitly, so the model has "
                             "no fixed equilibrium to analyse", field="equilibria")

        entries = [*mass, *forcing_at_rest, *_flat(stiffness), *_flat(damping), *_flat(jacobian),
                   *_flat(_flat(hessians)), *(e for _, e in static), *_flat(static_jacobian)]
        entries = [as_expression(e) for e in entries]
        if by_form:  # the same values at every t, so at t = 0
            entries = [e.xreplace({t: sp.S.Zero}) for e in entries]
            self.depends_on = self.depends_on - {t}
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
        # Only entries that vary with q (or t, or the parameters) are compiled; constants (most
        # of a big sparse model's K and C) are stored once.
        self._constants = np.zeros(len(entries))
        parts = [name for name, shape in self._layout for _ in range(int(np.prod(shape)))]
        varying = []
        for i, e in enumerate(entries):
            if e.free_symbols:
                varying.append(i)
            else:
                self._constants[i] = _real(e, parts[i])
        self._varying = np.array(varying, dtype=int)
        compiled = [entries[i] for i in varying]
        inputs = [*q, t, *symbols] if parametric else [*q, t]
        self._function = numpy_function(inputs, compiled) if varying else None

    def evaluate(self, q: np.ndarray, t: float = 0.0, parameters: np.ndarray | None = None
                 ) -> dict[str, np.ndarray]:
        """Every matrix at configurations q (..., n), at rest and time t (s); a parametric one
        at parameter vectors (..., k) in the model's order (SI), broadcast against q."""
        q = np.asarray(q, dtype=float)
        vector = self._fixed if parameters is None else np.asarray(parameters, dtype=float)
        if vector is None:
            raise ValueError("a parametric AtRestFunctions needs parameter values (or .at())")
        batch = np.broadcast_shapes(q.shape[:-1], vector.shape[:-1])
        # Entry-major: each entry is one contiguous write (a strided column write of a big
        # batch costs more than the arithmetic).
        flat = np.empty(self._constants.shape + batch)
        flat[...] = self._constants.reshape(self._constants.shape + (1,) * len(batch))
        if self._function is not None:
            raw = self._function(*np.moveaxis(q, -1, 0), np.broadcast_to(float(t), batch),
                                 *np.moveaxis(vector, -1, 0))
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
           ) -> AtRestFunctions:
        """The same compiled functions at fixed parameter values (name -> SI value, or the
        vector; a vector of shape (..., k) broadcasts against the configurations' batch)."""
        vector = values if isinstance(values, np.ndarray) else self.parameter_vector(values)
        vector = np.asarray(vector, float)
        if model is None:
            model = self.model.with_parameter_values(
                dict(zip(self.parameter_names, map(float, vector), strict=True)))
        fixed = copy.copy(self)
        fixed._fixed, fixed.model = vector, model
        if vector.ndim == 1:
            fixed.parameters = {str(p.symbol): float(v)
                                for p, v in zip(model.parameters, vector, strict=True)}
        return fixed


def _floats(expr: sp.Expr) -> sp.Expr:
    """Exact numbers too big for machine integers (from floats made exact) become floats."""
    big = {a: sp.Float(a) for a in expr.atoms(sp.Rational)
           if not (a.is_Integer and abs(a) < 2**31) and not (abs(a.p) < 2**31 and a.q < 2**31)}
    return expr.xreplace(big) if big else expr


# The part of the model each block of the equations at rest comes from, for messages.
_SOURCES = {
    "mass": "the kinetic energy T (its mass matrix)",
    "forcing": "the potential energy V or a load (the forces at rest)",
    "stiffness": "the potential energy V or a load (the stiffness)",
    "damping": "the dissipation D or a damper (the damping)",
    "jacobian": "a constraint (its Jacobian)",
    "hessians": "a constraint (its curvature)",
    "static": "the potential energy V or a load (the forces at rest)",
    "static_jacobian": "the potential energy V or a load (the stiffness)",
}


def _real(value: sp.Expr, part: str) -> float:
    if value.is_Number and value.is_finite:
        return float(value)
    number = complex(sp.N(value))
    if abs(number.imag) > 1e-12 * max(1.0, abs(number.real)) or not np.isfinite(number.real):
        raise ModelError(f"{_SOURCES.get(part, 'the model')} is not a real number with these "
                         f"parameter values (a value {value}): a square root or logarithm of a "
                         "negative value?")
    return number.real


def linear_velocity_row(expr: sp.Expr, q_dot: Sequence[sp.Symbol]) -> list[sp.Expr]:
    """d expr / d q_dot_j, for use at q_dot = 0.

    Terms at least quadratic in the velocities (centripetal, Coriolis) have no slope at rest, so
    they are dropped before differentiating: a big model's forcing is mostly such terms.
    """
    velocities = frozenset(q_dot)
    degrees: dict[sp.Basic, int] = {}
    kept = [term for term in sp.Add.make_args(expr)
            if _lowest_velocity_degree(term, velocities, degrees) < 2]
    linear = sp.Add(*kept)
    present = linear.free_symbols
    return [linear.diff(v) if v in present else sp.S.Zero for v in q_dot]


def _lowest_velocity_degree(expr: sp.Basic, velocities: frozenset, memo: dict) -> int:
    """A lower bound on the degree in the velocities of every term of ``expr`` (0 if unsure)."""
    if expr in memo:
        return memo[expr]
    if expr in velocities:
        degree = 1
    elif not (expr.free_symbols & velocities):
        degree = 0
    elif expr.is_Mul:
        degree = sum(_lowest_velocity_degree(a, velocities, memo) for a in expr.args)
    elif expr.is_Add:
        degree = min(_lowest_velocity_degree(a, velocities, memo) for a in expr.args)
    elif expr.is_Pow and expr.exp.is_Integer and expr.exp > 0:
        degree = int(expr.exp) * _lowest_velocity_degree(expr.base, velocities, memo)
    else:
        degree = 0  # a function of a velocity: no claim
    memo[expr] = degree
    return degree


def _flat(rows):
    return [x for row in rows for x in row]
