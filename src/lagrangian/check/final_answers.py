"""Verdicts on the final answers of an answer file: M, C, K, natural frequencies and damping
ratios, mode shapes, linearized equations, generalized forces at a configuration, equilibria,
statics loads.

Ours come from the project's analysis (linearize, modes, generalized_forces_at, equilibria),
through the System's public methods. A decimal number the student wrote is accepted when our
value rounds to it: within half a unit in its last written digit (a relative slack of 1e-9 for
rounding); whole numbers and constants (2, pi) are exact. Each finding says the precision used.
"""

from __future__ import annotations

import math
from typing import Protocol

import mpmath
import numpy as np
import sympy as sp

from ..errors import DerivationError, ModelError
from ..model.answer import Answer, answer_expression, answer_names
from ..model.expressions import format_expression as fmt
from . import equivalence as eq
from .conserved_answers import check_mechanics
from .final_at_rest import AtRest
from .final_linear import check_linearized, exact_linear
from .final_reading import (
    FREQUENCY_KINDS,
    SLACK,
    Entry,
    FinalAnswers,
    Written,
    agrees,
    read_final_answers,
)
from .final_statics import STATICS_CODES, check_statics
from .finding import Finding

FINAL_CODES = (
    "matrix_entry", "frequency_wrong", "frequency_count", "damping_ratio_wrong",
    "mode_shape_wrong", "linear_coefficient", "linear_offset", "not_linearized",
    "generalized_force_value", "equilibrium_wrong", "equilibrium_missing", *STATICS_CODES,
)
SHAPE_SLACK = 1e-6  # relative to the largest component: eigenvectors are computed numerically


class Analysis(Protocol):
    """What the checker asks of a system (lagrangian.System provides it)."""

    def equations_of_motion(self): ...
    def linearize(self, about=None, inputs=(), *, symbolic=False, steady=None): ...
    def modes(self, about=None, *, steady=None): ...
    def equilibria(self): ...
    def generalized_forces_at(self, configuration, parameters=None): ...
    def statics(self, configuration, solve_for, parameters=None): ...


def check_final_answers(system: Analysis, answer: Answer) -> list[Finding]:
    """Findings on every final answer of ``answer`` (none when it has none); a malformed
    table is a ModelError naming the file, the table and the field."""
    if not answer.final_tables:
        return []
    model = system.equations_of_motion().model
    names = answer_names(model)
    tables = dict(answer.final_tables)
    final = read_final_answers(tables, model, lambda value, field:
                               answer_expression(value, names, field, answer.source),
                               answer.source)
    return _FinalChecker(system, final, answer.source).run() + \
        check_mechanics(system, tables, answer.source)


