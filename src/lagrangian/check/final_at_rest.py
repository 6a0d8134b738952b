"""Final answers at rest: a generalized force at a configuration (``[generalized_forces]`` with
``at``; N for a length, N m for an angle) and the equilibrium positions (``[equilibria]``),
compared with the System's generalized_forces_at and equilibria to the precision written.
"""

from __future__ import annotations

import math

import sympy as sp

from ..model.units import generalized_force_unit, is_angle_unit
from .final_reading import FinalAnswers, Written, agrees
from .finding import Finding


class AtRest:
    """Findings on Q at a configuration (items Q_theta) and on equilibria (equilibrium.theta[1])."""

    def __init__(self, system, final: FinalAnswers):
        self.system = system
        self.final = final
        self.model = system.equations_of_motion().model
        self.names = [c.name for c in self.model.coordinates]

    def forces(self) -> list[Finding]:
        if not self.final.forces:
            return []
        at = dict(self.final.forces_at or ())
        rest = {c.velocity.name: 0.0 for c in self.model.coordinates}
        report = self.system.generalized_forces_at({**at, **rest})
        where = ", ".join(f"{k} = {_angle(self.model, k, v)}" for k, v in
                          report.configuration.items() if k in self.names)
        findings = []
        for name, written in self.final.forces:
            item, unit = f"Q_{name}", generalized_force_unit(self.model.coordinate(name).unit)
            true = report.generalized_forces[name]
            parts = [(load, value) for load, coordinate, value in report.contributions
                     if coordinate == name]
            scale = max([abs(v) for _, v in parts] + [1.0])
            if agrees(written, true, scale):
                findings.append(Finding(item, "correct", None,
                                        f"{item} = {written.text} matches ours, {true:.6g} "
                                        f"{unit} at {where}, compared {written.precision}.",
                                        None))
                continue
            loads = ", ".join(f"{load!r}: {value:.6g} {unit}" for load, value in parts)
            findings.append(Finding(
                item, "wrong", "generalized_force_value",
                f"{item} = {written.text} at {where}: ours is {true:.6g} {unit}"
                + (f" (each load's part: {loads})" if loads else "")
                + f", compared {written.precision}.{self.force_hint(name, written, true, report)}"
                " Did I do virtual work for every non-potential load, dW = F . dr with dr = "
                "dr/dq dq?", f"{true:.6g} {unit}"))
        return findings

    def force_hint(self, name: str, written: Written, true: float, report) -> str:
        """A slip the value shows: the sign, a factor 2, or sin for cos in the projection."""
        if true != 0 and agrees(written, -true):
            return " Yours has the opposite sign."
        for factor, words in ((2.0, "twice ours"), (0.5, "half of ours")):
            if true != 0 and agrees(written, factor * true):
                return f" Yours is {words}: the lever arm?"
        values = {p.symbol: p.value for p in self.model.parameters if p.value is not None}
        values.update({c.symbol: report.configuration[c.name] for c in self.model.coordinates})
        values.update(dict.fromkeys(self.model.q_dot, 0.0))
        x = sp.Dummy("x")
        swapped = sum((c.expression.replace(sp.sin, sp.Lambda(x, sp.Function("_c")(x)))
                       .replace(sp.cos, sp.Lambda(x, sp.sin(x))).replace(
                           sp.Function("_c"), sp.Lambda(x, sp.cos(x)))
                       for c in self.system.equations_of_motion().load_contributions
                       if c.coordinate == name), sp.S.Zero)
        try:
            other = float(sp.sympify(swapped).xreplace(values))  # safe: a sympy expression
        except (TypeError, ValueError):
            return ""
        if agrees(written, other) or agrees(written, -other):
            return " It is ours with sin and cos exchanged: which component of dr does the " \
                   "force do work through?"
        return ""

    # -- equilibria ------------------------------------------------------------------------

    def equilibria(self) -> list[Finding]:
        if not self.final.equilibria:
            return []
        found = list(self.system.equilibria())
        listed = dict(self.final.equilibria)
        names = list(listed)
        count = len(next(iter(listed.values())))
        matched: set[int] = set()
        findings = []
        for k in range(count):
            point = {n: listed[n][k] for n in names}
            item = f"equilibrium.{names[0]}[{k + 1}]" if len(names) == 1 else f"equilibrium[{k + 1}]"
            text = ", ".join(f"{n} = {w.text}" for n, w in point.items())
            hits = [e for e, ours in enumerate(found) if all(
                n in ours.neutral or self.at_position(n, w, ours.coordinates[n])
                for n, w in point.items())]
            matched.update(hits)
            precision = "; ".join(sorted({w.precision for w in point.values()}))
            if hits:
                findings.append(Finding(item, "correct", None, f"{text} is an equilibrium, "
                                        f"compared {precision}.", None))
            else:
                findings.append(Finding(item, "wrong", "equilibrium_wrong",
                                        f"{text} is not an equilibrium, compared {precision}; "
                                        f"ours: {self.listing(found, names)}. Is dV/dq = Q there "
                                        "(no generalized force left at rest)?",
                                        self.listing(found, names)))
        missing = [e for e in range(len(found)) if e not in matched]
        if missing:
            findings.append(Finding(
                "equilibria", "wrong", "equilibrium_missing",
                f"you list {count} equilibrium position(s); the model has {len(found)}: "
                f"missing {self.listing([found[e] for e in missing], names)}.",
                self.listing(found, names)))
        return findings

    def at_position(self, name: str, written: Written, true: float) -> bool:
        """Angles agree modulo a full turn."""
        if is_angle_unit(self.model.coordinate(name).unit):
            turns = round((written.value - true) / (2 * math.pi))
            true += 2 * math.pi * turns
        return agrees(written, true, 1.0)

    def listing(self, found, names) -> str:
        return "; ".join(", ".join(f"{n} = {_angle(self.model, n, e.coordinates[n])}"
                                   for n in names) for e in found) or "none found"


def _angle(model, name: str, value: float) -> str:
    """A coordinate value, with its angle in degrees where it is one."""
    if is_angle_unit(model.coordinate(name).unit):
        return f"{value:.6g} rad ({math.degrees(value):.4g} deg)"
    unit = model.coordinate(name).unit or "m"
    return f"{value:.6g} {unit}"
