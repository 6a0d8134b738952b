"""Generalized forces evaluated at a configuration, load by load (N for lengths, N m for angles)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..errors import ModelError
from ..model.units import generalized_force_unit
from ..model.values import ParameterValues, State, resolve_parameters, resolve_state


@dataclass(frozen=True)
class ForceReport:
    """Generalized forces and each load's contribution at one configuration."""

    configuration: dict[str, float]
    generalized_forces: dict[str, float]
    contributions: tuple[tuple[str, str, float], ...]
    units: dict[str, str]

    def _repr_latex_(self) -> str:
        """Jupyter: each Q_i with its unit and each load's part of it."""
        rows = []
        for name, value in self.generalized_forces.items():
            parts = ", ".join(rf"\text{{{load}}}: {part:.6g}"
                              for load, coordinate, part in self.contributions
                              if coordinate == name)
            unit = self.units[name].replace("*", r"\,")
            rows.append(rf"Q_{{{sp.latex(sp.Symbol(name))}}} &= {value:.6g}\ \mathrm{{{unit}}}"
                        + (rf" && ({parts})" if parts else ""))
        return r"$\begin{aligned}" + r" \\ ".join(rows) + r"\end{aligned}$"


def evaluate_generalized_forces(
    eom: EquationsOfMotion, at: Mapping[str, float] | State,
    parameters: Mapping[str, float] | ParameterValues | None = None,
) -> ForceReport:
    """Evaluate Q_i and every load's contribution to it at the configuration ``at`` (SI)."""
    model = eom.model
    needed: set[sp.Symbol] = set()
    for contribution in eom.load_contributions:
        needed |= contribution.expression.free_symbols
    state = resolve_state(model, at, field="configuration")
    values: dict[sp.Symbol, float] = state.symbol_values(model)
    values.update(resolve_parameters(model, parameters, require=False).symbol_values(model))
    missing = sorted(str(s) for s in needed if s not in values)
    if missing:
        raise ModelError(f"parameter '{missing[0]}' has no value; give one",
                         field=f"parameters.{missing[0]}")
    # The report names q always, q_dot and t where they were given or the forces contain them.
    configuration = {}
    for c, q, v in zip(model.coordinates, state.q, state.q_dot, strict=True):
        configuration[c.name] = q
        if c.velocity.name in state.given or c.velocity in needed:
            configuration[c.velocity.name] = v
    if "t" in state.given or model.time in needed:
        configuration["t"] = state.t
    totals = {c.name: 0.0 for c in model.coordinates}
    contributions = []
    for contribution in eom.load_contributions:
        value = _number(contribution.expression, values)
        totals[contribution.coordinate] += value
        contributions.append((contribution.load, contribution.coordinate, value))
    units = {c.name: generalized_force_unit(c.unit) for c in model.coordinates}
    return ForceReport(configuration, totals, tuple(contributions), units)


def _number(expr: sp.Expr, values: Mapping[sp.Symbol, float]) -> float:
    value = expr.xreplace({s: sp.Float(v) for s, v in values.items()}).evalf()
    result = complex(value)
    if abs(result.imag) > 1e-12 * max(1.0, abs(result.real)):
        raise ModelError(f"the value of {expr} is not real at this configuration")
    return result.real
