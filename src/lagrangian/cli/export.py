"""`lagrangian export MODEL --fmu out.fmu [--set k=2]`: the model as an FMI 2.0 FMU, Model
Exchange and Co-Simulation (the generated C compiled for this platform) for Modelica tools,
Simulink or fmpy."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from . import app
from .common import SET_HELP, load_system

FMU_HELP = ("Write an FMI 2.0 FMU (Model Exchange and Co-Simulation): states q, q_dot as "
            "outputs, the parameters tunable, a generalized force Q_<coordinate> per "
            "coordinate as an input.")


@app.command()
def export(
    model: Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")],
    fmu: Annotated[Path | None, typer.Option("--fmu", help=FMU_HELP)] = None,
    set_: Annotated[list[str], typer.Option("--set", help=SET_HELP)] = [],  # noqa: B006
) -> None:
    """Export the model for another tool (an FMU)."""
    import lagrangian

    if fmu is None:
        raise lagrangian.InputError("say what to export: --fmu out.fmu", field="fmu")
    system = load_system(model, set_)
    written = system.to_fmu(fmu)
    typer.echo(f"FMU (FMI 2.0, Model Exchange and Co-Simulation) of '{system.name}' written "
               f"to {written}: states {', '.join(c.name for c in system.model.coordinates)} "
               "and their rates, "
               f"{len(system.parameters)} tunable parameters")
