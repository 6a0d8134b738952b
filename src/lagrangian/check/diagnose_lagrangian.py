"""[energy] L of an answer, checked as T - V (ladder level 3 asks for the Lagrangian itself).

L is split where it can be: when its velocity terms are those of our L, the potential it
implies, T - L, is judged as V is (a sign slip in one term gets potential_sign naming it);
when its terms at rest are ours, the kinetic energy it implies, L + V, is judged as T is.
"""

from __future__ import annotations

from dataclasses import replace

import sympy as sp

from ..kinds import FindingStatus
from ..model.expressions import format_expression as fmt
from . import equivalence as eq


def lagrangian_findings(checker, L_user: sp.Expr, Finding) -> list:
    """The findings on L (item "L"); ``checker`` is diagnose's _Checker, ``Finding`` its
    finding type (passed in: this room sits below diagnose)."""
    eom, points, model = checker.eom, checker.points, checker.model
    T, V = eom.kinetic_energy, eom.potential_energy
    L = T - V
    expected = fmt(eq.display(L))
    foreign = checker.answer.foreign_symbols("L")
    if foreign:
        listed = ", ".join(sorted(map(str, foreign)))
        return [Finding("L", "wrong", "unknown_name", checker._misspelled(foreign, "L")
                        or f"L uses {listed}, which the model does not declare.", expected)]
    if eq.identical(L_user, L, points):
        return [Finding("L", "correct", None, "L = T - V matches.", None)]
    if eq.constant_in_state(L_user - L, points):
        return [Finding("L", "equivalent", "potential_datum",
                        f"L differs from ours only by the constant {fmt(eq.display(L_user - L))}"
                        ": another datum for V, which is fine.", expected)]
    if eq.constant_in_state(L_user - (T + V), points):
        return [Finding("L", "wrong", "potential_sign",
                        "yours is T + V: the Lagrangian is kinetic minus potential energy, "
                        "L = T - V.", expected)]
    if eq.constant_in_state(L_user + L, points):
        return [Finding("L", "wrong", "potential_sign",
                        "yours is V - T: the Lagrangian is L = T - V.", expected)]
    rest = dict.fromkeys(model.q_dot, sp.S.Zero)
    moving = L_user - L - (L_user - L).xreplace(rest)  # the velocity terms that differ
    if eq.zero(moving, points):
        found = checker.potential(T - L_user)  # the V your L implies
        return [_as_lagrangian(f, expected, "the potential energy in your L") for f in found]
    if eq.constant_in_state((L_user - L).xreplace(rest), points):
        found = checker.kinetic(L_user + V)  # the T your L implies
        return [_as_lagrangian(f, expected, "the kinetic energy in your L") for f in found]
    return [Finding("L", "wrong", "lagrangian_wrong",
                    "both the kinetic and the potential terms of L differ from ours: yours "
                    f"minus ours is {fmt(eq.display(L_user - L))}; L = T - V.", expected)]


def _as_lagrangian(finding, expected: str, part: str):
    """A finding on the T or V an L implies, said of L."""
    if finding.status == FindingStatus.CORRECT:
        return replace(finding, item="L", message="L = T - V matches.")
    return replace(finding, item="L", message=f"In L = T - V, {part}: {finding.message}",
                   expected=expected)


__all__ = ["lagrangian_findings"]
