"""Grading a class: many answer files checked against one model, derived once.

Answer files are named by path, glob or folder (its ``*.toml``); a file that cannot be read or
checked becomes a result with its error, never a failure of the whole run. A folder or a glob
gives only regular files of its own: a symbolic link (a student's link to the answer key) or a
FIFO there is a refused row and is never opened, so no other file's content reaches a message.
"""

from __future__ import annotations

import csv
import glob
import html
import io
import os
import stat
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from ..derivation.equations import EquationsOfMotion
from ..errors import LagrangianError, one_line
from ..kinds import FindingStatus
from ..model.answer import parse_answer
from ..model.reader import file_kind, read_text_file
from .diagnose import CheckReport, check_answer
from .hints import hinted

# The columns of a class's records (JSON) and of its CSV, in order (a public contract).
RECORD_KEYS = ("file", "verdict", "item", "status", "code", "message", "expected", "error")
VERDICTS = ("correct", "incorrect", "unreadable")


@dataclass(frozen=True)
class AnswerResult:
    """One answer file's report, or the reason it could not be read or checked."""

    file: str
    report: CheckReport | None = None
    error: str | None = None

    @property
    def verdict(self) -> str:
        return "unreadable" if self.report is None else self.report.verdict

    @property
    def exit_status(self) -> int:
        """The status `check` gives this file alone: 0 correct, 1 incorrect, 2 unreadable."""
        return VERDICTS.index(self.verdict)


@dataclass(frozen=True)
class ClassReport:
    """The reports of a class's answer files, in the order they were named."""

    model: str
    results: tuple[AnswerResult, ...]
    hints_only: bool = False

    def __iter__(self) -> Iterator[AnswerResult]:
        return iter(self.results)

    def __len__(self) -> int:
        return len(self.results)

    @property
    def counts(self) -> dict[str, int]:
        """How many files are correct, incorrect and unreadable."""
        return {v: sum(r.verdict == v for r in self.results) for v in VERDICTS}

    @property
    def passed(self) -> bool:
        """Every answer file is correct."""
        return all(r.verdict == "correct" for r in self.results)

    @property
    def exit_status(self) -> int:
        """The worst file's status: 2 when one is unreadable, 1 when one is incorrect, else 0."""
        return max((r.exit_status for r in self.results), default=0)

    def records(self) -> list[dict[str, Any]]:
        """One record per file per item (RECORD_KEYS); an unreadable file is one record with
        its error, a file without items one record with item None."""
        rows = []
        for r in self.results:
            base = {"file": r.file, "verdict": r.verdict}
            findings = r.report.findings if r.report is not None else ()
            if not findings:
                rows.append({**base, "item": None, "status": None, "code": None,
                             "message": None, "expected": None, "error": r.error})
            rows += [{**base, "item": f.item, "status": f.status, "code": f.code,
                      "message": f.message, "expected": f.expected, "error": None}
                     for f in findings]
        return rows

    def csv_text(self) -> str:
        """The records as CSV (RECORD_KEYS as its header; empty cells for None). A file name
        that a spreadsheet would run as a formula (=, +, -, @) is quoted with a leading '."""
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(RECORD_KEYS)
        for record in self.records():
            row = ["" if record[k] is None else str(record[k]) for k in RECORD_KEYS]
            if row[0][:1] in ("=", "+", "-", "@", "\t", "\r"):
                row[0] = "'" + row[0]
            writer.writerow(row)
        return buffer.getvalue()

    def rows(self) -> list[dict[str, str]]:
        """One row per file: file, verdict, findings (the items not correct, by name)."""
        return [{"file": r.file, "verdict": r.verdict, "findings": summary(r)}
                for r in self.results]

    def __repr__(self) -> str:
        lines = [f"ClassReport({self.model!r}: " + ", ".join(
            f"{n} {v}" for v, n in self.counts.items()) + ")"]
        lines += [f"  {row['file']}: {row['verdict']}  {row['findings']}" for row in self.rows()]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        """The rows as an HTML table (every text escaped), for notebooks."""
        cells = "".join(
            f"<tr><td>{html.escape(row['file'])}</td><td>{row['verdict']}</td>"
            f"<td>{html.escape(row['findings'])}</td></tr>" for row in self.rows())
        counts = ", ".join(f"{n} {v}" for v, n in self.counts.items())
        return (f"<table><caption>{html.escape(self.model)}: {counts}</caption>"
                "<thead><tr><th>file</th><th>verdict</th><th>findings</th></tr></thead>"
                f"<tbody>{cells}</tbody></table>")


def summary(result: AnswerResult) -> str:
    """The findings of one file on one line: the items not correct with their codes, then how
    many are correct; or the file's error."""
    if result.report is None:
        return result.error or ""
    findings = result.report.findings
    if not findings:
        return "no items to check"
    named = [f"{f.item}: {f.code or f.status}" + (" (equivalent)" if f.status == FindingStatus.EQUIVALENT
                                                   else "")
             for f in findings if f.status != FindingStatus.CORRECT]
    right = sum(f.status == FindingStatus.CORRECT for f in findings)
    if right:
        named.append(f"{right} item(s) ok" if named else f"all {right} item(s) ok")
    return "; ".join(named)


def shown_name(path: str | Path) -> str:
    """A file name as every output shows it (the text table, the JSON, the CSV): its control
    characters escaped as Python writes them (a newline as ``\\n``, ESC as ``\\x1b``; the line
    separators and bidirectional overrides as ``\\u2028``...), so a name is one line and cannot
    forge rows; other characters, backslashes included, are kept (errors.one_line's rule)."""
    return one_line(str(path))


