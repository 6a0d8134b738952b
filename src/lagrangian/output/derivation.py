"""The derivation (`derive`): text for a terminal, the JSON document, and LaTeX for a paper.

Text and JSON write expressions in the model-file grammar (readable, copyable, and read back by
``parse_expression``); LaTeX uses the model's symbol names.
"""

from __future__ import annotations

from typing import Any

from ..derivation.equations import EquationsOfMotion
from ..model.expressions import format_expression as fmt
from ..model.notation import latex_printer
from ..model.units import generalized_force_unit

CONVENTION = "M q_ddot + Phi_q^T lambda = forcing"


# -- text ---------------------------------------------------------------------------------------

# The letters the text labels its lines with, and the words used instead when the model has a
# parameter or coordinate of that name (a length L beside "L = T - V", a mass M beside "Mass
# matrix M"), so that a reader never takes one for the other.
_LETTER_LABELS = {
    "T": ("T", "Kinetic energy"),
    "V": ("V", "Potential energy"),
    "D": ("D", "Dissipation function"),
    "L": ("L = T - V", "Lagrangian T - V"),
    "M": ("Mass matrix M", "Mass matrix"),
    "f": ("Forcing f", "Forcing"),
}


def _labels(model) -> dict[str, str]:
    names = {p.name for p in model.parameters} | {c.name for c in model.coordinates}
    labels = {letter: words if letter in names else short
              for letter, (short, words) in _LETTER_LABELS.items()}
    if names & {"T", "V"}:  # "T - V" would name them too
        labels["L"] = "Lagrangian (kinetic less potential energy)"
    labels["convention"] = ("M q_ddot + Phi_q^T lambda = f" if not names & {"M", "f"} else
                            "(mass matrix) q_ddot + Phi_q^T lambda = (forcing)")
    return labels



def derivation_text(eom: EquationsOfMotion) -> str:
    model = eom.model
    lines = [model.name, "=" * len(model.name)]
    coordinates = ", ".join(f"{c.name} [{c.unit or '1'}]" for c in model.coordinates)
    lines += [f"Coordinates: {coordinates}", ""]
    label = _labels(model)
    lines += [f"{label['T']} = {fmt(eom.kinetic_energy)}",
              f"{label['V']} = {fmt(eom.potential_energy)}"]
    if eom.dissipation != 0:
        lines.append(f"{label['D']} = {fmt(eom.dissipation)}")
    lines += [f"{label['L']} = {fmt(eom.lagrangian)}", ""]

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

    lines.append(f"{label['M']}:")
    for i in range(eom.mass_matrix.rows):
        lines.append("  [" + ", ".join(fmt(v) for v in eom.mass_matrix.row(i)) + "]")
    lines.append(f"{label['f']}:")
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
    elif eom.accelerations_note:
        lines += ["", f"Accelerations: {eom.accelerations_note}"]
    lines += ["", f"Convention: {label['convention']}"]
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


# -- JSON ---------------------------------------------------------------------------------------


def derivation_document(eom: EquationsOfMotion) -> dict[str, Any]:
    """The `derive --format json` document."""
    model = eom.model
    names = [c.name for c in model.coordinates]
    text = fmt
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
        "accelerations_note": eom.accelerations_note,
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


# -- LaTeX --------------------------------------------------------------------------------------


def derivation_latex(eom: EquationsOfMotion) -> str:
    """A self-contained LaTeX fragment (amsmath) ready to paste into a paper."""
    model = eom.model
    tex = latex_printer(model)

    lines = [f"% {model.name}: equations of motion by Lagrange's method",
             r"% Convention: M \ddot{q} + \Phi_q^T \lambda = f", r"\begin{align}"]
    lines.append(rf"T &= {tex(eom.kinetic_energy)} \\")
    lines.append(rf"V &= {tex(eom.potential_energy)} \\")
    if eom.dissipation != 0:
        lines.append(rf"D &= {tex(eom.dissipation)} \\")
    lines.append(rf"L &= T - V = {tex(eom.lagrangian)} \\")
    for c, total in zip(model.coordinates, eom.generalized_forces, strict=True):
        lines.append(rf"Q_{{{tex(c.symbol)}}} &= {tex(total)} \\")
    for c, equation in zip(model.coordinates, eom.equations, strict=True):
        lines.append(rf"0 &= {tex(equation)} && \text{{({c.name})}} \\")
    lines.append(rf"M &= {tex(eom.mass_matrix)} \\")
    lines.append(rf"f &= {tex(eom.forcing)}")
    if model.constraints:
        lines[-1] += r" \\"
        lines.append(rf"\Phi_q &= {tex(eom.constraint_jacobian)} \\")
        lines.append(rf"\gamma &= {tex(eom.acceleration_rhs)}")
    lines.append(r"\end{align}")
    return "\n".join(lines) + "\n"
