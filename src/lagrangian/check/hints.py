"""Hints instead of answers (`check --hints-only`): each finding keeps its item, status and code,
loses its expected expression and any value, and gives its own hint where the diagnosis left one
(a Finding's ``hint``: which slip, never the answer), else the seed module's diagnostic question
for its code (module 7, section 07: misconceptions and diagnostics), so a student can use the
checker alone.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..kinds import FindingStatus
from .diagnose import CheckReport, Finding


@dataclass(frozen=True)
class Hint:
    """One row of the module's misconceptions table: the mistake, its diagnostic question and
    the correction (the module's own words)."""

    mistake: str
    question: str
    correction: str


_SIGN = Hint("Sign error in potential energy", "Does V increase as the body rises?",
             "Take V positive upward and be consistent with the datum.")
_FORCE = Hint("Forgetting a generalized force",
              "Did I do virtual work for every non-potential load?",
              "Project each load with δW = Q · δq.")
_REACTION = Hint("Keeping constraint forces in minimal coordinates",
                 "Do ideal reactions do any virtual work?",
                 "In minimal coordinates they vanish; leave them out.")
_MULTIPLIERS = Hint("Mismatched multiplier count", "Is there one λ per constraint?",
                    "Add exactly one multiplier for each constraint equation.")

# The module's four misconceptions by diagnosis code; the other codes get a question from the
# module's skills (7.1 energies, 7.2 Lagrange's equation), never the answer itself.
HINTS: dict[str, Hint] = {
    "potential_sign": _SIGN,
    "generalized_force_missing": _FORCE,
    "generalized_force_projection": _FORCE,
    "reaction_in_minimal_coordinates": _REACTION,
    "multiplier_count": _MULTIPLIERS,
    "potential_datum": Hint("Another datum for V", "Does only dV/dq enter the equations?",
                            "A constant added to V changes nothing; yours is fine."),
    "kinetic_factor": Hint("A factor in T", "Does every term of T carry 1/2 and its mass or "
                           "inertia?", "Write T = sum 1/2 m v² + 1/2 I ω² in the chosen "
                           "coordinates."),
    "kinetic_term": Hint("A term of T", "Did I write 1/2 m v² of every body's centre and "
                         "1/2 I ω² of its rotation, once each?",
                         "Write each body's speed from its position in the coordinates."),
    "equation_equivalent": Hint("An equivalent form", "Is mine ours multiplied through or "
                                "combined with another equation?",
                                "Equivalent equations give the same motion; yours is fine."),
    "statics_load": _FORCE,
    "statics_potential": _SIGN,
    "statics_value": Hint("A load that holds it", "Is δW = 0 for every admissible δq, with "
                          "every load's, weight's and spring's virtual work?",
                          "Ideal reactions do no virtual work; sum the rest and solve."),
    "units_mismatch": Hint("Units", "Does every term have the same units (T and V in J, Q in J "
                           "per unit of its coordinate)?", "Check each term's units."),
    # each item's own question where no misconception names the slip (issue 40)
    "potential_term": Hint("A term of V", "Did I write the potential of every weight (m g h) "
                           "and every spring (1/2 k s², s its stretch), once each?",
                           "Write V term by term from the heights and the stretches."),
    "dissipation_term": Hint("A term of D", "Does D = sum 1/2 c (rate)² take each damper's "
                             "own rate of stretch?", "Write each damper's rate in the "
                             "coordinates."),
    "generalized_force_wrong": Hint("A generalized force", "Is Q the virtual work per unit of "
                                    "the coordinate, of the non-potential loads only?",
                                    "Project each load with δW = Q · δq; weights and springs "
                                    "belong in V."),
    "unknown_name": Hint("A name the model does not have", "Does every name match the model's "
                         "coordinates and parameters (case matters)?",
                         "Use the model's own names."),
    "lagrangian_wrong": Hint("The Lagrangian", "Is L kinetic minus potential energy, L = T − V?",
                             "Write T and V first, then take their difference."),
    "equation_wrong": Hint("A wrong equation", "Did I apply d/dt(∂L/∂q̇) − ∂L/∂q = Q to this "
                           "coordinate, with every term of T and V differentiated?",
                           "Re-derive the equation from T, V and Q, term by term."),
    "equation_linearized": Hint("A linearized equation", "Is this the full equation of motion, "
                                "or its small-angle form?", "Keep sin and cos in the equation "
                                "of motion; a small-angle form goes under [linearized]."),
    "matrix_entry": Hint("A matrix entry", "Is M from the terms of T in q̇ and K from the "
                         "second derivatives of V at the equilibrium?",
                         "Read M from T and K from V, entry by entry."),
    "frequency_wrong": Hint("A natural frequency", "Does ω² solve det(K − ω² M) = 0, in rad/s?",
                            "Solve the eigenproblem with the model's M and K."),
    "frequency_count": Hint("How many frequencies", "Is there one natural frequency per degree "
                            "of freedom?", "List one per mode."),
    "damping_ratio_wrong": Hint("A damping ratio", "Is ζ = c / (2 √(k m)) for one coordinate, "
                                "c over its critical value?", "Compare c with 2 √(k m)."),
    "mode_shape_wrong": Hint("A mode shape", "Does the shape solve (K − ω² M) φ = 0 for its "
                             "frequency?", "Substitute ω² and solve for the ratio of the "
                             "components."),
    "linear_coefficient": Hint("A linearized coefficient", "Did I expand each term to first "
                               "order about the equilibrium (sin θ ≈ θ − θ₀ there)?",
                               "Take the derivative of each term at the equilibrium."),
    "linear_offset": Hint("A linearized offset", "Is the expansion about the equilibrium, "
                          "where the constant terms balance?", "Measure the coordinates from "
                          "the equilibrium."),
    "not_linearized": Hint("Not linearized", "Is every term first order in the coordinates "
                           "and rates about the equilibrium?", "Drop the products and powers "
                           "of small quantities."),
    "generalized_force_value": _FORCE,
    "equilibrium_wrong": Hint("An equilibrium", "Do the forces balance there at rest, "
                              "dV/dq = Q with q̇ = 0?", "Solve dV/dq = Q for each coordinate."),
    # what L conserves, Routh and Hamilton (check/conserved_answers.py)
    "momentum_wrong": Hint("A momentum", "Is p = ∂L/∂q̇, with every term of T that has q̇?",
                           "Differentiate L with respect to the rate, cross terms included."),
    "not_cyclic": Hint("A coordinate taken for cyclic", "Does L contain the coordinate itself, "
                       "not only its rate?", "Only a coordinate absent from L is cyclic."),
    "cyclic_missing": Hint("A cyclic coordinate left out", "Which coordinates does L not "
                           "contain?", "Each such coordinate's momentum is conserved."),
    "momentum_not_conserved": Hint("A broken momentum", "Does a load do virtual work along "
                                   "the cyclic coordinate?", "A cyclic momentum is conserved "
                                   "only where Q along it vanishes."),
    "energy_not_conserved": Hint("T + V taken for conserved", "Does a drive, a load or explicit "
                                 "time do work on the system?", "Where a drive does work, the "
                                 "Jacobi integral h = q̇ · ∂L/∂q̇ − L may be conserved "
                                 "instead."),
    "not_conserved": Hint("A quantity that changes", "Does dF/dt vanish by the equations of "
                          "motion?", "Look for cyclic coordinates and for h."),
    "routhian_sign": Hint("The Routhian's sign", "Which convention: R = p q̇ − L, or the "
                          "reduced Lagrangian L_R = −R?", "Here R = Σ p q̇ − L (Goldstein)."),
    "effective_potential": Hint("The effective potential", "Did you write the cyclic rate "
                                "through its momentum before forming R?",
                                "Eliminate q̇ of the cyclic coordinate with p = ∂L/∂q̇."),
    "routhian_wrong": Hint("The Routhian", "Is R = Σ p q̇ − L over the cyclic coordinates, "
                           "their rates written through p?", "Form R term by term."),
    "hamiltonian_in_velocities": Hint("H in the rates", "Is H written in the momenta p?",
                                      "Write each q̇ through p = ∂L/∂q̇."),
    "hamiltonian_inverse": Hint("M for M⁻¹", "Did you invert p = M q̇ for q̇?",
                                "The kinetic part of H is ½ pᵀ M⁻¹ p."),
    "hamiltonian_wrong": Hint("The Hamiltonian", "Is H = p · q̇ − L with q̇ written through p?",
                              "Form H from the momenta, term by term."),
    "equilibrium_missing": Hint("An equilibrium left out", "Did I find every configuration "
                                "where dV/dq = Q at rest (each root, within the coordinate's "
                                "range)?", "Solve dV/dq = Q for all its roots."),
}
GENERAL = Hint("A wrong item", "Did I apply d/dt(∂L/∂q̇) − ∂L/∂q = Q to each coordinate, with "
               "L = T − V and every generalized force included?",
               "Re-derive the item from T, V and virtual work, step by step.")


def hint_for(code: str | None) -> Hint:
    """The module's hint for a diagnosis code (the general one for a code it does not name)."""
    return HINTS.get(code or "", GENERAL)


def hinted(report: CheckReport) -> CheckReport:
    """``report`` with every expected expression removed and every finding that is not correct
    worded as the module's diagnostic question and correction (no expression, no value)."""
    return replace(report, findings=tuple(_hinted(f) for f in report.findings))


def _hinted(finding: Finding) -> Finding:
    if finding.status == FindingStatus.CORRECT:
        return replace(finding, expected=None)
    if finding.hint:  # the item's own, specific and non-revealing
        return replace(finding, message=finding.hint, expected=None)
    hint = hint_for(finding.code)
    return replace(finding, message=f"{hint.question} {hint.correction}", expected=None)


__all__ = ["GENERAL", "HINTS", "Hint", "hint_for", "hinted"]
