"""Generalized forces evaluated at a configuration, load by load (N for lengths, N m for angles)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..errors import ModelError
from ..model.units import generalized_force_unit


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


def state_values(
    eom: EquationsOfMotion, at: Mapping[str, float], parameters: Mapping[str, float] | None = None,
    *, needed: set[sp.Symbol] | None = None,
) -> tuple[dict[sp.Symbol, float], dict[str, float]]:
    """Numeric values for every symbol: ``at`` (coordinates, velocities, t), then the model's
    initial values and rates, then 0; parameters from the model, overridden by ``parameters``.
    Returns (symbol -> value, the configuration as name -> value)."""
    model = eom.model
    parameters = dict(parameters or {})
    known = {c.name for c in model.coordinates} | {c.velocity.name for c in model.coordinates}
    known.add("t")
    for name in at:
        if name not in known:
            raise ModelError(f"'{name}' is not a coordinate, velocity or t of this model",
                             field="--at")
    for name in parameters:
        if name not in {p.name for p in model.parameters}:
            raise ModelError(f"'{name}' is not a parameter of this model", field="--set")
    values: dict[sp.Symbol, float] = {}
    configuration: dict[str, float] = {}
    for c in model.coordinates:
        values[c.symbol] = float(at.get(c.name, c.initial or 0.0))
        configuration[c.name] = values[c.symbol]
        values[c.velocity] = float(at.get(c.velocity.name, c.rate or 0.0))
        if c.velocity.name in at or (needed and c.velocity in needed):
            configuration[c.velocity.name] = values[c.velocity]
    values[model.time] = float(at.get("t", 0.0))
    if "t" in at or (needed and model.time in needed):
        configuration["t"] = values[model.time]
    for p in model.parameters:
        value = parameters.get(p.name, p.value)
        if value is not None:
            values[p.symbol] = float(value)
    return values, configuration


def evaluate_generalized_forces(
    eom: EquationsOfMotion, at: Mapping[str, float], parameters: Mapping[str, float] | None = None
) -> ForceReport:
    """Evaluate Q_i and every load's contribution to it at the configuration ``at`` (SI)."""
    model = eom.model
    needed: set[sp.Symbol] = set()
    for contribution in eom.load_contributions:
        needed |= contribution.expression.free_symbols
    values, configuration = state_values(eom, at, parameters, needed=needed)
    missing = sorted(str(s) for s in needed if s not in values)
    if missing:
        raise ModelError(
            f"parameter '{missing[0]}' has no value; give one with --set {missing[0]}=...",
            field="parameters",
        )
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
