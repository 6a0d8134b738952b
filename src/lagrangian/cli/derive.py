"""`lagrangian derive MODEL`: energies, equations of motion, generalized forces, matrices."""

from __future__ import annotations

from enum import StrEnum
from typing import Annotated

import typer

from ..errors import ModelError
from . import app
from .common import LOCK_HELP, SET_HELP, load_system, print_json, warn_if_unphysical


class Format(StrEnum):
    text = "text"
    latex = "latex"
    json = "json"


@app.command()
def derive(
    model: Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")],
    format: Annotated[Format, typer.Option("--format", "-f", help="Output format.")] = Format.text,
    json_: Annotated[bool, typer.Option("--json", help="Print JSON (as --format json, the flag of every other command).")] = False,  # noqa: E501
    set_: Annotated[list[str], typer.Option("--set", help=SET_HELP)] = [],  # noqa: B006
    lock: Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)] = [],  # noqa: B006
    standalone: Annotated[bool, typer.Option("--standalone", help="With --format latex: a complete document for pdflatex (title, amsmath), not a fragment.")] = False,  # noqa: E501
) -> None:
    """Derive the equations of motion by Lagrange's method."""
    from ..output.derivation import derivation_document, derivation_latex, derivation_text

    eom = load_system(model, set_, lock).equations_of_motion()
    warn_if_unphysical(eom)
    if json_ and format is Format.latex:
        raise ModelError("--json and --format latex ask for two formats; give one", field="--format")
    if standalone and (json_ or format is not Format.latex):
        raise ModelError("--standalone writes a LaTeX document; give it with --format latex",
                         field="--standalone")
    if json_ or format is Format.json:
        print_json(derivation_document(eom))
    elif format is Format.latex:
        typer.echo(derivation_latex(eom, standalone=standalone), nl=False)
    else:
        typer.echo(derivation_text(eom), nl=False)
