"""`lagrangian modes MODEL [--about theta=0] [--json] [--plot modes.png] [--animate modes.gif]`:
natural frequencies, mode shapes, and the mechanism animated in each mode."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from . import app
from .common import (
    FPS_HELP,
    GRAVITY_HELP,
    LOCK_HELP,
    ONLY_WITH_ANIMATE,
    PAYLOAD_HELP,
    SET_HELP,
    SIZE_HELP,
    load_system,
    print_json,
    state_assignments,
)

ABOUT_HELP = "Equilibrium: COORDINATE=VALUE (pi, 180deg, 0.5m); the others are solved for."
ANIMATE_HELP = ("Animate the mechanism oscillating in each mode (the lowest six side by side): "
                ".gif, .html (a player) or .mp4 (needs lagrangian[mp4]).")
MODE_HELP = "With --animate: only this mode, numbered from 1 as printed."
VIEW_HELP = "With --animate, bodies in space: AZIMUTH,ELEVATION in degrees (default isometric)."
INPUTS_HELP = ("Loads, parameters or coordinates (a generalized force) that drive the system: "
               "their values that make --about an equilibrium are solved for and printed (the "
               "trim), the linear model's B is theirs; repeat, or separate by commas.")
STEADY_HELP = ("Steady motion: a cyclic coordinate's constant rate, NAME_dot=VALUE (psi_dot=10, "
               "rad/s, or an expression in the parameters: thetaR_dot=-v/rR); linearize about "
               "it instead of an equilibrium.")


def steady_assignments(system, settings: list[str]) -> dict[str, float | str]:
    """--steady NAME_dot=VALUE: the library reads each as a quantity (10, 600rpm) or as an
    expression in the parameters (-v/rR), or refuses it (lagrangian.parse_steady_rates)."""
    from .. import parse_steady_rates, state_units
    from .common import assignments, comma_separated, warn_bare_angles

    pairs = assignments(comma_separated(settings), "--steady")
    rates = parse_steady_rates(system.model, dict(pairs))
    warn_bare_angles("--steady", pairs, state_units(system.model), rates)
    return rates


@app.command()
def modes(
    model: Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")],
    about: Annotated[list[str], typer.Option("--about", help=ABOUT_HELP)] = [],  # noqa: B006
    steady: Annotated[list[str], typer.Option("--steady", help=STEADY_HELP)] = [],  # noqa: B006
    set_: Annotated[list[str], typer.Option("--set", help=SET_HELP)] = [],  # noqa: B006
    lock: Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)] = [],  # noqa: B006
    gravity: Annotated[str | None, typer.Option("--gravity", help=GRAVITY_HELP)] = None,
    payload: Annotated[list[str], typer.Option("--payload", help=PAYLOAD_HELP)] = [],  # noqa: B006
    drives: Annotated[list[str], typer.Option("--inputs", help=INPUTS_HELP)] = [],  # noqa: B006
    json_: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    plot: Annotated[Path | None, typer.Option("--plot", help="Draw the mode shapes to a PNG file.")] = None,
    animate: Annotated[Path | None, typer.Option("--animate", help=ANIMATE_HELP)] = None,
    mode: Annotated[int | None, typer.Option("--mode", help=MODE_HELP)] = None,
    size: Annotated[str | None, typer.Option("--size", help=SIZE_HELP)] = None,
    fps: Annotated[int | None, typer.Option("--fps", help=FPS_HELP + " Default 20.")] = None,
    view: Annotated[str | None, typer.Option("--view", help=VIEW_HELP)] = None,
) -> None:
    """Linearize about an equilibrium: M, C, K, natural frequencies, damping and mode shapes."""
    from ..errors import InputError
    from ..output.files import check_output_path
    from ..output.modes import modes_document, modes_text

    system = load_system(model, set_, lock, gravity, payload)
    point = state_assignments(system, about, "--about")
    inputs = (Path(model),) if Path(model).exists() else ()
    if plot is not None:  # before the analysis: a path that cannot be written costs nothing
        from ..output.plots import check_plot_path

        check_output_path(check_plot_path(plot), "plot", inputs=inputs)
    for given, field in ((mode, "mode"), (size, "size"), (fps, "fps"), (view, "view")):
        if given is not None and animate is None:
            raise InputError(f"{ONLY_WITH_ANIMATE[field]} only used with --animate", field=field)
    if animate is not None:  # the same: everything checked before the analysis
        from ..output.animation import check_animation_target, check_fps, check_size, check_view

        check_output_path(animate, "animation", inputs=inputs)
        check_animation_target(animate)
        size, fps, view = check_size(size), check_fps(20 if fps is None else fps), check_view(view)
    rates = steady_assignments(system, steady) if steady else {}
    names = [name.strip() for text in drives for name in text.split(",") if name.strip()]
    analysis = system.modes(about=point or None, steady=rates or None, inputs=names)
    trim = analysis.linear_model.trim
    if plot is not None:
        from ..output.modes import write_mode_plot

        write_mode_plot(analysis, plot, protect=inputs)
    if animate is not None:
        analysis.animate(animate, mode=mode, fps=fps, size=size, view=view)
    if json_:
        document = modes_document(analysis)
        if names:  # the inputs, their trim and B (x = [z; z_dot])
            document.update(inputs=names, trim=trim,
                            input_matrix=analysis.linear_model.B.tolist())
        if animate is not None:
            document["animation"] = str(animate)
        print_json(document)
    else:
        typer.echo(modes_text(analysis), nl=False)
        if trim:
            from .simulate import trim_text

            typer.echo(trim_text(trim))
        if plot is not None:
            typer.echo(f"Mode shapes drawn to {plot}")
        if animate is not None:
            which = f"mode {mode}" if mode is not None else "each mode"
            typer.echo(f"The mechanism in {which} animated to {animate}")

