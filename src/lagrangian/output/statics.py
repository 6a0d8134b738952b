"""Statics by virtual work (`statics`): text for a terminal and the JSON document."""

from __future__ import annotations

from typing import Any

from ..analysis.statics import StaticsReport


def statics_text(report: StaticsReport) -> str:
    given = [k for k in report.configuration if k not in report.found_from_constraints]
    at = ", ".join(f"{k} = {report.configuration[k]:.6g}" for k in given)
    lines = [f"Statics by virtual work (delta W = 0) at {at}:"]
    if report.found_from_constraints:
        found = ", ".join(f"{k} = {report.configuration[k]:.6g}"
                          for k in report.found_from_constraints)
        lines.append(f"  from the constraints: {found}")
    lines.append("Load magnitudes that hold it:")
    for name, value in report.solved.items():
        unit = f" {report.units[name]}" if report.units.get(name) else ""
        lines.append(f"  {name} = {value:.6g}{unit}")
    if report.reactions:
        lines.append("Constraint reactions (multipliers):")
        lines += [f"  {name} = {value:.6g}" for name, value in report.reactions.items()]
    lines.append("Each source's generalized force (they sum to zero on every coordinate):")
    for coordinate, unit in report.force_units.items():
        parts = [(source, value) for source, c, value in report.shares if c == coordinate]
        if parts:
            lines.append(f"  [{coordinate}]")
            lines += [f"      {source}: {value:.6g} {unit}" for source, value in parts]
    return "\n".join(lines) + "\n"


def statics_document(report: StaticsReport) -> dict[str, Any]:
    """The `statics --json` document."""
    return {
        "configuration": dict(report.configuration),
        "found_from_constraints": list(report.found_from_constraints),
        "solved": dict(report.solved),
        "units": dict(report.units),
        "reactions": dict(report.reactions),
        "shares": [{"source": source, "coordinate": coordinate, "value": value}
                   for source, coordinate, value in report.shares],
        "force_units": dict(report.force_units),
        "residual": report.residual,
    }
