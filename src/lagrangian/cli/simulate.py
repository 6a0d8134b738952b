"""`lagrangian simulate MODEL --t-end 10`: integrate the equations of motion; table, plot, animation."""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path
from typing import Annotated

import typer

from ..errors import ModelError
from ..model.units import parse_quantity
from ..numerics.simulate import METHODS, parse_stop_condition
from . import app
from .common import load_system, print_json, state_assignments


@app.command()
def simulate(
    model: Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")],
    t_end: Annotated[str, typer.Option("--t-end", help="End time (s, or with a unit: 500ms).")],
    initial: Annotated[list[str], typer.Option("--initial", help="Initial value: NAME=VALUE (theta=30deg, theta_dot=0, t=0); default: the model's initial/rate.")] = [],  # noqa: B006,E501
    set_: Annotated[list[str], typer.Option("--set", help="Override a parameter: NAME=VALUE.")] = [],  # noqa: B006
    method: Annotated[str, typer.Option("--method", help=f"Integrator: {', '.join(METHODS)}.")] = "DOP853",
    rtol: Annotated[float, typer.Option("--rtol", help="Relative tolerance.")] = 1e-9,
    atol: Annotated[float, typer.Option("--atol", help="Absolute tolerance.")] = 1e-9,
    samples: Annotated[int, typer.Option("--samples", help="Output samples, evenly spaced in time.")] = 1001,
    out: Annotated[Path | None, typer.Option("--out", help="Write the table: .csv or .parquet.")] = None,
    plot: Annotated[Path | None, typer.Option("--plot", help="Plot coordinates and energy: .png (.svg, .pdf).")] = None,  # noqa: E501
    animate: Annotated[Path | None, typer.Option("--animate", help="Animate the mechanism: .gif or .html.")] = None,  # noqa: E501
    stop_when: Annotated[str | None, typer.Option("--stop-when", help="Stop when a condition turns true, e.g. \"theta < 0\".")] = None,  # noqa: E501
    json_: Annotated[bool, typer.Option("--json", help="Print a JSON summary.")] = False,
) -> None:
    """Integrate the equations of motion from the initial state and report, save, plot, animate."""
    from ..output.animation import _check_suffix as check_animation
    from ..output.animation import check_animatable
    from ..output.plots import _check_suffix as check_plot
    from ..output.tables import TABLE_FORMATS

    system = load_system(model, set_)
    end = parse_quantity(t_end, "s", "--t-end")
    start_values = state_assignments(system, initial, "--initial")
    if method not in METHODS:
        raise ModelError(f"unknown method '{method}'; choose one of {', '.join(METHODS)}",
                         field="--method")
    # Check everything the user typed before spending time on the integration.
    if stop_when is not None:
        parse_stop_condition(stop_when, system.model)
    if out is not None and out.suffix.lower() not in TABLE_FORMATS:
        raise ModelError(f"cannot write {out}: use a .csv or .parquet file name", field="--out")
    if plot is not None:
        check_plot(plot)
    if animate is not None:
        check_animation(animate)
        check_animatable(system.model)
    inputs = (Path(model),) if Path(model).exists() else ()
    for path in (out, plot, animate):
        if path is not None and inputs and path.exists() and path.resolve() == inputs[0].resolve():
            raise ModelError(f"{path}: refusing to overwrite the input model file", field="output")

    with _Progress(end) as progress:
        simulation = system.simulate(
            end, initial=start_values, method=method, rtol=rtol, atol=atol, samples=samples,
            stop_when=stop_when, progress=progress.update,
        )
    result = simulation.result
    if result.projected_initial_state:
        changes = ", ".join(f"{name} {given:.12g} -> {used:.12g}"
                            for name, (given, used) in result.projected_initial_state.items())
        typer.echo("warning: the initial state violates the constraints; projected onto them: "
                   + changes, err=True)

    written = {}
    if out is not None:
        written["out"] = str(simulation.save(out))
    if plot is not None:
        simulation.plot(plot)
        written["plot"] = str(plot)
    if animate is not None:
        simulation.animate(animate)
        written["animate"] = str(animate)

    if json_:
        document = _finite(result.summary())
        document["outputs"] = written
        print_json(document)
    else:
        typer.echo(_summary_text(result, written), nl=False)
    if result.status == "failed":
        saved = f"; partial result saved to {', '.join(written.values())}" if written else ""
        typer.echo(f"error: integration failed: {result.message}{saved}", err=True)
        raise SystemExit(1)  # not typer.Exit: click swallows its code outside standalone mode
    if result.status == "interrupted":
        saved = f"; partial result saved to {', '.join(written.values())}" if written else ""
        typer.echo(f"{result.message}{saved}", err=True)
        raise SystemExit(130)


class _Progress:
    """A rich progress bar on a terminal (stderr), shown once a run has taken about a second."""

    def __init__(self, t_end: float):
        self.t_end = t_end
        self.enabled = sys.stderr.isatty()
        self.started = time.perf_counter()
        self.bar = None
        self.task = None

    def __enter__(self):
        self.started = time.perf_counter()
        return self

    def update(self, t: float) -> None:
        if not self.enabled:
            return
        if self.bar is None:
            if time.perf_counter() - self.started < 1.0:
                return
            from rich.console import Console
            from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

            self.bar = Progress(TextColumn("simulating"), BarColumn(),
                                TextColumn("t = {task.completed:.3g} / {task.total:.3g} s"),
                                TimeElapsedColumn(), console=Console(stderr=True), transient=True)
            self.bar.start()
            self.task = self.bar.add_task("simulate", total=self.t_end)
        self.bar.update(self.task, completed=t)

    def __exit__(self, *exc):
        if self.bar is not None:
            self.bar.stop()
        return False


def _finite(value):
    """JSON has no NaN/inf: such numbers become null."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value


def _summary_text(result, written: dict[str, str]) -> str:
    lines = [f"{result.model_name}: {result.message} "
             f"({result.method}, rtol {result.rtol:g}, atol {result.atol:g}, {result.backend})"]
    steps = f"{result.steps} steps, " if result.steps is not None else ""
    lines.append(f"  {steps}{result.nfev} right-hand-side calls, wall time {result.wall_time:.3g} s")
    state = ", ".join(f"{k} = {v:.9g}" for k, v in result.final_state.items())
    lines.append(f"  final state: {state}")
    if result.energy_drift is not None:
        lines.append(f"  relative energy drift: {result.energy_drift:.2e}")
    if result.max_residual is not None:
        lines.append(f"  largest constraint residual: {result.max_residual:.2e}")
    for path in written.values():
        lines.append(f"  wrote {path}")
    return "\n".join(lines) + "\n"
