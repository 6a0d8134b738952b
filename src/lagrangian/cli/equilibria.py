"""`lagrangian equilibria MODEL [--set k=2] [--json]`: configurations of rest and their stability."""

from __future__ import annotations

from typing import Annotated

import typer

from . import app
from .common import GRAVITY_HELP, LOCK_HELP, PAYLOAD_HELP, SET_HELP, load_system, print_json


@app.command()
def equilibria(
    model: Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")],
    set_: Annotated[list[str], typer.Option("--set", help=SET_HELP)] = [],  # noqa: B006
    lock: Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)] = [],  # noqa: B006
    gravity: Annotated[str | None, typer.Option("--gravity", help=GRAVITY_HELP)] = None,
    payload: Annotated[list[str], typer.Option("--payload", help=PAYLOAD_HELP)] = [],  # noqa: B006
    json_: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
) -> None:
    """Find the equilibria (forces balance at rest, with the constraints) and their stability."""
    from ..output.modes import equilibria_document, equilibria_text

    system = load_system(model, set_, lock, gravity, payload)
    found = system.equilibria()
    if json_:
        print_json(equilibria_document(found))
    else:
        typer.echo(equilibria_text(found), nl=False)
        if system.model.steady_motion is not None:  # a bicycle: its motion of interest rolls
            typer.echo("\nThese are configurations at rest. The model's [steady] table names a "
                       "steady motion: `modes` (and `speeds`) without --about study it.")
