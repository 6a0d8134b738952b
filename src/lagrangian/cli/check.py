"""`lagrangian check MODEL ANSWER.toml`, `lagrangian crosscheck MODEL`, `lagrangian units MODEL`.

check exits 0 when the answer is correct, 1 when it is not, 2 when a file cannot be read
(crosscheck: 1 when the derivations disagree; units: 1 when a term is inconsistent).
SystemExit(1) rather than typer.Exit(1): the app runs with standalone_mode=False, where click
returns an Exit's code instead of raising it, and the status would be lost.
"""

from __future__ import annotations

from typing import Annotated

import typer

from . import app
from .common import LOCK_HELP, SET_HELP, load_system, print_json

_MODEL = Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")]
_SET = Annotated[list[str], typer.Option("--set", help=SET_HELP)]
_LOCK = Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)]
_JSON = Annotated[bool, typer.Option("--json", help="Print JSON.")]


@app.command()
def check(
    model: _MODEL,
    answer: Annotated[str, typer.Argument(help="Your derivation, ANSWER.toml: tables energy (T, V, "
                                                "D), generalized_forces, equations, multipliers.")],
    set_: _SET = [],  # noqa: B006
    lock: _LOCK = [],  # noqa: B006
    json_: _JSON = False,
) -> None:
    """Check a hand derivation (T, V, Q, equations, multipliers) and diagnose each mistake."""
    from ..output.check import check_document, check_text

    system = load_system(model, set_, lock)
    report = system.check(answer)
    if json_:
        print_json(check_document(report))
    else:
        typer.echo(check_text(report), nl=False)
    if not report.passed:
        raise SystemExit(1)


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
