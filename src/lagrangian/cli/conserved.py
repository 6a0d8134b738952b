"""`lagrangian conserved MODEL [--json]`: what the model's own L conserves."""

from __future__ import annotations

from typing import Annotated

import typer

from . import app
from .common import SET_HELP, load_system, print_json


@app.command()
def conserved(
    model: Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")],
    set_: Annotated[list[str], typer.Option("--set", help=SET_HELP)] = [],  # noqa: B006
    json_: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
) -> None:
    """List the conserved quantities: cyclic momenta, the Jacobi integral (and whether it is
    T + V), Noether quantities of translations and rotations no coordinate shows."""
    from ..output.conserved import conserved_document, conserved_text

    system = load_system(model, set_)
    found = system.conserved()
    if json_:
        print_json(conserved_document(found, system.model))
    else:
        typer.echo(conserved_text(found, system.model), nl=False)
