"""Generalized forces at a configuration (`forces`): text for a terminal and the JSON document."""

from __future__ import annotations

from typing import Any

from ..analysis.forces import ForceReport


def forces_text(report: ForceReport) -> str:
    at = ", ".join(f"{k} = {v:.6g}" for k, v in report.configuration.items())
    lines = [f"Generalized forces at {at}:"]
    for name, value in report.generalized_forces.items():
        lines.append(f"  Q[{name}] = {value:.6g} {report.units[name]}")
        for load, coordinate, part in report.contributions:
            if coordinate == name:
                lines.append(f"      from {load}: {part:.6g} {report.units[name]}")
    return "\n".join(lines) + "\n"


def forces_document(report: ForceReport) -> dict[str, Any]:
    """The `forces --json` document."""
    return {
        "configuration": dict(report.configuration),
        "generalized_forces": dict(report.generalized_forces),
        "contributions": [
            {"load": load, "coordinate": coordinate, "value": value}
            for load, coordinate, value in report.contributions
        ],
        "units": dict(report.units),
    }