class _FinalChecker:
    def __init__(self, system: Analysis, final: FinalAnswers, source: str):
        self.system = system
        self.final = final
        self.source = source
        self.model = system.equations_of_motion().model
        self.names = [c.name for c in self.model.coordinates]
        self.order = list(final.order)  # the student's order
        self.random = eq.random_points(self.model)
        self.valued = eq.random_points(self.model, model_values=True)
        self.about = dict(final.about) if final.about is not None else None
        self._equilibrium: dict[str, float] | None = None

    def run(self) -> list[Finding]:
        findings: list[Finding] = []
        final = self.final
        if final.matrices:
            findings += self.guarded("matrices", self.matrices)
        if final.frequencies or final.damping_ratios or final.mode_shapes:
            findings += self.guarded("frequencies", self.modes)
        if final.linearized:
            findings += self.guarded("linearized", lambda: check_linearized(self))
        if final.forces or final.equilibria:
            statics = AtRest(self.system, final)
            findings += statics.forces() + statics.equilibria()
        findings += check_statics(self.system, final, self.source)
        return findings

    def guarded(self, table: str, method) -> list[Finding]:
        """An `about` that is no equilibrium is the file's fault (exit 2); a model whose linear
        matrices cannot be formed here gets a note."""
        try:
            return method()
        except ModelError as error:
            field = error.field if error.field not in (None, "about") else (
                "linearized.about" if self.about is not None else table)
            raise ModelError(error.message, field=field, source=self.source) from None
        except DerivationError as error:
            return [Finding(table, "note", None, f"not checked: {error}", None)]

    # -- numbers and expressions -----------------------------------------------------------

    def same(self, entry: Entry, ours: sp.Expr, scale: float = 1.0, numeric: bool = False
             ) -> bool:
        """An entry equals ours: a number at the model's values to its written precision, an
        expression identically (measured numbers in it, or ``numeric`` ours: at the model's
        values, to the precision of its numbers)."""
        if entry.written is not None:
            return agrees(entry.written, self.value(ours), scale)
        if entry.relative is None and not numeric:
            return eq.identical(entry.value, ours, self.random)
        rows = self.valued.evaluate([entry.value, ours])
        tolerance = (entry.relative or 0.0) + SLACK
        return all(not mpmath.isnan(a.real) and abs(a - b) <= tolerance * max(abs(a), abs(b))
                   + SLACK * scale for a, b in rows)

    def value(self, ours: sp.Expr) -> float:
        """Ours at the model's parameter values (a constant of the state)."""
        result = self.valued.evaluate([ours])[0][0]
        return float(result.real)

    def equilibrium(self) -> dict[str, float]:
        """The equilibrium of [linearized] about, else the one `modes` takes by default."""
        if self._equilibrium is None:
            if self.about is not None:
                self._equilibrium = dict(self.system.linearize(self.about).equilibrium)
            else:
                self._equilibrium = dict(self.system.modes().equilibrium)
        return self._equilibrium

    def symbolic(self):
        """Exact M, C, K about the equilibrium (None where only numbers can be had: constraints,
        many coordinates, an equilibrium that moves with the parameters)."""
        equilibrium = self.equilibrium()  # not an equilibrium: refused (ModelError)
        return exact_linear(self, equilibrium)

    # -- matrices --------------------------------------------------------------------------

    def matrices(self) -> list[Finding]:
        linear = self.symbolic()
        where = ", ".join(f"{k} = {v:.6g}" for k, v in self.equilibrium().items())
        if linear is None:
            numeric = self.system.linearize(self.about)
            if numeric.coordinates != numeric.user_coordinates:
                return [Finding(name, "note", None, "not checked: the model is constrained, its "
                                "linear matrices are in independent coordinates", None)
                        for name, _ in self.final.matrices]
            ours = {"M": sp.Matrix(numeric.M), "C": sp.Matrix(numeric.C), "K": sp.Matrix(numeric.K)}
        else:
            ours = {"M": linear.M, "C": linear.C, "K": linear.K}
        index = [self.names.index(n) for n in self.order]
        findings = []
        for name, rows in self.final.matrices:
            matrix = ours[name]
            mine = sp.Matrix([[matrix[i, j] for j in index] for i in index])
            scale = max([abs(self.value(e)) for e in mine] + [1e-300])
            wrong = [(i, j) for i, row in enumerate(rows) for j, entry in enumerate(row)
                     if not self.same(entry, mine[i, j], scale, numeric=linear is None)]
            expected = "[" + ", ".join("[" + ", ".join(fmt(eq.display(e)) for e in mine.row(i))
                                       + "]" for i in range(mine.rows)) + "]"
            order = f"rows and columns {', '.join(self.order)}, about {where}"
            if not wrong:
                findings.append(Finding(name, "correct", None,
                                        f"{name} matches ours ({order}).", None))
                continue
            named = "; ".join(
                f"{name}[{i + 1},{j + 1}] (row {self.order[i]}, column {self.order[j]}) is "
                f"{_shown(rows[i][j])} in yours, ours is {fmt(eq.display(mine[i, j]))}"
                + ("" if rows[i][j].written is None else f" = {self.value(mine[i, j]):.6g}")
                for i, j in wrong[:4])
            numbers = any(rows[i][j].written is not None or rows[i][j].relative is not None
                          for i, j in wrong)
            note = ("; numbers compared at the model's parameter values, to the precision you "
                    "wrote" if numbers else "")
            findings.append(Finding(name, "wrong", "matrix_entry", f"{named} ({order}{note}).",
                                    expected))
        return findings

    # -- frequencies, damping ratios, mode shapes -------------------------------------------

    def modes(self) -> list[Finding]:
        analysis = self.system.modes(self.about)
        modes = list(analysis.modes)
        oscillating = [m for m in modes if m.frequency > 0]
        final, findings = self.final, []
        listed = len(final.frequencies or final.mode_shapes or final.damping_ratios)
        chosen = modes if listed == len(modes) or listed != len(oscillating) else oscillating
        if final.frequencies:
            findings += self.frequencies(chosen, oscillating)
        for i, (written, mode) in enumerate(zip(final.damping_ratios, chosen, strict=False), 1):
            zeta = mode.damping_ratio or 0.0
            ok = agrees(written, zeta)
            findings.append(Finding(
                f"zeta[{i}]", "correct" if ok else "wrong", None if ok else "damping_ratio_wrong",
                f"zeta[{i}] = {written.text} {'matches' if ok else 'differs from'} ours, "
                f"{zeta:.6g}, compared {written.precision}." + ("" if ok else
                " zeta = c / (2 sqrt(k m)) for one coordinate; c / c_critical in general."),
                None if ok else f"{zeta:.6g}"))
        for i, (shape, mode) in enumerate(zip(final.mode_shapes, chosen, strict=False), 1):
            findings.append(self.shape(i, shape, mode, modes))
        return findings

    def frequencies(self, chosen, oscillating) -> list[Finding]:
        kind = self.final.frequency_kind or "omega"
        unit, what = FREQUENCY_KINDS[kind]
        convert = {"omega": lambda w: w, "f": lambda w: w / (2 * math.pi),
                   "period": lambda w: 2 * math.pi / w if w > 0 else math.inf}[kind]
        by_value = sorted((convert(m.frequency), m) for m in chosen)
        ours = [v for v, _ in by_value]
        listed = self.final.frequencies
        findings = []
        if len(listed) != len(ours):
            findings.append(Finding(
                "frequencies", "wrong", "frequency_count",
                f"you list {len(listed)} {what}(s); the model has {len(ours)} modes, "
                f"{len(oscillating)} of them oscillating (one natural frequency per degree of "
                "freedom).", ", ".join(f"{v:.6g} {unit}" for v in ours)))
        pairs = sorted(range(len(listed)), key=lambda k: listed[k].value)
        for rank, k in enumerate(pairs):
            written = listed[k]
            item = f"{kind}[{k + 1}]"
            if len(listed) == len(ours):
                true, mode = by_value[rank]
            else:  # the nearest of ours
                true, mode = min(by_value, key=lambda vm: abs(vm[0] - written.value),
                                 default=(math.nan, None))
            if agrees(written, true):
                findings.append(Finding(item, "correct", None,
                                        f"{item} = {written.text} matches ours, {true:.6g} "
                                        f"{unit}, compared {written.precision}.", None))
                continue
            slip = self.damped_hint(written, mode, convert) + \
                _frequency_hint(written.value, true, kind)
            findings.append(Finding(
                item, "wrong", "frequency_wrong",
                f"{item} = {written.text}: ours is {true:.6g} {unit}, which does not round to "
                f"yours (compared {written.precision}).{slip}",
                f"{true:.6g} {unit}", hint=_slip_hint(written.value, true, kind, slip)))
        return findings

    @staticmethod
    def damped_hint(written: Written, mode, convert) -> str:
        """Yours is the damped frequency omega_d = omega_n sqrt(1 - zeta^2) (or its f, period)."""
        zeta = (mode.damping_ratio or 0.0) if mode is not None else 0.0
        if not 0 < zeta < 1:
            return ""
        damped = convert(mode.frequency * math.sqrt(1 - zeta**2))
        if not agrees(written, damped):
            return ""
        return (f" Yours is the damped one, omega_d = omega_n sqrt(1 - zeta^2) ({damped:.6g}); "
                "the table asks for the natural frequency omega_n (undamped).")

    def shape(self, i: int, shape: tuple[Written, ...], mode, modes) -> Finding:
        """Equal up to a (complex) factor: the best fit of ours, entry by entry within the
        precision written; a repeated frequency's shape may be any vector of its modes' span."""
        index = [self.names.index(n) for n in self.order]
        group = [m for m in modes if abs(m.frequency - mode.frequency)
                 <= 1e-6 * max(mode.frequency, 1e-12)]
        basis = np.array([[m.complex_shape[k] for k in index] for m in group]).T
        v = np.array([w.value for w in shape], dtype=complex)
        largest = max(abs(v))
        tolerance = np.array([(w.step or 0) / 2 + SHAPE_SLACK * largest for w in shape])
        # weighted by each entry's tolerance, so exact entries (1) pin the scale
        alpha = np.linalg.lstsq(basis / tolerance[:, None], v / tolerance, rcond=None)[0]
        fitted = basis @ alpha
        ok = bool(np.all(np.abs(fitted - v) <= tolerance))
        ours = [mode.shape[n] for n in self.order]
        text = "(" + ", ".join(w.text for w in shape) + ")"
        expected = "(" + ", ".join(f"{x:.4g}" for x in ours) + ")"
        precision = ("to the precision you wrote" if any(w.step for w in shape)
                     else "at the model's parameter values, as written in its parameters"
                     if any(w.in_parameters for w in shape)
                     else "exactly (whole numbers and constants)")
        if ok:
            return Finding(f"shape[{i}]", "correct", None,
                           f"shape[{i}] = {text} is ours, {expected}, up to scale and sign, "
                           f"compared {precision}.", None)
        return Finding(f"shape[{i}]", "wrong", "mode_shape_wrong",
                       f"shape[{i}] = {text} is not ours ({self.order and ', '.join(self.order)}"
                       f" = {expected} at {mode.frequency:.6g} rad/s) at any scale or sign, "
                       f"compared {precision}. Does it solve (K - omega^2 M) phi = 0?", expected)


