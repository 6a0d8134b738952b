"""JSON documents of the public contracts (derive, forces); expressions in the model grammar."""

from __future__ import annotations

from typing import Any

from ..analysis.forces import ForceReport
from ..derivation.equations import EquationsOfMotion
from ..model.expressions import format_expression

CONVENTION = "M q_ddot + Phi_q^T lambda = forcing"


def derivation_document(eom: EquationsOfMotion) -> dict[str, Any]:
    """The `derive --format json` document."""
    model = eom.model
    names = [c.name for c in model.coordinates]
    text = format_expression
    document: dict[str, Any] = {
        "name": model.name,
        "convention": CONVENTION,
        "coordinates": names,
        "parameters": {p.name: p.value for p in model.parameters},
        "kinetic_energy": text(eom.kinetic_energy),
        "potential_energy": text(eom.potential_energy),
        "dissipation": text(eom.dissipation),
        "lagrangian": text(eom.lagrangian),
        "generalized_forces": {n: text(v) for n, v in zip(names, eom.generalized_forces,
                                                           strict=True)},
        "load_contributions": [
            {"load": c.load, "coordinate": c.coordinate, "expression": text(c.expression)}
            for c in eom.load_contributions
        ],
        "mass_matrix": [[text(v) for v in eom.mass_matrix.row(i)]
                        for i in range(eom.mass_matrix.rows)],
        "forcing": [text(v) for v in eom.forcing],
        "equations": {n: text(v) for n, v in zip(names, eom.equations, strict=True)},
        "accelerations": {
            n: (text(v) if eom.accelerations is not None else None)
            for n, v in zip(names, eom.accelerations if eom.accelerations is not None
                            else [None] * len(names), strict=True)
        },
    }
    if model.constraints:
        document["constraints"] = {
            "names": [c.name for c in model.constraints],
            "kinds": [c.kind for c in model.constraints],
            "multipliers": [str(s) for s in eom.multipliers],
            "jacobian": [[text(v) for v in eom.constraint_jacobian.row(i)]
                         for i in range(eom.constraint_jacobian.rows)],
            "acceleration_rhs": [text(v) for v in eom.acceleration_rhs],
        }
    return document


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
