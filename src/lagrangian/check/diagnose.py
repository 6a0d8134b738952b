"""Verdicts on a hand derivation, with diagnoses in the seed's own terms (module 7, section 07).

Each item of the user's answer (T, V, D, Q[q], equation[q], multipliers) is compared with the
Lagrange derivation by probabilistic identity testing (see :mod:`.equivalence`). A wrong item
gets one diagnosis code and the corrected item; ``equation_wrong`` is also the fallback for an
item that is wrong in a way no more specific diagnosis names.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..errors import misspelled
from ..kinds import FindingStatus
from ..model.answer import Answer, answer_names
from ..model.expressions import as_expression
from ..model.expressions import format_expression as fmt
from ..model.model import Model
from ..model.units import generalized_force_unit
from . import equivalence as eq
from .diagnose_equations import EquationDiagnoses
from .diagnose_lagrangian import lagrangian_findings
from .diagnose_terms import (
    flipped_potential_term,
    kinetic_parts,
    potential_parts,
    projection_message,
    sign_question,
)
from .finding import Finding
from .units import answer_unit_issues

CODES = (
    "potential_sign", "potential_datum", "kinetic_factor", "kinetic_term",
    "generalized_force_missing", "generalized_force_projection",
    "reaction_in_minimal_coordinates", "multiplier_count", "equation_wrong",
    "equation_equivalent", "units_mismatch", "equation_linearized",
    # the item's own code where no more specific diagnosis names the slip (issue 40)
    "potential_term", "dissipation_term", "generalized_force_wrong", "unknown_name",
    "lagrangian_wrong",
)


@dataclass(frozen=True)
class CheckReport:
    """All findings on an answer; the verdict is 'correct' unless some item is wrong."""

    model: str
    answer: str
    findings: tuple[Finding, ...]

    @property
    def verdict(self) -> str:
        return "incorrect" if any(f.status == FindingStatus.WRONG for f in self.findings) \
            else "correct"

    @property
    def correct(self) -> bool:
        return self.verdict == "correct"

    @property
    def passed(self) -> bool:
        """The check passed: every item is correct or equivalent (the same as ``correct``)."""
        return self.correct

    def codes(self, item: str | None = None) -> list[str]:
        return [f.code for f in self.findings if f.code and (item is None or f.item == item)]

    def __repr__(self) -> str:
        lines = [f"CheckReport({self.verdict})"]
        lines += [f"  {f.item}: {f.status}" + (f" [{f.code}]" if f.code else "") + f" {f.message}"
                  for f in self.findings]
        return "\n".join(lines)


# -- the checker -------------------------------------------------------------------------


def check_answer(eom: EquationsOfMotion, answer: Answer) -> CheckReport:
    """Compare every item of ``answer`` with the Lagrange derivation ``eom``."""
    model = eom.model
    foreign = set().union(*(symbols for _, symbols in answer.foreign)) if answer.foreign else set()
    points = eq.random_points(model, foreign)
    checker = _Checker(eom, answer, points)
    numeric = _NumericItems(model, eq.random_points(model, foreign, model_values=True), checker)
    findings: list[Finding] = []
    if answer.kinetic_energy is not None:
        findings += numeric.run(checker.kinetic, [answer.kinetic_energy], [eom.kinetic_energy],
                                answer.kinetic_energy)
    if answer.potential_energy is not None:
        findings += numeric.run(checker.potential, [answer.potential_energy],
                                [eom.potential_energy], answer.potential_energy)
    if answer.dissipation is not None:
        findings += numeric.run(checker.dissipation, [answer.dissipation], [eom.dissipation],
                                answer.dissipation)
    if answer.lagrangian is not None:  # checked as T - V
        findings += numeric.run(lambda value: lagrangian_findings(checker, value, Finding),
                                [answer.lagrangian], [eom.lagrangian], answer.lagrangian)
    for name, value in answer.generalized_forces:
        i = [c.name for c in model.coordinates].index(name)
        findings += numeric.run(checker.generalized_force, [value],
                                [eom.generalized_forces[i]], name, value)
    if answer.equations:
        findings += numeric.run(checker.equations, [v for _, v in answer.equations],
                                list(eom.equations))
    if answer.multiplier_count is not None or answer.multiplier_names is not None:
        findings += checker.multipliers()
    findings += checker.units()
    unique, seen = [], set()
    for finding in findings:  # one multiplier_count finding, whichever item raised it first
        key = (finding.item, finding.code) if finding.code == "multiplier_count" else id(finding)
        if key not in seen:
            seen.add(key)
            unique.append(finding)
    return CheckReport(model.name, answer.source, tuple(unique))


class _NumericItems:
    """Items that write numbers in place of parameters (9.81 for g) are compared at the
    model's parameter values instead of at random ones, and the finding says so."""

    NOTE = " (compared at the model's parameter values: numbers stand in for parameters)"

    def __init__(self, model: Model, points: eq.Points, checker: _Checker):
        self.valued = {p.symbol for p in model.parameters if p.value is not None}
        self.points = points
        self.checker = checker

    def run(self, method, yours: list[sp.Expr], ours: list[sp.Expr], *args) -> list[Finding]:
        yours = [as_expression(e) for e in yours]
        used = set().union(*(e.free_symbols for e in yours))
        needed = set().union(*(as_expression(e).free_symbols for e in ours)) & self.valued
        if not needed - used or not any(_measured(e) for e in yours):
            return method(*args)
        saved, self.checker.points = self.checker.points, self.points
        try:
            findings = method(*args)
        finally:
            self.checker.points = saved
        return [replace(f, message=f.message.rstrip() + self.NOTE) for f in findings]


