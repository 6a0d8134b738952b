"""`lagrangian cycle MODEL [--set NAME=VALUE] [--guess NAME=VALUE] [--json]`: the periodic orbit
through a model's impacts (a walker's gait): period, multipliers, stability."""

from __future__ import annotations

from typing import Annotated

import typer

from . import app
from .common import SET_HELP, load_system, print_json, state_assignments

GUESS_HELP = ("A state just after the impact to start Newton's method from: NAME=VALUE "
              "(theta_st=-0.27, theta_st_dot=1.1); default: the model's initial state.")


@app.command()
def cycle(
    model: Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")],
    set_: Annotated[list[str], typer.Option("--set", help=SET_HELP)] = [],  # noqa: B006
    guess: Annotated[list[str], typer.Option("--guess", help=GUESS_HELP)] = [],  # noqa: B006
    json_: Annotated[bool, typer.Option("--json", help="Print JSON: state, period, multipliers ([re, im]), stable.")] = False,  # noqa: E501
) -> None:
    """The limit cycle through the model's impacts: its state after the impact, period and
    Floquet multipliers (exact Jacobian of the Poincare map), and whether it is stable."""
    from ..output.impacts import cycle_document, cycle_text

    system = load_system(model, set_)
    start = state_assignments(system, guess, "--guess")  # the rest: the model's initial state
    found = system.limit_cycle(start or None)
    if json_:
        print_json(cycle_document(found))
    else:
        typer.echo(cycle_text(found, system.name), nl=False)
