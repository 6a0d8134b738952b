"""The derivation (`derive`): text for a terminal, the JSON document, and LaTeX for a paper.

Text and JSON write expressions in the model-file grammar (readable, copyable, and read back by
``parse_expression``); LaTeX uses the model's symbol names. Equations too large to print written
out (a deep chain of bodies) are written in named intermediate quantities, listed first
(derivation/intermediates.py); ``expand=True`` (derive --expand) writes them out all the same.
"""

from __future__ import annotations

from typing import Any

import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..model.expressions import format_expression
from ..model.units import generalized_force_unit
from .derivation_display import _Display

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
    # Lagrange's equations name L and Q: written out when the model uses either letter.
    lagrangian = ("L" if "L" not in names else "(T - V)" if not names & {"T", "V"}
                  else "(Lagrangian)")
    force = "Q" if "Q" not in names else "(generalized force)"
    labels["equations"] = (f"Equations of motion, d/dt(d{lagrangian}/dq_dot) - d{lagrangian}/dq"
                           f" = {force}")
    return labels


def derivation_text(eom: EquationsOfMotion, expand: bool = False) -> str:
    """The `derive` text; ``expand``: every expression written out, however large."""
    model = eom.model
    fmt = _Display(eom, expand)
    lines = [model.name, "=" * len(model.name)]
    coordinates = ", ".join(f"{c.name} [{c.unit or '1'}]" for c in model.coordinates)
    lines += [f"Coordinates: {coordinates}", ""]
    named = fmt.definitions()
    if named:
        lines.append(f"Intermediate quantities ({len(named)}; each in the ones before it, and "
                     "the equations below in them; derive --expand writes them out).")
        lines.append("Bodies by number (R rotation, omega angular velocity in body axes, o "
                     "origin, p centre of mass, v, a its velocity, acceleration at q_ddot = 0; "
                     "d/dt as dR, vo, alpha):")
        lines.append("  " + ", ".join(f"{k} {b.name}" for k, b in
                                       enumerate(model.rigid_bodies, start=1)))
        lines += [f"  {name} = {text}" for name, text in named]
        lines.append("")
    label = _labels(model)
    lines += [f"{label['T']} = {fmt(eom.kinetic_energy)}",
              f"{label['V']} = {fmt(eom.potential_energy)}"]
    if eom.dissipation != 0:
        lines.append(f"{label['D']} = {fmt(eom.dissipation)}")
    lines += [f"{label['L']} = {format_expression(fmt.lagrangian(eom))}", ""]

    lines.append(label["equations"] + (" - Phi_q^T lambda" if model.constraints else "") + ":")
    for c, row, f in zip(model.coordinates, _rows(eom, fmt), eom.forcing, strict=True):
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
            lines.append(f"  {constraint.name} ({constraint.kind}): "
                         f"{fmt(constraint.expression, plain=True)} = 0   "
                         f"multiplier {eom.multipliers[k]}")
        lines.append("Constraint Jacobian Phi_q:")
        for i in range(eom.constraint_jacobian.rows):
            lines.append("  [" + ", ".join(fmt(v, plain=True)
                                           for v in eom.constraint_jacobian.row(i)) + "]")
        lines.append("Acceleration level, Phi_q q_ddot = gamma:")
        for constraint, gamma in zip(model.constraints, eom.acceleration_rhs, strict=True):
            lines.append(f"  {constraint.name}: gamma = {fmt(gamma, plain=True)}")

    if eom.accelerations is not None:
        lines += ["", "Accelerations:"]
        for c, a in zip(model.coordinates, eom.accelerations, strict=True):
            lines.append(f"  {c.acceleration} = {fmt(a)}")
    elif eom.accelerations_note:
        lines += ["", f"Accelerations: {eom.accelerations_note}"]
    lines += ["", f"Convention: {label['convention']}"]
    return "\n".join(lines) + "\n"


