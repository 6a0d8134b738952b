"""`lagrangian statics MODEL --at theta=40deg --solve-for F`: load magnitudes by virtual work."""

from __future__ import annotations

from typing import Annotated

import typer

from . import app
from .common import LOCK_HELP, SET_HELP, load_system, print_json, state_assignments

AT_HELP = "Configuration: NAME=VALUE (40deg, 0.5m); coordinates not given follow the constraints."
SOLVE_HELP = "Parameter to find (a load magnitude); repeat or separate by commas."


@app.command()
def statics(
    model: Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")],
    at: Annotated[list[str], typer.Option("--at", help=AT_HELP)] = [],  # noqa: B006
    solve_for: Annotated[list[str], typer.Option("--solve-for", help=SOLVE_HELP)] = [],  # noqa: B006
    set_: Annotated[list[str], typer.Option("--set", help=SET_HELP)] = [],  # noqa: B006
    lock: Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)] = [],  # noqa: B006
    json_: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
) -> None:
    """Find the load magnitudes that hold the mechanism at rest in a configuration (delta W = 0)."""
    from ..output.statics import statics_document, statics_text

    system = load_system(model, set_, lock)
    names = [name.strip() for item in solve_for for name in item.split(",") if name.strip()]
    report = system.statics(state_assignments(system, at, "--at"), names)
    if json_:
        print_json(statics_document(report))
    else:
        typer.echo(statics_text(report), nl=False)
