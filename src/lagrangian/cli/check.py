"""`lagrangian check MODEL ANSWER.toml` (or ANSWERS... of a class), `lagrangian crosscheck MODEL`,
`lagrangian units MODEL`.

check exits 0 when the answer is correct, 1 when it is not, 2 when a file cannot be read
(a class: the worst file's status; an unreadable file is a row with its error)
(crosscheck: 1 when the derivations disagree; units: 1 when a term is inconsistent).
SystemExit(1) rather than typer.Exit(1): the app runs with standalone_mode=False, where click
returns an Exit's code instead of raising it, and the status would be lost.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..errors import LagrangianError
from . import app
from .common import LOCK_HELP, SET_HELP, load_system, print_json

_MODEL = Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")]
_SET = Annotated[list[str], typer.Option("--set", help=SET_HELP)]
_LOCK = Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)]
_JSON = Annotated[bool, typer.Option("--json", help="Print JSON.")]


@app.command()
def check(
    model: _MODEL,
    answers: Annotated[list[str], typer.Argument(
        help="Your derivation, ANSWER.toml: tables energy (T, V, D), generalized_forces, "
             "equations, multipliers. A class: several files, globs or folders (their *.toml); "
             "one row per file.", show_default=False)],
    set_: _SET = [],  # noqa: B006
    lock: _LOCK = [],  # noqa: B006
    json_: _JSON = False,
    csv: Annotated[str | None, typer.Option(
        "--csv", help="Also write one row per file per item to this CSV (new, or one that "
                      "check wrote).")] = None,
    hints_only: Annotated[bool, typer.Option(
        "--hints-only", help="Hide the expected expressions and values: give the module's "
                             "diagnostic question for each finding instead.")] = False,
) -> None:
    """Check a hand derivation (T, V, Q, equations, multipliers) and diagnose each mistake;
    with several answer files, grade a class (derived once, one row per file)."""
    from .. import check_input_file

    single = len(answers) == 1 and _one_file(answers[0])
    if single and Path(answers[0]).exists():
        # a FIFO, a device or a 3 GB file is refused at once, before the model is even read
        _refused_as_unreadable(lambda: check_input_file(answers[0]), json_)
    from .. import AnswerResult, ClassReport, answer_files
    from ..errors import one_line as shown_name  # a file name as every output shows it
    from ..output.check import (
        check_class_csv_path,
        check_document,
        check_text,
        class_document,
        class_text,
        write_class_csv,
    )

    inputs: tuple[Path, ...] = ()
    if csv is not None:
        named = answers if single else [p for p, error in answer_files(answers) if not error]
        inputs = tuple(Path(p) for p in [model, *named] if Path(p).exists())
        check_class_csv_path(csv, inputs=inputs)
    system = load_system(model, set_, lock)
    if single:
        system.equations_of_motion()  # the model's own faults stay errors without a document
        report = _refused_as_unreadable(
            lambda: system.check(answers[0], hints_only=hints_only), json_)
        if csv is not None:
            write_class_csv(ClassReport(system.name, (AnswerResult(shown_name(answers[0]), report),),
                                        hints_only), csv, inputs=inputs)
        if json_:
            print_json(check_document(report))
        else:
            typer.echo(check_text(report), nl=False)
        if not report.passed:
            raise SystemExit(1)
        return
    grades = system.check_many(answers, hints_only=hints_only)
    if csv is not None:
        write_class_csv(grades, csv, inputs=inputs)
    if json_:
        print_json(class_document(grades))
    else:
        typer.echo(class_text(grades), nl=False)
    if grades.exit_status:
        raise SystemExit(grades.exit_status)


def _refused_as_unreadable(work, json_: bool):
    """``work()``; its LagrangianError raised again, after an "unreadable" document with --json
    (a script reading the JSON gets a document, not an empty stdout)."""
    try:
        return work()
    except LagrangianError as exc:
        if json_:
            print_json({"verdict": "unreadable", "findings": [], "error": str(exc)})
        raise


def _one_file(name: str) -> bool:
    """ANSWER is one file as before (today's output and JSON): not a folder or a glob that
    names files; a missing file stays one, refused as before."""
    import glob

    path = Path(name)
    if path.is_dir():
        return False
    return path.exists() or not glob.has_magic(name)


@app.command()
def crosscheck(model: _MODEL, set_: _SET = [], lock: _LOCK = [],  # noqa: B006
               json_: _JSON = False,
               steps: Annotated[bool, typer.Option("--steps", help="Show each body's free-body equations and how they map to Lagrange's (a 'steps' key in JSON).")] = False,  # noqa: E501
               ) -> None:
    """Derive again by Newton-Euler (free bodies, reactions eliminated) and compare with Lagrange."""
    from ..output.check import crosscheck_document, crosscheck_text
    from ..output.crosscheck_steps import crosscheck_steps_document, crosscheck_steps_text

    system = load_system(model, set_, lock)
    report = system.crosscheck()
    working = system.crosscheck_steps() if steps else None
    if json_:
        document = crosscheck_document(report)
        if working is not None:
            document["steps"] = crosscheck_steps_document(working)
        print_json(document)
    else:
        typer.echo(crosscheck_text(report), nl=False)
        if working is not None:
            typer.echo("\n" + crosscheck_steps_text(working), nl=False)
    if not report.passed:
        raise SystemExit(1)


@app.command()
def units(model: _MODEL, lock: _LOCK = [], json_: _JSON = False) -> None:  # noqa: B006
    """Check the model for dimensional consistency; print every inconsistent term."""
    from ..output.check import units_document, units_text

    system = load_system(model, (), lock)
    report = system.check_units()
    if json_:
        print_json(units_document(report))
    else:
        typer.echo(units_text(report), nl=False)
    if not report.passed:
        raise SystemExit(1)