def _rows(eom: EquationsOfMotion, fmt: _Display) -> list[str]:
    """Left-hand sides sum_j M_ij q_ddot_j + sum_k Phi_ki lambda_k as text."""
    model = eom.model
    rows = []
    for i in range(len(model.coordinates)):
        terms = []
        for j, c in enumerate(model.coordinates):
            terms.append(_product_text(fmt.form(eom.mass_matrix[i, j]), c.acceleration))
        for k in range(eom.multipliers.rows):
            terms.append(_product_text(fmt.plain(eom.constraint_jacobian[k, i]),
                                       eom.multipliers[k]))
        text = ""
        for term in filter(None, terms):
            if not text:
                text = term
            elif term.startswith("-"):
                text += " - " + term[1:]
            else:
                text += " + " + term
        rows.append(text or "0")
    return rows


def _product_text(coefficient: sp.Expr, unknown: sp.Symbol) -> str:
    """coefficient*unknown as text, the sum in parentheses ('' for a zero coefficient)."""
    if coefficient == 0:
        return ""
    if coefficient.is_Add:
        negated = -coefficient
        if sp.count_ops(negated) < sp.count_ops(coefficient) and not negated.is_Add:
            return "-" + format_expression(negated * unknown)
        return f"({format_expression(coefficient)})*{unknown}"
    if (coefficient.is_Mul and any(factor.is_Add for factor in coefficient.args)
            and coefficient.as_coeff_Mul()[0].is_Integer):
        return f"{format_expression(coefficient)}*{unknown}"  # the unknown after the sum
    return format_expression(coefficient * unknown)


# -- JSON ---------------------------------------------------------------------------------------


def derivation_document(eom: EquationsOfMotion, expand: bool = False) -> dict[str, Any]:
    """The `derive --format json` document; where the equations are large, an "intermediates"
    list of {"name", "expression"} that the other expressions are written in (not with
    ``expand``)."""
    model = eom.model
    names = [c.name for c in model.coordinates]
    text = _Display(eom, expand)
    document: dict[str, Any] = {
        "name": model.name,
        "convention": CONVENTION,
        "coordinates": names,
        "parameters": {p.name: p.value for p in model.parameters},
        "kinetic_energy": text(eom.kinetic_energy),
        "potential_energy": text(eom.potential_energy),
        "dissipation": text(eom.dissipation),
        "lagrangian": format_expression(text.lagrangian(eom)),
        "generalized_forces": {n: text(v) for n, v in zip(names, eom.generalized_forces,
                                                           strict=True)},
        "load_contributions": [
            {"load": c.load, "coordinate": c.coordinate, "expression": text(c.expression)}
            for c in eom.load_contributions
        ],
        "mass_matrix": [[text(v) for v in eom.mass_matrix.row(i)]
                        for i in range(eom.mass_matrix.rows)],
        "forcing": [text(v) for v in eom.forcing],
        "equations": {n: format_expression(v)
                      for n, v in zip(names, text.equations(eom), strict=True)},
        "accelerations": {
            n: (text(v) if eom.accelerations is not None else None)
            for n, v in zip(names, eom.accelerations if eom.accelerations is not None
                            else [None] * len(names), strict=True)
        },
        "accelerations_note": eom.accelerations_note,
    }
    named = text.definitions()
    if named:
        document["intermediates"] = [{"name": n, "expression": e} for n, e in named]
    if model.constraints:
        document["constraints"] = {
            "names": [c.name for c in model.constraints],
            "kinds": [c.kind for c in model.constraints],
            "multipliers": [str(s) for s in eom.multipliers],
            "jacobian": [[text(v, plain=True) for v in eom.constraint_jacobian.row(i)]
                         for i in range(eom.constraint_jacobian.rows)],
            "acceleration_rhs": [text(v, plain=True) for v in eom.acceleration_rhs],
        }
    return document


# -- LaTeX --------------------------------------------------------------------------------------


def derivation_latex(eom: EquationsOfMotion, standalone: bool = False,
                     expand: bool = False) -> str:
    """LaTeX (amsmath) ready to paste into a paper, or with ``standalone`` a complete document
    for pdflatex (output/latex.py: M q_ddot = f per coordinate, long rows broken)."""
    from .latex import handout_latex  # LaTeX's printer: loaded by --format latex

    return handout_latex(eom, standalone=standalone, expand=expand)
