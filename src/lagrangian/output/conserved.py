"""What L conserves, the Routhian and Hamilton's equations as text (the module's notation,
with the model-file grammar beside it) and as JSON documents."""

from __future__ import annotations

from typing import Any

import sympy as sp

from ..analysis.conserved import ConservedKind, ConservedQuantities
from ..analysis.hamilton import Hamiltonian
from ..model.expressions import format_expression
from ..model.model import Model
from .module_notation import module_notation

_KIND_WORDS = {
    ConservedKind.MOMENTUM: "momentum of a cyclic coordinate",
    ConservedKind.JACOBI: "Jacobi integral h = q_dot . dL/dq_dot - L",
    ConservedKind.NOETHER: "Noether quantity of a symmetry no coordinate shows",
}
ROUTH_CONVENTION = ("R = sum p_k q_dot_k - L (Goldstein, Landau); the reduced Lagrangian "
                    "is L_R = -R")


def _generator_text(generator) -> str:
    return "(" + ", ".join(format_expression(x) for x in generator) + ")"


def conserved_lines(found: ConservedQuantities, model: Model) -> list[str]:
    """One line per conserved quantity (and per broken candidate), for derive --steps too."""
    lines = []
    for q in found:
        words = _KIND_WORDS[q.kind]
        if q.kind == ConservedKind.JACOBI:
            words += ", equal to T + V" if q.equals_energy else \
                ", NOT T + V (T + V is not conserved here)"
        if q.kind == ConservedKind.NOETHER:
            words += f", generator xi = {_generator_text(q.generator)}"
        lines.append(f"  {q.name} = {module_notation(q.expression)}    [{words}]")
        lines.append(f"      as written in a model file: {q.text}")
    for b in found.broken:
        lines.append(f"  not conserved: {b.name} ({b.kind}): {b.reason}")
    if not found and not found.broken:
        lines.append("  (none found)")
    if found.note:
        lines.append(f"  note: {found.note}")
    return lines


def conserved_text(found: ConservedQuantities, model: Model) -> str:
    """The `conserved` command's text."""
    title = f"Conserved quantities of {model.name}"
    lines = [title, "=" * len(title), *conserved_lines(found, model)]
    if found.not_cyclic:
        lines.append("Not cyclic (L depends on them): " + "; ".join(
            f"{name} through {terms}" for name, terms in found.not_cyclic))
    return "\n".join(lines) + "\n"


def conserved_document(found: ConservedQuantities, model: Model) -> dict[str, Any]:
    """The `conserved --json` document."""
    return {
        "name": model.name,
        "coordinates": [c.name for c in model.coordinates],
        "conserved": [{"name": q.name, "kind": str(q.kind), "expression": q.text,
                       "notation": module_notation(q.expression),
                       "generator": [format_expression(x) for x in q.generator],
                       "equals_energy": q.equals_energy} for q in found],
        "not_conserved": [{"name": b.name, "kind": str(b.kind), "reason": b.reason}
                          for b in found.broken],
        "not_cyclic": dict(found.not_cyclic),
        "note": found.note,
    }


def routhian_text(reduced: Model) -> str:
    """derive --routh: the reduced Lagrangian, its effective potential and the convention."""
    L_R = reduced.kinetic_energy - reduced.potential_energy
    momenta = [p for p in reduced.parameters if p.name.startswith("p_")]
    lines = [reduced.name, "=" * len(reduced.name),
             f"Convention: {ROUTH_CONVENTION}",
             "Kept coordinates: " + ", ".join(c.name for c in reduced.coordinates),
             "Constant momenta: " + ", ".join(
                 f"{p.name} = {p.value:.6g} {p.unit or ''}".rstrip() if p.value is not None
                 else p.name for p in momenta),
             f"L_R = {module_notation(L_R)}",
             f"    as written in a model file: {format_expression(L_R)}",
             f"Effective potential V_R = {module_notation(reduced.potential_energy)}",
             f"    as written in a model file: {format_expression(reduced.potential_energy)}"]
    return "\n".join(lines) + "\n"


def routhian_document(reduced: Model) -> dict[str, Any]:
    L_R = reduced.kinetic_energy - reduced.potential_energy
    return {"name": reduced.name, "convention": ROUTH_CONVENTION,
            "coordinates": [c.name for c in reduced.coordinates],
            "parameters": {p.name: p.value for p in reduced.parameters},
            "reduced_lagrangian": format_expression(L_R),
            "routhian": format_expression(-L_R),
            "kinetic_part": format_expression(reduced.kinetic_energy),
            "effective_potential": format_expression(reduced.potential_energy)}


_WRITTEN_OPS = 40  # -dH/dq up to this many operations is written out in the text


def hamiltonian_text(hamiltonian: Hamiltonian) -> str:
    """derive --hamilton: the momenta, H and Hamilton's equations."""
    model = hamiltonian.eom.model
    title = f"Hamilton's equations of {model.name}"
    lines = [title, "=" * len(title), "Momenta p = dL/dq_dot:"]
    for p, expression in zip(hamiltonian.momenta, hamiltonian.momentum_expressions, strict=True):
        lines.append(f"  {p} = {module_notation(expression)}    ({format_expression(expression)})")
    H = hamiltonian.H
    lines += [f"H = {module_notation(H)}", f"    as written in a model file: "
              f"{format_expression(H)}", "Equations: q_dot = dH/dp, p_dot = -dH/dq + Q"]
    forces = hamiltonian.eom.generalized_forces
    for q, p, Q in zip(model.q, hamiltonian.momenta, forces, strict=True):
        extra = "" if Q == 0 else f" + Q[{q}]"
        lines.append(f"  {q}_dot = {format_expression(sp.simplify(H.diff(p)))}")
        rate = -H.diff(q)  # written out where it reads at a glance; --json has it always
        written = (f" = {format_expression(rate + Q)}" if sp.count_ops(rate) <= _WRITTEN_OPS
                   else " (written out in --json)")
        lines.append(f"  {p}_dot = -dH/d{q}{extra}{written}")
    return "\n".join(lines) + "\n"


def hamiltonian_document(hamiltonian: Hamiltonian) -> dict[str, Any]:
    model = hamiltonian.eom.model
    H = hamiltonian.H
    return {"name": model.name,
            "coordinates": [c.name for c in model.coordinates],
            "momenta": {str(p): format_expression(e) for p, e in
                        zip(hamiltonian.momenta, hamiltonian.momentum_expressions, strict=True)},
            "hamiltonian": format_expression(H),
            "q_dot": {str(q): format_expression(sp.simplify(H.diff(p)))
                      for q, p in zip(model.q, hamiltonian.momenta, strict=True)},
            "p_dot": {str(p): format_expression(-H.diff(q)) for q, p in
                      zip(model.q, hamiltonian.momenta, strict=True)},
            "generalized_forces": {str(q): format_expression(Q) for q, Q in
                                   zip(model.q, hamiltonian.eom.generalized_forces,
                                       strict=True)},
            "convention": "p_dot = -dH/dq + Q (Q at q_dot = dH/dp)"}


__all__ = ["ROUTH_CONVENTION", "conserved_document", "conserved_lines", "conserved_text",
           "hamiltonian_document", "hamiltonian_text", "routhian_document", "routhian_text"]