class _Checker(EquationDiagnoses):
    Finding = Finding  # the type EquationDiagnoses builds its findings with

    def __init__(self, eom: EquationsOfMotion, answer: Answer, points: eq.Points):
        self.eom = eom
        self.model = eom.model
        self.answer = answer
        self.points = points
        self.names = [c.name for c in self.model.coordinates]

    # T ---------------------------------------------------------------------------------

    def kinetic(self, T_user: sp.Expr) -> list[Finding]:
        T = self.eom.kinetic_energy
        unknown = self._unknown_names("T", "T")
        if unknown:
            return unknown
        if eq.identical(T_user, T, self.points):
            return [Finding("T", "correct", None, "T matches.", None)]
        expected = fmt(eq.display(T))  # a wrong T's finding shows ours (simplify: not before)
        parts = kinetic_parts(self.model)
        for label, part in parts:
            if len(parts) > 1 and eq.identical(T_user, T - part, self.points):
                return [Finding("T", "wrong", "kinetic_term",
                                f"T is missing the {label}: {fmt(eq.display(part))}.", expected)]
        for label, part in parts:
            if len(parts) > 1 and eq.identical(T_user, T + part, self.points):
                return [Finding("T", "wrong", "kinetic_term",
                                f"T counts the {label} twice: {fmt(eq.display(part))}.", expected)]
        if not eq.zero(T, self.points) and eq.constant_in_state(T_user / T, self.points):
            factor = eq.display(sp.cancel(T_user / T))
            hint = ""
            if factor == 2:
                hint = " (a forgotten 1/2?)"
            elif (1 / factor).free_symbols and (1 / factor).free_symbols <= self._masses():
                hint = f" (a missing mass {fmt(1 / factor)}?)"
            return [Finding("T", "wrong", "kinetic_factor",
                            f"T is {fmt(factor)} times the kinetic energy{hint}: every term of "
                            "T = sum 1/2 m v^2 + 1/2 I w^2 carries 1/2 and its mass or inertia.",
                            expected)]
        difference = eq.display(T_user - T)
        return [Finding("T", "wrong", "kinetic_term",
                        f"T has a wrong or extra term: yours minus ours is {fmt(difference)}.",
                        expected)]

    def _masses(self) -> set[sp.Symbol]:
        """Parameters that are masses: in kg, or in a particle's or body's mass."""
        masses = {p.symbol for p in self.model.parameters if (p.unit or "").strip() == "kg"}
        for item in (*self.model.particles, *self.model.bodies):
            masses |= item.mass.free_symbols
        return masses

    # V ---------------------------------------------------------------------------------

    def potential(self, V_user: sp.Expr) -> list[Finding]:
        V = self.eom.potential_energy
        unknown = self._unknown_names("V", "V")
        if unknown:
            return unknown
        if eq.identical(V_user, V, self.points):
            return [Finding("V", "correct", None, "V matches.", None)]
        expected = fmt(eq.display(V))  # a wrong V's finding shows ours (simplify: not before)
        if eq.constant_in_state(V_user - V, self.points):
            offset = eq.display(V_user - V)
            return [Finding("V", "equivalent", "potential_datum",
                            f"V differs from ours only by the constant {fmt(offset)}: another "
                            "datum, which is fine (only dV/dq enters the equations).", expected)]
        rises = ("Does V increase as the body rises? Take V positive upward (V = m g h) "
                 "and be consistent with the datum.")
        parts = potential_parts(self.model)
        if eq.constant_in_state(V_user + V, self.points):
            question = sign_question([label for label, _ in parts], rises)
            return [Finding("V", "wrong", "potential_sign", f"V has the wrong sign. {question}",
                            expected, hint=None if question == rises else question)]
        if len(parts) > 1:
            for label, part in parts:
                if eq.constant_in_state(V_user - (V - 2 * part), self.points):
                    return [Finding("V", "wrong", "potential_sign",
                                    f"the {label} has the wrong sign (it should be "
                                    f"{fmt(eq.display(part))}). {sign_question([label], rises)}",
                                    expected, hint=f"The {label} has the wrong sign. "
                                    + sign_question([label], rises))]
        flipped = flipped_potential_term(V_user, V, self.model, self.points)
        if flipped is not None:
            labels, term = flipped
            return [Finding("V", "wrong", "potential_sign",
                            f"the term {fmt(eq.display(term))} of the "
                            f"{' and the '.join(labels)} has the wrong sign (yours has "
                            f"{fmt(eq.display(-term))}). {sign_question(labels, rises)}",
                            expected, hint=f"One term of the {' and the '.join(labels)} has "
                            f"the wrong sign. {sign_question(labels, rises)}")]
        for label, part in parts:
            if eq.constant_in_state(V_user - (V - part), self.points):
                return [Finding("V", "wrong", "potential_term",
                                f"V is missing the {label}: {fmt(eq.display(part))}.", expected)]
        missing = flipped_potential_term(V_user, V, self.model, self.points, factor=1)
        if missing is not None:
            labels, term = missing
            return [Finding("V", "wrong", "potential_term",
                            f"V is missing the term {fmt(eq.display(term))} of the "
                            f"{' and the '.join(labels)}.", expected)]
        difference = eq.display(V_user - V)
        return [Finding("V", "wrong", "potential_term",
                        f"V differs from ours by {fmt(difference)} (not a constant).", expected)]

    # D ---------------------------------------------------------------------------------

    def dissipation(self, D_user: sp.Expr) -> list[Finding]:
        D = self.eom.dissipation
        unknown = self._unknown_names("D", "D")
        if unknown:
            return unknown
        if eq.identical(D_user, D, self.points):
            return [Finding("D", "correct", None, "D matches.", None)]
        difference = eq.display(D_user - D)
        return [Finding("D", "wrong", "dissipation_term",
                        f"the dissipation function differs from ours by {fmt(difference)}; "
                        "D = sum 1/2 c (rate)^2.", fmt(D))]

    # Q ---------------------------------------------------------------------------------

    def generalized_force(self, name: str, Q_user: sp.Expr) -> list[Finding]:
        item = f"Q[{name}]"
        i = self.names.index(name)
        coordinate = self.model.coordinates[i]
        Q = self.eom.generalized_forces[i]
        expected = fmt(eq.display(Q))
        foreign = self.answer.foreign_symbols(item)
        if self._misspelled(foreign):
            return [Finding(item, "wrong", "unknown_name", self._misspelled(foreign, item),
                            expected, hint=self._misspelled(foreign, item))]
        if foreign:
            listed = ", ".join(sorted(map(str, foreign)))
            stripped = Q_user.xreplace({s: 0 for s in foreign})
            rest = (" Without them your Q matches ours." if eq.identical(stripped, Q, self.points)
                    else "")
            if not self.model.constraints:
                return [Finding(item, "wrong", "reaction_in_minimal_coordinates",
                                f"{item} contains {listed}, which the model does not have: ideal "
                                "reactions do no virtual work, so in minimal coordinates they "
                                f"vanish; leave them out.{rest}", expected)]
            return [Finding(item, "wrong", "generalized_force_wrong",
                            f"{item} contains {listed}, which the model does not have: constraint "
                            "reactions enter as multipliers (Phi_q^T lambda), not as generalized "
                            f"forces.{rest}", expected)]
        if eq.identical(Q_user, Q, self.points):
            return [Finding(item, "correct", None, f"{item} matches.", None)]
        V = self.eom.potential_energy
        V_user = self.answer.potential_energy if self.answer.potential_energy is not None else 0
        dV, dV_user = V.diff(coordinate.symbol), as_expression(V_user).diff(coordinate.symbol)
        if dV != 0 and eq.identical(Q_user - dV_user, Q - dV, self.points):
            return [Finding(item, "equivalent", "equation_equivalent",
                            f"{item} includes the conservative force -dV/d{name} = "
                            f"{fmt(eq.display(-dV))}; fine as long as V leaves it out.", expected)]
        contributions = [(c.load, c.expression) for c in self.eom.load_contributions
                         if c.coordinate == name]
        unit = generalized_force_unit(coordinate.unit)
        for load, part in contributions:
            if eq.identical(Q_user, Q - part, self.points):
                return [Finding(item, "wrong", "generalized_force_missing",
                                f"the load '{load}' is missing: it does virtual work "
                                f"dW = ({fmt(eq.display(part))}) d{name} on {name} ({unit}). "
                                "Did you do virtual work for every non-potential load?", expected)]
        if len(contributions) > 1 and eq.zero(Q_user, self.points):
            listed = "; ".join(f"'{load}': {fmt(eq.display(p))}" for load, p in contributions)
            return [Finding(item, "wrong", "generalized_force_missing",
                            f"every load is missing; by virtual work they give {listed}.",
                            expected)]
        suspect = self._mis_projected(Q_user, Q, contributions)
        if suspect is not None:
            load, part = suspect
            return [Finding(item, "wrong", "generalized_force_projection",
                            projection_message(self.model, load, part, name, Q_user - (Q - part)),
                            expected)]
        difference = eq.display(Q_user - Q)
        if not contributions:
            message = (f"no load does virtual work on {name}, so {item} = 0 (potential forces "
                       f"belong in V); yours minus ours is {fmt(difference)}.")
        else:
            message = f"{item} differs from ours by {fmt(difference)}."
        return [Finding(item, "wrong", "generalized_force_wrong", message, expected)]

    def _mis_projected(self, Q_user, Q, contributions):
        """The load whose contribution the user replaced by something else (same magnitudes)."""
        if len(contributions) == 1:
            return contributions[0]
        parameters = {p.symbol for p in self.model.parameters}
        for load, part in contributions:
            yours = as_expression(Q_user - (Q - part))
            if eq.zero(yours, self.points):
                continue
            if (yours.free_symbols & parameters) == (part.free_symbols & parameters):
                return load, part
        return None

    # multipliers -----------------------------------------------------------------------

    def multipliers(self) -> list[Finding]:
        m = len(self.model.constraints)
        count = self.answer.multiplier_count
        if count is None:
            count = len(self.answer.multiplier_names or ())
        expected = ", ".join(str(s) for s in self.eom.multipliers) or "none"
        if count == m:
            return [Finding("multipliers", "correct", None,
                            f"{m} multiplier(s), one per constraint.", None)]
        listed = ", ".join(self.eom.constraint_names) or "none"
        return [Finding("multipliers", "wrong", "multiplier_count",
                        f"{count} multiplier(s) for {m} constraint(s) ({listed}). Is there one "
                        "lambda per constraint? Add exactly one for each constraint equation.",
                        expected)]

    # units -----------------------------------------------------------------------------

    def units(self) -> list[Finding]:
        answer = self.answer
        items: list[tuple[str, sp.Expr, str | None, str]] = []
        if answer.kinetic_energy is not None:
            items.append(("T", answer.kinetic_energy, "J", "an energy"))
        if answer.potential_energy is not None:
            items.append(("V", answer.potential_energy, "J", "an energy"))
        if answer.dissipation is not None:
            items.append(("D", answer.dissipation, "W", "a power"))
        if answer.lagrangian is not None:
            items.append(("L", answer.lagrangian, "J", "an energy"))
        for name, value in answer.generalized_forces:
            unit = generalized_force_unit(self.model.coordinate(name).unit)
            items.append((f"Q[{name}]", value, unit, f"energy per unit of {name}"))
        for name, value in answer.equations:
            items.append((f"equation[{name}]", value, None, ""))
        unknown = {s: None for _, symbols in answer.foreign for s in symbols}
        # A number standing for a measured value (9.81) carries no unit to judge; in a robot
        # read from URDF every number is one (its masses and lengths are SI by the format).
        robot = self.model.kinematic_tree is not None
        items = [item for item in items
                 if not (_measured(item[1]) or robot and _numbers(item[1]))]
        issues = answer_unit_issues(self.model, items, unknown)
        return [Finding(issue.item, "wrong", "units_mismatch", issue.message, None)
                for issue in issues]

    def _unknown_names(self, item: str, label: str) -> list[Finding]:
        foreign = self.answer.foreign_symbols(item)
        if not foreign:
            return []
        listed = ", ".join(sorted(map(str, foreign)))
        said = self._misspelled(foreign, label) or \
            f"{label} uses {listed}, which the model does not declare."
        ours = self.eom.kinetic_energy if item == "T" else \
            self.eom.potential_energy if item == "V" else self.eom.dissipation
        return [Finding(item, "wrong", "unknown_name", said, fmt(ours), hint=said)]

    def _misspelled(self, foreign, label: str | None = None) -> str:
        """'V uses L1, ...; did you mean l1?' when an undeclared name is close to a declared one."""
        return misspelled(label, map(str, foreign), answer_names(self.model))


def _measured(expr: sp.Expr) -> bool:
    """Contains a number that looks like a measured value (9.81, 0.35, 50), not a plain
    factor such as 1/2, 2 or 1/12 that derivations write anyway."""
    for number in expr.atoms(sp.Rational):
        p, q = abs(number.p), number.q
        if p > 12 or q > 12:
            return True
    return bool(expr.atoms(sp.Float))


def _numbers(expr: sp.Expr) -> bool:
    """Contains a number other than 1 and -1."""
    return bool(expr.atoms(sp.Rational, sp.Float) - {sp.S.One, sp.S.NegativeOne})



__all__ = ["CODES", "CheckReport", "Finding", "check_answer", "kinetic_parts", "potential_parts"]