def answer_files(named: Iterable[str | Path], *, exclude: Iterable[str | Path] = ()
                 ) -> list[tuple[str, str | None]]:
    """(path, error) of every answer file named by a path, a glob or a folder (its *.toml,
    hidden files and ``exclude``, the model itself, left out), each once, in the order named.
    A name that gives no file is an entry with its error, and so is a file of a folder or a glob
    that is not a regular file inside it (a symbolic link, a FIFO): refused, never read; of
    several names (a class) each file named is held to that rule too, a lone one read as named."""
    return [(path, error) for path, error, _ in _entries(named, exclude)]


def _entries(named: Iterable[str | Path], exclude: Iterable[str | Path]
             ) -> list[tuple[str, str | None, bool]]:
    """answer_files' entries, each with whether it was found (in a folder, by a glob) rather
    than named: a found file is read without following a link, so none can be swapped in."""
    excluded = {Path(p).resolve() for p in exclude if Path(p).exists()}
    entries: list[tuple[str, str | None, bool]] = []
    seen: set[Path] = set()
    named = list(named)
    # several names are a class, and the shell's `class/*.toml` names a folder's files one by
    # one: each is held to the folder's rule (a student's link to the key graded 'correct')
    strict = len(named) > 1

    def add(path: Path, found: bool) -> None:
        refusal = _refusal(path) if found else None
        if refusal:
            entries.append((str(path), f"{shown_name(path)}: {refusal}", found))
            return
        key = _resolved(path)
        if key is None:
            entries.append((str(path), f"{shown_name(path)}: a symbolic link that leads nowhere "
                                       "(a loop): not read", found))
            return
        if key not in seen and key not in excluded:
            seen.add(key)
            entries.append((str(path), None, found))

    for name in named:
        text = str(name)
        path = Path(text)
        if path.is_dir() and not (strict and path.is_symlink()):
            found = sorted(p for p in path.glob("*.toml") if not p.name.startswith("."))
            kept = [p for p in found if _resolved(p) not in excluded and not _directory(p)]
            if not kept:
                entries.append((text, f"{shown_name(text)}: no answer files (*.toml) in this "
                                      "folder", False))
            for p in kept:
                add(p, True)
        elif path.exists() or path.is_symlink():
            add(path, strict)
        elif glob.has_magic(text):
            found = sorted(Path(p) for p in glob.glob(text) if not _directory(Path(p)))
            if not found:
                entries.append((text, f"{shown_name(text)}: no file matches this pattern", False))
            for p in found:
                add(p, True)
        else:
            entries.append((text, f"{shown_name(text)}: no such file", False))
    return entries


def _resolved(path: Path) -> Path | None:
    """The file's real place, or None where its links loop (resolving raises)."""
    try:
        return path.resolve()
    except (RuntimeError, OSError):
        return None


def _directory(path: Path) -> bool:
    """A real directory (not a link to one): never an answer file, left out without a word."""
    return not path.is_symlink() and path.is_dir()


def _refusal(path: Path) -> str | None:
    """Why a file found in a folder is not graded, judged without opening it (os.lstat), or
    None for a regular file whose real place is the folder itself."""
    try:
        mode = os.lstat(path).st_mode
    except OSError as exc:
        return f"cannot read the file ({exc.strerror or exc})"
    if stat.S_ISLNK(mode):
        return ("not a regular file (a symbolic link): not read; only the folder's own files "
                "are graded")
    if not stat.S_ISREG(mode):
        return f"not a regular file ({file_kind(mode)}): not read"
    if _resolved(path) is None or path.resolve().parent != path.parent.resolve():
        return "not inside its folder: not read"
    return None


def check_class(eom: EquationsOfMotion, named: Iterable[str | Path], *,
                hints_only: bool = False, exclude: Iterable[str | Path] = (),
                final: Callable | None = None) -> ClassReport:
    """Check every answer file named (paths, globs, folders) against ``eom``, derived once.
    ``final(answer)``: the findings on its final answers (M, K, omega, ...; System.check's)."""
    results = []
    for path, error, found in _entries(named, exclude):
        results.append(AnswerResult(shown_name(path), error=error) if error else
                       check_file(eom, path, hints_only=hints_only, final=final,
                                  follow_symlinks=not found))
    return ClassReport(eom.model.name, tuple(results), hints_only)


def check_file(eom: EquationsOfMotion, path: str | Path, *, hints_only: bool = False,
               final: Callable | None = None, follow_symlinks: bool = True) -> AnswerResult:
    """One answer file's result; an error reading or checking it is kept, never raised.
    ``follow_symlinks=False``: a symbolic link is refused, not read."""
    name = shown_name(path)
    try:
        text = read_text_file(path, follow_symlinks=follow_symlinks)
        answer = parse_answer(text, eom.model, source=str(path))
        report = check_answer(eom, answer)
        if final is not None and answer.final_tables:
            report = replace(report, findings=report.findings + tuple(final(answer)))
    except LagrangianError as exc:
        return AnswerResult(name, error=one_line(str(exc)))
    except (RecursionError, MemoryError):
        return AnswerResult(name, error=f"{name}: the answer is too large or too deeply "
                                        "nested to check")
    except Exception as exc:  # noqa: BLE001 - one student's file never stops a class's grading
        return AnswerResult(name, error=one_line(f"{name}: could not be checked "
                                                 f"({type(exc).__name__}: {exc})"))
    return AnswerResult(name, hinted(report) if hints_only else report)


__all__ = ["RECORD_KEYS", "AnswerResult", "ClassReport", "answer_files", "check_class",
           "check_file", "shown_name", "summary"]
