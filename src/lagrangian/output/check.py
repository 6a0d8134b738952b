"""Text and JSON of the checking reports: check (findings), crosscheck (Newton-Euler), units."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..check.classroom import RECORD_KEYS, ClassReport, summary
from ..check.crosscheck_report import CrosscheckReport
from ..check.diagnose import CheckReport
from ..check.units import UnitsReport
from ..errors import ModelError
from ..kinds import FindingStatus
from ..model.expressions import format_expression as fmt
from .files import atomic_write, check_output_path

_MARK = {FindingStatus.CORRECT: "ok", FindingStatus.EQUIVALENT: "equivalent",
         FindingStatus.WRONG: "WRONG", FindingStatus.NOTE: "note"}


def check_document(report: CheckReport) -> dict[str, Any]:
    """The `check --json` document (a public contract)."""
    return {
        "verdict": report.verdict,
        "findings": [
            {"item": f.item, "status": f.status, "code": f.code, "message": f.message,
             "expected": f.expected}
            for f in report.findings
        ],
    }


def check_text(report: CheckReport) -> str:
    lines = [f"Checking {report.answer} against {report.model}"]
    if not report.findings:
        lines.append("  (the answer has no items to check)")
    for f in report.findings:
        code = f" [{f.code}]" if f.code else ""
        lines.append(f"  {f.item}: {_MARK.get(f.status, f.status)}{code}")
        lines.append(f"      {f.message}")
        if f.expected is not None and f.status != FindingStatus.CORRECT:
            lines.append(f"      expected: {f.expected}")
    lines.append(f"verdict: {report.verdict}")
    return "\n".join(lines) + "\n"


# -- a class: many answer files against one model ----------------------------------------------


def class_document(report: ClassReport) -> dict[str, Any]:
    """The `check MODEL ANSWERS...` JSON document: counts and one record per file per item."""
    return {"model": report.model, "answers": len(report), "counts": report.counts,
            "hints_only": report.hints_only, "records": report.records()}


def class_text(report: ClassReport) -> str:
    """One row per answer file: file, verdict, the findings by item name (or the error)."""
    rows = report.rows()
    lines = [f"Checking {len(rows)} answer file(s) against {report.model}"
             + (" (hints only)" if report.hints_only else "")]
    width = max([len(row["file"]) for row in rows] + [4])
    for row, result in zip(rows, report.results, strict=True):
        findings = row["findings"] if result.report is not None else f"error: {summary(result)}"
        lines.append(f"  {row['file']:<{width}}  {row['verdict']:<10}  {findings}")
        if report.hints_only and result.report is not None:  # the question, once per finding
            lines += [f"      {f.item}: {f.message}" for f in result.report.findings
                      if f.status != FindingStatus.CORRECT]
    lines.append(", ".join(f"{n} {v}" for v, n in report.counts.items()))
    return "\n".join(lines) + "\n"


def check_class_csv_path(path: str | Path, *, inputs: tuple[Path, ...] = ()) -> Path:
    """The --csv path, checked before any work: writable, not a directory, not an input, and
    either new or a class CSV that check wrote before (its header is RECORD_KEYS)."""
    path = check_output_path(path, "csv", inputs=inputs)
    if path.is_symlink():
        raise ModelError(f"{path} is a symbolic link: refusing to write through it",
                         field="csv")
    if path.exists():
        try:
            with open(path, encoding="utf-8", errors="replace") as handle:
                first = handle.readline(400).strip()
        except OSError as exc:
            raise ModelError(f"cannot read {path}: {exc.strerror or exc}", field="csv") from None
        if first != ",".join(RECORD_KEYS):
            raise ModelError(f"{path} exists and is not a class table written by check: "
                             "refusing to overwrite it", field="csv")
    return path


def write_class_csv(report: ClassReport, path: str | Path, *, inputs: tuple[Path, ...] = ()
                    ) -> Path:
    """Write the class's records as CSV, atomically (a partial file never replaces a good one)."""
    path = check_class_csv_path(path, inputs=inputs)
    return atomic_write(path, report.csv_text(), protect=inputs)


