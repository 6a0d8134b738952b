"""Statics by virtual work: the load magnitudes that hold a mechanism in a configuration.

At rest (q_dot = 0) the equations of motion reduce to the equilibrium conditions
Q_i - dV/dq_i - sum_k lambda_k dPhi_k/dq_i = 0 (delta W = 0 for every admissible delta q). The
unknowns are the parameters asked for, which must enter these conditions linearly (a load's
magnitude does), and one reaction lambda_k per constraint; they are found by least squares
with a rank test, so too few, too many or dependent unknowns are named instead of guessed.
Coordinates not given are found from the constraints, starting at their initial values.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..compile.lambdified import numpy_function
from ..derivation.equations import EquationsOfMotion
from ..errors import ModelError
from ..kinds import ConstraintKind
from ..model.checked import unknown_name
from ..model.expressions import as_expression
from ..model.model import Model
from ..model.units import generalized_force_unit
from ..model.values import ParameterValues, State, resolve_parameters, resolve_state

_RANK_TOLERANCE = 1e-9
_RESIDUAL_TOLERANCE = 1e-8


@dataclass(frozen=True)
class StaticsReport:
    """Loads that hold a mechanism at rest in one configuration (SI units).

    ``solved`` maps each unknown parameter to its value; ``reactions`` the multiplier of each
    constraint; ``shares`` lists (source, coordinate, generalized force) at the solution for
    every load, spring, weight and the reactions, which sum to zero on each coordinate.
    """

    configuration: dict[str, float]
    found_from_constraints: tuple[str, ...]
    solved: dict[str, float]
    reactions: dict[str, float]
    shares: tuple[tuple[str, str, float], ...]
    units: dict[str, str]
    force_units: dict[str, str]
    residual: float

    def _repr_latex_(self) -> str:
        rows = [rf"{sp.latex(sp.Symbol(name))} &= {value:.6g}" for name, value in
                self.solved.items()]
        return r"$\begin{aligned}" + r" \\ ".join(rows) + r"\end{aligned}$"


def solve_statics(
    eom: EquationsOfMotion,
    at: Mapping[str, float] | State,
    unknowns: Sequence[str],
    parameters: Mapping[str, float] | ParameterValues | None = None,
) -> StaticsReport:
    """The values of the parameters ``unknowns`` (load magnitudes) for which delta W = 0 at the
    configuration ``at`` (name -> SI value; coordinates not given are found from the
    constraints), with each load's share."""
    model = eom.model
    names = [p.name for p in model.parameters]
    unknowns = list(dict.fromkeys(unknowns))
    if not unknowns:
        raise ModelError("give at least one parameter to solve for", field="solve_for")
    for name in unknowns:
        if name not in names:
            raise unknown_name(name, names, "parameter", "solve_for")
    given = resolve_parameters(model, parameters, require=False)
    known = {model.parameter(n).symbol: sp.Float(v) for n, v in given.as_dict().items()
             if n not in unknowns}
    p_symbols = [model.parameter(n).symbol for n in unknowns]
    state = resolve_state(model, at, field="configuration", velocities=False)
    q, found = _configuration(model, state, known)
    values = dict(known)
    values.update({c.symbol: sp.Float(x) for c, x in zip(model.coordinates, q, strict=True)})
    values.update({c.velocity: sp.S.Zero for c in model.coordinates})
    values[model.time] = sp.Float(state.t)

    lam = list(eom.multipliers)
    conditions = [sp.expand(f.xreplace(values)) for f in eom.static_conditions]
    jacobian = eom.constraint_jacobian.xreplace(values)
    for i in range(len(conditions)):
        conditions[i] -= sp.Add(*(jacobian[k, i] * lam[k] for k in range(len(lam))))
    missing = sorted({str(s) for c in conditions for s in c.free_symbols}
                     - {str(s) for s in (*p_symbols, *lam)})
    if missing:
        raise ModelError(f"parameter '{missing[0]}' has no value; give one (or solve for it)",
                         field=f"parameters.{missing[0]}")
    columns = [*p_symbols, *lam]
    A = np.zeros((len(conditions), len(columns)))
    b = np.zeros(len(conditions))
    for i, condition in enumerate(conditions):
        for j, x in enumerate(columns):
            coefficient = condition.diff(x)
            if coefficient.free_symbols & set(columns):
                raise ModelError(f"'{unknowns[j] if j < len(unknowns) else x}' does not enter "
                                 "the generalized forces linearly, so it is not a load "
                                 "magnitude that virtual work can solve for", field="solve_for")
            A[i, j] = _real(coefficient)
        b[i] = -_real(condition.xreplace({x: 0 for x in columns}))
    # A coefficient of 6e-17 is cos(pi/2) in floating point, not a lever: compared with the
    # other coefficients, and at least with 1 (SI magnitudes of real mechanisms are far above).
    size = max(np.abs(A).max(initial=0.0), np.abs(b).max(initial=0.0), 1.0)
    idle = [unknowns[j] for j in range(len(unknowns))
            if np.abs(A[:, j]).max(initial=0.0) <= 1e-12 * size]
    if idle:
        raise ModelError(f"'{idle[0]}' does no virtual work in this configuration (it is not in "
                         "Q), so the equilibrium cannot fix it", field="solve_for")
    scale = max(np.abs(A).max(initial=0.0), 1e-300)
    rank = np.linalg.matrix_rank(A, tol=_RANK_TOLERANCE * scale)
    if rank < len(columns):
        raise ModelError(_underdetermined(A, unknowns, len(lam), len(conditions), rank),
                         field="solve_for")
    x, *_ = np.linalg.lstsq(A, b, rcond=None)
    residual = float(np.abs(A @ x - b).max(initial=0.0))
    size = max(float(np.abs(b).max(initial=0.0)), float(np.abs(A @ x).max(initial=0.0)), 1e-300)
    if residual > _RESIDUAL_TOLERANCE * max(size, 1.0):
        raise ModelError(
            f"too few unknowns: {_listed(unknowns)} cannot satisfy all {len(conditions) - len(lam)}"
            " independent equilibrium conditions at this configuration (left over "
            f"{residual:.3g}); solve for more load magnitudes", field="solve_for")
    solved = {name: _clean(v) for name, v in zip(unknowns, x[:len(unknowns)], strict=True)}
    reactions = {str(k): _clean(v) for k, v in zip(lam, x[len(unknowns):], strict=True)}
    values.update({s: sp.Float(v) for s, v in zip(p_symbols, x, strict=False)})
    shares = _shares(eom, values, reactions, jacobian)
    configuration = {c.name: float(v) for c, v in zip(model.coordinates, q, strict=True)}
    units = {name: _unit(model, name) for name in unknowns}
    force_units = {c.name: generalized_force_unit(c.unit) for c in model.coordinates}
    return StaticsReport(configuration, found, solved, reactions, shares, units, force_units,
                         residual)


