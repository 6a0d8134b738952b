"""Plain-text reports for a terminal, written in the model grammar (readable, copyable)."""

from __future__ import annotations

from ..analysis.forces import ForceReport
from ..derivation.equations import EquationsOfMotion
from ..model.expressions import format_expression as fmt
from ..model.units import generalized_force_unit


def derivation_text(eom: EquationsOfMotion) -> str:
    model = eom.model
    lines = [model.name, "=" * len(model.name)]
    coordinates = ", ".join(f"{c.name} [{c.unit or '1'}]" for c in model.coordinates)
    lines += [f"Coordinates: {coordinates}", ""]
    lines += [f"T = {fmt(eom.kinetic_energy)}", f"V = {fmt(eom.potential_energy)}"]
    if eom.dissipation != 0:
        lines.append(f"D = {fmt(eom.dissipation)}")
    lines += [f"L = T - V = {fmt(eom.lagrangian)}", ""]

    lines.append("Equations of motion, d/dt(dL/dq_dot) - dL/dq = Q"
                 + (" - Phi_q^T lambda" if model.constraints else "") + ":")
    for c, row, f in zip(model.coordinates, _rows(eom), eom.forcing, strict=True):
        lines.append(f"  [{c.name}]  {row} = {fmt(f)}")
    lines.append("")

    lines.append("Generalized forces (virtual work, delta W = Q . delta q):")
    for c, total in zip(model.coordinates, eom.generalized_forces, strict=True):
        unit = generalized_force_unit(c.unit)
        lines.append(f"  Q[{c.name}] = {fmt(total)}   [{unit}]")
        for part in eom.load_contributions:
            if part.coordinate == c.name:
                lines.append(f"      from {part.load}: {fmt(part.expression)}")
    lines.append("")

    lines.append("Mass matrix M:")
    for i in range(eom.mass_matrix.rows):
        lines.append("  [" + ", ".join(fmt(v) for v in eom.mass_matrix.row(i)) + "]")
    lines.append("Forcing f:")
    for c, f in zip(model.coordinates, eom.forcing, strict=True):
        lines.append(f"  {c.name}: {fmt(f)}")

    if model.constraints:
        lines += ["", f"Constraints ({len(model.constraints)}, one multiplier each):"]
        for k, constraint in enumerate(model.constraints):
            lines.append(f"  {constraint.name} ({constraint.kind}): {fmt(constraint.expression)}"
                         f" = 0   multiplier {eom.multipliers[k]}")
        lines.append("Constraint Jacobian Phi_q:")
        for i in range(eom.constraint_jacobian.rows):
            lines.append("  [" + ", ".join(fmt(v) for v in eom.constraint_jacobian.row(i)) + "]")
        lines.append("Acceleration level, Phi_q q_ddot = gamma:")
        for constraint, gamma in zip(model.constraints, eom.acceleration_rhs, strict=True):
            lines.append(f"  {constraint.name}: gamma = {fmt(gamma)}")

    if eom.accelerations is not None:
        lines += ["", "Accelerations:"]
        for c, a in zip(model.coordinates, eom.accelerations, strict=True):
            lines.append(f"  {c.acceleration} = {fmt(a)}")
    lines += ["", "Convention: M q_ddot + Phi_q^T lambda = f"]
    return "\n".join(lines) + "\n"


def _rows(eom: EquationsOfMotion) -> list[str]:
    """Left-hand sides sum_j M_ij q_ddot_j + sum_k Phi_ki lambda_k as text."""
    model = eom.model
    rows = []
    for i in range(len(model.coordinates)):
        terms = []
        for j, c in enumerate(model.coordinates):
            entry = eom.mass_matrix[i, j]
            if entry != 0:
                terms.append(f"({fmt(entry)})*{c.acceleration}" if entry.is_Add
                             else f"{fmt(entry * c.acceleration)}")
        for k in range(eom.multipliers.rows):
            entry = eom.constraint_jacobian[k, i]
            if entry != 0:
                terms.append(f"({fmt(entry)})*{eom.multipliers[k]}" if entry.is_Add
                             else fmt(entry * eom.multipliers[k]))
        rows.append(" + ".join(terms) if terms else "0")
    return rows


def forces_text(report: ForceReport) -> str:
    at = ", ".join(f"{k} = {v:.6g}" for k, v in report.configuration.items())
    lines = [f"Generalized forces at {at}:"]
    for name, value in report.generalized_forces.items():
        lines.append(f"  Q[{name}] = {value:.6g} {report.units[name]}")
        for load, coordinate, part in report.contributions:
            if coordinate == name:
                lines.append(f"      from {load}: {part:.6g} {report.units[name]}")
    return "\n".join(lines) + "\n"