def _shown(entry: Entry) -> str:
    """An entry as written when a number, else as we read it (never raw text: one line)."""
    return entry.written.text if entry.written is not None else fmt(entry.value)


def _slip_hint(yours: float, ours: float, kind: str, slip: str) -> str | None:
    """--hints-only's words for a frequency slip: which one, never the value."""
    if "2 pi" in slip:
        return ("Is it in the units asked (omega in rad/s, f in Hz)? omega = 2 pi f: rad/s and "
                "Hz differ by 2 pi.")
    if "squared" in slip:
        return "Is it omega or omega^2? The eigenvalues of det(K - omega^2 M) = 0 are omega^2."
    if "damped" in slip:
        return "Is it the natural (undamped) frequency omega_n, or the damped one omega_d?"
    if yours > ours:
        return ("Yours is too high: does ω² solve det(K − ω² M) = 0 with every mass and "
                "inertia in M?")
    return "Yours is too low: does ω² solve det(K − ω² M) = 0 with every stiffness in K?"


def _frequency_hint(yours: float, ours: float, kind: str) -> str:
    """A ratio a known slip explains: Hz for rad/s (2 pi), omega^2 for omega."""
    if ours <= 0 or yours <= 0:
        return ""
    ratio = yours / ours
    if abs(ratio - 2 * math.pi) < 0.02 * 2 * math.pi or abs(ratio * 2 * math.pi - 1) < 0.02:
        return " It is off by a factor 2 pi: rad/s and Hz mixed up (omega = 2 pi f)?"
    if kind == "omega" and abs(yours - ours**2) <= 0.02 * ours**2 and abs(ours - 1) > 0.05:
        return " It is ours squared: omega^2 = k/m, so omega = sqrt(k/m)?"
    return ""


__all__ = ["FINAL_CODES", "check_final_answers"]
