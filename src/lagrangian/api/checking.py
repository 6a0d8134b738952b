"""System's methods for checking a hand derivation: check, check_many, crosscheck (and its
working), check_units; mixed into System (api/system.py)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

# The checkers are imported by the methods that run them: a System that only derives or
# simulates loads none of them (issue 38).
if TYPE_CHECKING:
    from ..check.classroom import ClassReport
    from ..check.crosscheck_report import CrosscheckReport
    from ..check.diagnose import CheckReport
    from ..check.free_body_steps import CrosscheckSteps
    from ..check.units import UnitsReport


class CheckMethods:
    """Mixed into System (api/system.py): ``self._model`` and ``equations_of_motion()``."""

    def check(self, answer, *, hints_only: bool = False) -> CheckReport:
        """Verdicts and diagnoses on a hand derivation: a path to ANSWER.toml, its tables as a
        dict ({"energy": {"V": "..."}}), or an Answer.

        Returns a CheckReport (``verdict``, ``findings`` with item, status, code, message,
        expected); items written differently but equivalently are accepted. Final answers
        (``[matrices]``, ``[frequencies]``, ``[mode_shapes]``, ``[linearized]``,
        ``[generalized_forces]`` with ``at``, ``[equilibria]``) are compared with this system's
        linearize, modes, generalized_forces_at and equilibria, numbers to their written precision.
        ``hints_only``: no expected expression or value, the module's diagnostic question instead.
        """
        from ..check.diagnose import check_answer
        from ..check.hints import hinted
        from ..model.answer import Answer, answer_from_mapping, read_answer

        if isinstance(answer, Mapping):
            answer = answer_from_mapping(answer, self._model, source="<answer>")
        elif not isinstance(answer, Answer):
            answer = read_answer(answer, self._model)
        report = check_answer(self.equations_of_motion(), answer)
        if answer.final_tables:
            # final answers (M, K, omega, shapes, ...) come from this system's own analysis
            report = replace(report, findings=report.findings
                             + tuple(_final_answers(self, answer)))
        return hinted(report) if hints_only else report

    def check_many(self, answers, *, hints_only: bool = False) -> ClassReport:
        """Grade a class: every answer file named in ``answers`` (paths, globs, folders of
        *.toml, or one such name) checked against this model, derived once. A file that cannot
        be read is a result with its error. Returns a ClassReport (``results``, ``counts``,
        ``records()`` one per file per item, ``csv_text()``; a table in a notebook)."""
        from ..check.classroom import check_class

        named = [answers] if isinstance(answers, str | Path) else list(answers)
        return check_class(self.equations_of_motion(), named, hints_only=hints_only,
                           exclude=[self._model.source] if self._model.source else [],
                           final=lambda answer: _final_answers(self, answer))

    def crosscheck(self) -> CrosscheckReport:
        """Newton-Euler (free bodies, reactions eliminated) vs Lagrange, coordinate by
        coordinate, with the reaction force on each body (N; moment about the centre, N m)."""
        from ..check.newton_euler import crosscheck

        return crosscheck(self.equations_of_motion())

    def crosscheck_steps(self) -> CrosscheckSteps:
        """The working of crosscheck: each body's free-body equations (m a_G = sum F + R,
        I alpha = sum M_G + M_R) and their projection onto dr/dq_i, coordinate by coordinate."""
        from ..check.free_body_steps import crosscheck_steps

        return crosscheck_steps(self.equations_of_motion())

    def check_units(self) -> UnitsReport:
        """Every dimensionally inconsistent term of the model (T, V: J; D: W; Q: J per unit of q)."""
        from ..check.units import check_model_units

        return check_model_units(self._model)


def _final_answers(system, answer) -> list:
    """The findings on an answer's final tables (check/final_answers.py, loaded by an answer
    that has them)."""
    from ..check.final_answers import check_final_answers

    return check_final_answers(system, answer)