def _configuration(model: Model, state: State, known: Mapping) -> tuple[np.ndarray, tuple]:
    """The coordinates, those not given found from the holonomic constraints (Newton)."""
    q = np.array(state.q, dtype=float)
    holonomic = [c.expression for c in model.constraints if c.kind == ConstraintKind.HOLONOMIC]
    free = [i for i, c in enumerate(model.coordinates) if c.name not in state.given]
    if not holonomic or not free:
        return q, ()
    symbols = [c.symbol for c in model.coordinates]
    phi = sp.Matrix(holonomic).xreplace({**known, model.time: sp.Float(state.t)})
    unknown = sorted({str(s) for s in phi.free_symbols} - {str(s) for s in symbols})
    if unknown:
        raise ModelError(f"parameter '{unknown[0]}' has no value; give one",
                         field=f"parameters.{unknown[0]}")
    residual_of = numpy_function(symbols, list(phi))
    jacobian_of = numpy_function(symbols, list(phi.jacobian([symbols[i] for i in free])))

    def residual(q):
        return np.array(residual_of(*q), dtype=float)

    for _ in range(50):
        r = residual(q)
        if np.abs(r).max() < 1e-13:
            break
        jacobian = np.array(jacobian_of(*q), dtype=float).reshape(len(r), len(free))
        step, *_ = np.linalg.lstsq(jacobian, -r, rcond=None)
        q[free] += step
    if np.abs(residual(q)).max() > 1e-9:
        raise ModelError("the constraints cannot be satisfied with the coordinates given; "
                         "give a configuration the mechanism can take", field="configuration")
    return q, tuple(model.coordinates[i].name for i in free)


