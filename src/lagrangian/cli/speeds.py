"""`lagrangian speeds MODEL --speed v --steady x_dot=v,... --keep phi,delta`: the reduced linear
equations about steady motion in the benchmark form, and their eigenvalues against speed."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..errors import InputError
from . import app
from .common import LOCK_HELP, SET_HELP, assignments, comma_separated, load_system, print_json

STEADY_HELP = ("A steady rate, NAME_dot=EXPRESSION in the parameters (x_dot=v, "
               "thetaR_dot=-v/rR); repeat or join with commas. Default: the model's [steady] "
               "table.")
KEEP_HELP = ("The coordinates whose equations are kept (phi,delta); the rest are eliminated. "
             "Default: the model's [steady] table.")


def steady_settings(settings: list[str], option: str = "--steady") -> dict[str, str]:
    """NAME_dot=TEXT pairs, the text left to the library (a number or an expression in the
    parameters)."""
    return dict(assignments(comma_separated(settings), option))


@app.command()
def speeds(
    model: Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")],
    speed: Annotated[str | None, typer.Option("--speed", help="The parameter that is the "
                                              "forward speed (m/s), e.g. v. Default: the "
                                              "model's [steady] table.")] = None,
    steady: Annotated[list[str], typer.Option("--steady", help=STEADY_HELP)] = [],  # noqa: B006
    keep: Annotated[list[str], typer.Option("--keep", help=KEEP_HELP)] = [],  # noqa: B006
    about: Annotated[list[str], typer.Option("--about", help="Configuration of the steady "
                                             "motion, COORDINATE=VALUE (the rest solved for).")
                     ] = [],  # noqa: B006
    lowest: Annotated[float, typer.Option("--from", help="Lowest speed of the sweep.")] = 0.0,
    highest: Annotated[float, typer.Option("--to", help="Highest speed of the sweep.")] = 10.0,
    points: Annotated[int, typer.Option("--points", help="Speeds in the sweep.")] = 101,
    at: Annotated[list[str], typer.Option("--at", help="Eigenvalues at chosen speeds, "
                                          "SPEED=V1,V2,... (v=0.7,2.9,5.3; units allowed: "
                                          "18km/h).")] = [],  # noqa: B006
    set_: Annotated[list[str], typer.Option("--set", help=SET_HELP)] = [],  # noqa: B006
    lock: Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)] = [],  # noqa: B006
    json_: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    plot: Annotated[Path | None, typer.Option("--plot", help="Draw the eigenvalues against "
                                              "speed (.png, .svg, .pdf).")] = None,
) -> None:
    """M q'' + v C1 q' + (g K0 + v^2 K2) q = f about steady motion, and a speed sweep with the
    speeds where the eigenvalues' real parts cross zero (weave, capsize)."""
    from ..errors import InputError
    from ..output.files import check_output_path
    from ..output.plots import check_plot_path
    from ..output.speed_form import (
        chosen_speeds_document,
        chosen_speeds_text,
        speed_form_document,
        speed_form_text,
        write_speed_plot,
    )
    from .common import state_assignments

    system = load_system(model, set_, lock)
    inputs = (Path(model),) if Path(model).exists() else ()
    if plot is not None:
        check_output_path(check_plot_path(plot), "plot", inputs=inputs)
    if not (points >= 2 and highest > lowest):
        raise InputError("the sweep needs --to above --from and --points of at least 2",
                         field="--points")
    point = state_assignments(system, about, "--about")
    # --at read before the speed form is derived: a bad speed costs no derivation
    default = system.model.steady_motion
    named = speed or (default.speed if default is not None else None)
    chosen = _chosen_speeds(system, named, at) if named else None
    kept = [name.strip() for setting in keep for name in setting.split(",") if name.strip()]
    form = system.speed_form(steady_settings(steady) or None, speed, kept or None,
                             about=point or None)
    import numpy as np

    from .. import speed_sweep

    sweep = speed_sweep(form, np.linspace(lowest, highest, points))
    if chosen is None:
        chosen = _chosen_speeds(system, form.speed, at)
    if plot is not None:
        write_speed_plot(form, sweep, plot, protect=inputs)
    if json_:
        document = speed_form_document(system.model.name, form, sweep)
        if chosen:
            document["at"] = chosen_speeds_document(form, chosen)
        print_json(document)
    else:
        typer.echo(speed_form_text(system.model.name, form, sweep), nl=False)
        if chosen:
            typer.echo(chosen_speeds_text(form, chosen), nl=False)
        if plot is not None:
            typer.echo(f"Eigenvalues against speed drawn to {plot}")


def _chosen_speeds(system, speed: str, settings: list[str]) -> list[float]:
    """--at SPEED=V1,V2,...: the speeds (m/s) to evaluate, named by the speed parameter."""
    from .. import parse_quantity

    unit = next((p.unit for p in system.model.parameters if p.name == speed), None)
    speeds: list[float] = []
    for setting in settings:
        name, sep, text = setting.partition("=")
        if not sep or not text.strip():
            raise InputError(f"expected {speed}=V1,V2,..., got {setting!r}", field="--at")
        if name.strip() != speed:
            raise InputError(f"'{name.strip()}' is not the speed parameter; write "
                             f"{speed}=V1,V2,...", field="--at")
        for item in text.split(","):
            if not item.strip():
                raise InputError(f"an empty value in {text!r}", field="--at")
            speeds.append(parse_quantity(item.strip(), unit, f"--at {speed}"))
    return speeds
