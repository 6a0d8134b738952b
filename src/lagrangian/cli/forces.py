"""`lagrangian forces MODEL --at theta=30deg`: generalized forces by virtual work, per load."""

from __future__ import annotations

from typing import Annotated

import typer

from . import app
from .common import LOCK_HELP, SET_HELP, load_system, print_json, state_assignments


@app.command()
def forces(
    model: Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")],
    at: Annotated[list[str], typer.Option("--at", help="Configuration: NAME=VALUE (30deg, 0.5m); repeat, or join with commas.")] = [],  # noqa: B006,E501
    set_: Annotated[list[str], typer.Option("--set", help=SET_HELP)] = [],  # noqa: B006
    lock: Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)] = [],  # noqa: B006
    json_: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
) -> None:
    """Evaluate each generalized force, and each load's contribution, at a configuration."""
    from ..output.forces import forces_document, forces_text

    system = load_system(model, set_, lock)
    report = system.generalized_forces_at(state_assignments(system, at, "--at"))
    if json_:
        print_json(forces_document(report))
    else:
        typer.echo(forces_text(report), nl=False)
