"""The equations of motion of a hand derivation, judged item by item (module 7, section 07).

Each equation[q] is compared with ours up to a factor (even a state-dependent one, shown so the
user sees where it vanishes), then as a set (the same accelerations), then diagnosed: the
small-angle form, a load left out or projected wrongly, or the differing term.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import sympy as sp

from ..model.expressions import format_expression as fmt
from ..model.units import generalized_force_unit
from . import equivalence as eq
from .diagnose_terms import (
    about_zero,
    difference_message,
    linearized,
    potential_source,
    projection_message,
    scaled_phrase,
    traced_load,
)

if TYPE_CHECKING:
    from .finding import Finding


class EquationDiagnoses:
    """Mixin of diagnose's _Checker (its eom, model, answer, points, names, _misspelled);
    ``Finding`` is the checker's finding type (a class attribute: this room sits below
    diagnose)."""

    def equations(self) -> list[Finding]:
        eom, model = self.eom, self.model
        ours = list(eom.equations)
        given = dict(self.answer.equations)
        multipliers = list(eom.multipliers)
        foreign = set().union(*(self.answer.foreign_symbols(f"equation[{n}]") for n in given)) \
            if given else set()
        findings: list[Finding] = []
        if not model.constraints and foreign:
            for name, value in given.items():
                item = f"equation[{name}]"
                extra = self.answer.foreign_symbols(item)
                if not extra:
                    continue
                i = self.names.index(name)
                if self._misspelled(extra):  # a typo of a declared name, not a reaction
                    findings.append(self.Finding(item, "wrong", "equation_wrong",
                                            self._misspelled(extra, "the equation"),
                                            self._expected(i)))
                    continue
                stripped = value.xreplace({s: 0 for s in extra})
                rest = (" Without them the equation matches ours."
                        if self._multiple(stripped, ours[i]) is not None else "")
                listed = ", ".join(sorted(map(str, extra)))
                findings.append(self.Finding(
                    item, "wrong", "reaction_in_minimal_coordinates",
                    f"the equation contains {listed}, which the model does not have: do ideal "
                    "reactions do any virtual work? In minimal coordinates they vanish; leave "
                    f"them out.{rest}", self._expected(i)))
            done = {f.item for f in findings}
            given = {n: v for n, v in given.items() if f"equation[{n}]" not in done}
        user_multipliers = sorted(
            {s for v in given.values() for s in v.free_symbols if s in set(multipliers)} | foreign,
            key=str) if model.constraints else []
        # Only a full set of equations shows how many multipliers the user has.
        if (model.constraints and len(given) == len(ours)
                and len(user_multipliers) != len(multipliers)):
            findings.append(self.Finding(
                "multipliers", "wrong", "multiplier_count",
                f"your equations use {len(user_multipliers)} multiplier(s) "
                f"({', '.join(map(str, user_multipliers)) or 'none'}) for "
                f"{len(multipliers)} constraint(s) ({', '.join(eom.constraint_names)}). "
                "Is there one lambda per constraint?",
                ", ".join(map(str, multipliers))))
        # The user's own multiplier names (a tension T_rod) stand for ours, in order.
        renaming: dict[sp.Symbol, sp.Symbol] = {}
        if model.constraints and len(user_multipliers) == len(multipliers):
            free = [s for s in multipliers if s not in user_multipliers]
            renaming = dict(zip([s for s in user_multipliers if s not in multipliers], free,
                                strict=True))
        set_equivalent = False
        if given and len(given) == len(ours) and (not model.constraints
                                                   or len(user_multipliers) == len(multipliers)):
            set_equivalent = self._same_motion([given[n] for n in self.names], user_multipliers)
        for name, value in given.items():
            i = self.names.index(name)
            item = f"equation[{name}]"
            mapped = value.xreplace(renaming)
            factor = self._multiple(mapped, ours[i])
            if factor is not None and factor == 1:
                findings.append(self.Finding(item, "correct", None, "the equation matches ours.", None))
            elif factor is not None:
                findings.append(self.Finding(
                    item, "equivalent", "equation_equivalent",
                    f"your equation is ours multiplied by {fmt(factor)}: equivalent.",
                    self._expected(i)))
            elif set_equivalent:
                findings.append(self.Finding(
                    item, "equivalent", "equation_equivalent",
                    "your equations are an invertible combination of ours: they give the same "
                    "accelerations.", self._expected(i)))
            else:
                findings.append(self._wrong_equation(item, i, mapped, ours[i]))
        return findings

    def _expected(self, i: int) -> str:
        eom = self.eom
        lhs = (eom.mass_matrix * eom.acceleration_symbols)[i]
        if eom.multipliers.shape[0]:
            lhs += (eom.constraint_jacobian.T * eom.multipliers)[i]
        return f"{fmt(eq.display(lhs))} = {fmt(eq.display(eom.forcing[i]))}"

    def _multiple(self, user: sp.Expr, ours: sp.Expr) -> sp.Expr | None:
        """c when user == c * ours (a rescaling; c may depend on the state, like cos(theta),
        and is then shown so the user sees where it vanishes), else None."""
        if eq.identical(user, ours, self.points):
            return sp.S.One
        accelerations = [a for a in self.model.q_ddot if ours.has(a)]
        for a in accelerations:
            c_ours = ours.diff(a)
            if eq.zero(c_ours, self.points):
                continue
            ratio = user.diff(a) / c_ours
            if eq.zero(ratio, self.points):
                return None
            if eq.identical(user, ratio * ours, self.points):
                if eq.constant_in_state(ratio, self.points):
                    return eq.display(sp.cancel(ratio)) if eq.is_small(ratio) else ratio
                return eq.display(ratio)
            return None
        return None

    def _wrong_equation(self, item: str, i: int, user: sp.Expr, ours: sp.Expr) -> Finding:
        """The small-angle form, a load left out or projected wrongly, or the differing term."""
        name, expected = self.names[i], self._expected(i)
        linear = linearized(ours, self.model)
        factor = self._multiple(user, linear) if linear is not None else None
        if factor is not None:
            about = about_zero(self.model, ours)
            angle = next((c.name for c in self.model.coordinates
                          if c.is_angle and ours.has(c.symbol)), None)
            example = (f" (sin({angle}) where the small-angle form has {angle})" if angle
                       else "")
            return self.Finding(item, "wrong", "equation_linearized",
                           f"your equation is the small-angle (linearized) form of ours about "
                           f"{about}: correct near {about}, but the equation of motion keeps "
                           f"its full nonlinear terms{example}. Give it under [linearized] to "
                           "have it checked as a linearization.", expected)
        contributions = [(c.load, c.expression) for c in self.eom.load_contributions
                         if c.coordinate == name]
        traced = traced_load(user, ours, contributions, self.model, self.points)
        if traced is not None:
            unit = generalized_force_unit(self.model.coordinates[i].unit)
            scaled = scaled_phrase(traced[-1])
            if traced[0] == "missing":
                _, load, part, _ = traced
                return self.Finding(item, "wrong", "generalized_force_missing",
                               f"the equation{scaled} lacks the load '{load}': it does virtual "
                               f"work dW = ({fmt(eq.display(part))}) d{name}, so Q[{name}] = "
                               f"{fmt(eq.display(part))} ({unit}) belongs on the right-hand side. "
                               "Did you do virtual work for every non-potential load?", expected)
            if traced[0] == "all":
                listed = "; ".join(f"'{load}': {fmt(eq.display(p))}" for load, p in traced[1])
                return self.Finding(item, "wrong", "generalized_force_missing",
                               f"the equation{scaled} lacks every load; by virtual work they "
                               f"give Q[{name}] shares {listed} ({unit}).", expected)
            _, load, part, yours, _ = traced
            return self.Finding(item, "wrong", "generalized_force_projection",
                           f"in the equation{scaled}, " + projection_message(
                               self.model, load, part, name, yours), expected)
        message = difference_message(user, ours, self.model.q_ddot, list(self.eom.multipliers),
                                     self.points)
        source = potential_source(user, ours, self.model.coordinates[i].symbol, self.model,
                                  self.points)
        return self.Finding(item, "wrong", "equation_wrong",
                       message + (f" {source}" if source else ""), expected)

    def _same_motion(self, user: list[sp.Expr], user_multipliers: list[sp.Symbol]) -> bool:
        """Both sets give the same accelerations at random states (solved numerically)."""
        eom = self.eom
        unknowns = list(self.model.q_ddot) + list(user_multipliers)
        if not eq.is_linear(user, unknowns, self.points):
            return False
        A_u, b_u = eq.linear_system(user, unknowns)
        A, b = eq.linear_system(list(eom.equations), list(self.model.q_ddot) + list(eom.multipliers))
        m = len(eom.multipliers)
        if m:
            phi, gamma = eom.constraint_jacobian, eom.acceleration_rhs
            extra_rows = sp.Matrix(phi).row_join(sp.zeros(m, m))
            A_u = A_u.col_join(extra_rows)
            b_u = b_u.col_join(-sp.Matrix(gamma))
            A = A.col_join(extra_rows)
            b = b.col_join(-sp.Matrix(gamma))
        n = len(self.names)
        mine = eq.solve_at_points(A_u, b_u, self.points, count=n)
        theirs = eq.solve_at_points(A, b, self.points, count=n)
        usable = [(x, y) for x, y in zip(mine, theirs, strict=True) if y is not None]
        if not usable or any(x is None for x, _ in usable):
            return False
        return all(eq.close(a, b, self.points.tolerance)
                   for x, y in usable for a, b in zip(x, y, strict=True))
