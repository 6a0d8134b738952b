"""Hints instead of answers (`check --hints-only`): each finding keeps its item, status and code,
loses its expected expression and any value, and gives the seed module's diagnostic question
(module 7, section 07: misconceptions and diagnostics) so a student can use the checker alone.
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
    hint = hint_for(finding.code)
    return replace(finding, message=f"{hint.question} {hint.correction}", expected=None)


__all__ = ["GENERAL", "HINTS", "Hint", "hint_for", "hinted"]