def _shares(eom, values, reactions, jacobian) -> tuple[tuple[str, str, float], ...]:
    """Each source's generalized force at the solution: loads (virtual work), springs and
    weights (-dV/dq), the user's V, and each constraint's reaction (-lambda dPhi/dq)."""
    model = eom.model
    names = [c.name for c in model.coordinates]
    q = model.q
    out: list[tuple[str, str, float]] = []

    def add(source: str, gradient: Sequence[sp.Expr]) -> None:
        for name, value in zip(names, gradient, strict=True):
            number = _real(as_expression(value).xreplace(values)) if value != 0 else 0.0
            if number != 0.0:
                out.append((source, name, _clean(number)))

    for contribution in eom.load_contributions:
        number = _real(contribution.expression.xreplace(values))
        if number != 0.0:
            out.append((contribution.load, contribution.coordinate, _clean(number)))
    for spring in model.springs:
        energy = spring.stiffness * (spring.length - spring.rest_length) ** 2 / 2
        add(spring.name, [-energy.diff(x) for x in q])
    gravity = model.gravity
    if gravity is not None:
        for item in (*model.particles, *model.bodies, *model.rigid_bodies):
            height = sp.Add(*(d * r for d, r in zip(gravity.direction, item.position,
                                                    strict=True)))
            energy = -item.mass * gravity.magnitude * height
            add(f"weight of {item.name}", [-energy.diff(x) for x in q])
    if model.potential_energy != 0:
        add("V", [-model.potential_energy.diff(x) for x in q])
    for k, constraint in enumerate(model.constraints):
        value = reactions[str(eom.multipliers[k])]
        add(f"reaction of {constraint.name}", [-jacobian[k, i] * value for i in range(len(q))])
    return tuple(out)


def _underdetermined(A, unknowns, reactions: int, conditions: int, rank: int) -> str:
    count = len(unknowns) + reactions
    if count > conditions:
        return (f"too many unknowns: {_listed(unknowns)}"
                + (f" and {reactions} reaction(s)" if reactions else "")
                + f" for {conditions} equilibrium conditions; solve for fewer")
    null = np.linalg.svd(A)[2][-1]
    involved = [unknowns[j] for j in range(len(unknowns)) if abs(null[j]) > 1e-6]
    if len(involved) >= 2:
        return (f"{_listed(involved)} are not independent: they enter the equilibrium "
                "conditions in a fixed proportion, so only a combination of them is fixed")
    return (f"{_listed(unknowns)} cannot be solved for: the equilibrium conditions do not fix "
            "them independently of the constraint reactions")


def _listed(names: Sequence[str]) -> str:
    quoted = [f"'{n}'" for n in names]
    return quoted[0] if len(quoted) == 1 else ", ".join(quoted[:-1]) + " and " + quoted[-1]


def _unit(model: Model, name: str) -> str:
    unit = model.parameter(name).unit
    return unit or ""


def _real(expr: sp.Expr) -> float:
    value = complex(as_expression(expr).evalf())
    if abs(value.imag) > 1e-12 * max(1.0, abs(value.real)):
        raise ModelError(f"the value of {expr} is not real at this configuration",
                         field="configuration")
    return value.real


def _clean(value: float) -> float:
    return 0.0 if abs(value) < 1e-13 else float(value)


__all__ = ["StaticsReport", "solve_statics"]