def crosscheck_document(report: CrosscheckReport) -> dict[str, Any]:
    """The `crosscheck --json` document (a public contract)."""
    return {
        "agree": report.agree,
        "coordinates": {c.coordinate: {"agree": c.agree, "difference": c.difference}
                        for c in report.coordinates},
        # "joint" and "components" as first published; "body" names what the key holds (the
        # body the resultant acts on), "force" and "moment" label each component by its axis
        "reactions": [{"joint": r.joint, "components": [fmt(v) for v in r.components],
                       "body": r.joint, **_labelled(r), **_at_initial_state(r)}
                      for r in report.reactions],
    }


def _at_initial_state(reaction) -> dict[str, dict[str, dict[str, float]]]:
    """{"at_initial_state": {"force": {"x": N, ...}, "moment": {...}}} where it is known."""
    if reaction.at_initial_state is None:
        return {}
    groups: dict[str, dict[str, float]] = {}
    for label, value in zip(reaction.labels, reaction.at_initial_state, strict=True):
        kind, _, axis = label.partition("_")
        groups.setdefault({"R": "force", "M": "moment"}.get(kind, kind), {})[axis] = value
    return {"at_initial_state": groups}


# A reaction longer than this (characters) is printed by its value at the initial state.
READABLE_REACTION = 240


def _reaction_line(label: str, value, number: float | None) -> str:
    text = fmt(value)
    unit = "N m" if label.startswith("M") else "N"
    if number is not None and getattr(value, "is_Float", False):  # formed with numbers
        return f"      {label} = {number:.6g} {unit} at the initial state"
    if len(text) <= READABLE_REACTION or number is None:
        return f"      {label} = {text}"
    return (f"      {label} = {number:.6g} {unit} at the initial state (its expression, "
            f"{len(text)} characters, is in --json)")


def _labelled(reaction) -> dict[str, dict[str, str]]:
    """{"force": {"x": R_x, "y": R_y[, "z": R_z]}[, "moment": {"z": M_z}]} (N; N m about the
    centre of mass), from the report's labels R_x ... M_z."""
    groups: dict[str, dict[str, str]] = {}
    for label, value in zip(reaction.labels, reaction.components, strict=True):
        kind, _, axis = label.partition("_")
        groups.setdefault({"R": "force", "M": "moment"}.get(kind, kind), {})[axis] = fmt(value)
    return groups


def crosscheck_text(report: CrosscheckReport) -> str:
    lines = [f"Newton-Euler vs Lagrange: {report.model}"]
    for c in report.coordinates:
        state = "agree" if c.agree else f"DIFFER by {c.difference}"
        lines.append(f"  {c.coordinate}: {state}")
    if report.reactions:
        spatial = any("M_x" in r.labels for r in report.reactions)
        lines.append("reactions (resultant on each body; moment about its centre of mass):"
                     if not spatial else
                     "reactions (resultant on each body, moment about its centre of mass; a body "
                     "in space: at its joint, on it and the bodies it carries, moment about the "
                     "joint, world axes):")
        for r in report.reactions:
            lines.append(f"  {r.joint}:")
            numbers = r.at_initial_state or (None,) * len(r.labels)
            lines += [_reaction_line(label, value, number)
                      for label, value, number in zip(r.labels, r.components, numbers,
                                                      strict=True)]
    lines += [f"note: {note}" for note in report.notes]
    lines.append("agree" if report.agree else "disagree")
    return "\n".join(lines) + "\n"


def units_document(report: UnitsReport) -> dict[str, Any]:
    return {
        "consistent": report.consistent,
        "issues": [{"item": i.item, "term": i.term, "message": i.message} for i in report.issues],
        "unchecked_parameters": list(report.unchecked),
    }


def units_text(report: UnitsReport) -> str:
    lines = [f"Units of {report.model}"]
    lines += [f"  {issue.message}" for issue in report.issues]
    if report.unchecked:
        lines.append("note: parameters without a unit are not judged: "
                     + ", ".join(report.unchecked))
    lines.append("consistent" if report.consistent
                 else f"{len(report.issues)} inconsistent term(s)")
    return "\n".join(lines) + "\n"
