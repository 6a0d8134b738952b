"""`lagrangian sweep MODEL --vary k=10:100:46 --vary m=1,2,5 --compute modes --out study.nc`:
parameter studies and ensembles on Dask (see docs/sweeps.md)."""

from __future__ import annotations

import re
import sys
import time
from pathlib import Path
from typing import Annotated

import typer

from ..errors import InputError, LagrangianError, ModelError
from . import app
from .common import (
    LOCK_HELP,
    assignments,
    in_flags,
    load_system,
    print_json,
    state_assignments,
    warn,
)

# The library's field -> this command's flag (before the shared table of common.py).
SWEEP_FLAGS = {
    "vary": "--vary", "sample": "--sample", "members": "--members", "samples": "--time-samples",
    "compute": "--compute", "t_end": "--t-end", "out": "--out", "plot": "--plot",
    "resume": "--resume", "scheduler": "--scheduler", "stop_when": "--stop-when",
    "method": "--method", "rtol": "--rtol", "atol": "--atol", "initial": "--vary",
    "about": "--about", "workers": "--workers",
}
VARY_HELP = ("A varied name and its values: NAME=START:STOP:COUNT (COUNT evenly spaced values, "
             "both ends included), NAME=V1,V2,... or NAME=VALUE; units as in --set (0deg:90deg:19).")
_COUNT = re.compile(r"^\s*\d+\s*$")


@app.command()
def sweep(
    model: Annotated[str, typer.Argument(help="Model file (TOML or URDF) or built-in example name.")],
    vary: Annotated[list[str], typer.Option("--vary", help=VARY_HELP)] = [],  # noqa: B006
    compute: Annotated[str, typer.Option("--compute", help="modes, equilibria, simulate, or speeds (eigenvalues about the model's [steady] motion).")] = "modes",  # noqa: E501
    out: Annotated[Path | None, typer.Option("--out", help="Write the Dataset: .nc (NetCDF) or .zarr.")] = None,  # noqa: E501
    plot: Annotated[Path | None, typer.Option("--plot", help="Draw frequencies / stability / equilibria against the varied parameter(s): .png.")] = None,  # noqa: E501
    json_: Annotated[bool, typer.Option("--json", help="Print a JSON summary.")] = False,
    set_: Annotated[list[str], typer.Option("--set", help="Override a parameter for the whole study: NAME=VALUE.")] = [],  # noqa: B006,E501
    sample: Annotated[list[str], typer.Option("--sample", help="Ensemble: NAME=normal(MEAN,STD) or NAME=uniform(LOW,HIGH), SI.")] = [],  # noqa: B006,E501
    members: Annotated[int, typer.Option("--members", help="Ensemble members drawn for --sample.")] = 0,
    samples: Annotated[int | None, typer.Option("--samples", hidden=True, help="Deprecated: --members.")] = None,  # noqa: E501
    seed: Annotated[int, typer.Option("--seed", help="Seed of the ensemble's draws.")] = 0,
    t_end: Annotated[str | None, typer.Option("--t-end", help="simulate: end time (s, or with a unit).")] = None,  # noqa: E501
    time_samples: Annotated[int, typer.Option("--time-samples", help="simulate: samples of the common time grid.")] = 201,  # noqa: E501
    method: Annotated[str, typer.Option("--method", help="simulate: integrator.")] = "DOP853",
    rtol: Annotated[float, typer.Option("--rtol", help="simulate: relative tolerance.")] = 1e-9,
    atol: Annotated[float, typer.Option("--atol", help="simulate: absolute tolerance.")] = 1e-9,
    stop_when: Annotated[str | None, typer.Option("--stop-when", help="simulate: stop a member when a condition turns true.")] = None,  # noqa: E501
    trajectories: Annotated[bool, typer.Option("--trajectories", help="simulate: keep every member's states on the time grid.")] = False,  # noqa: E501
    scheduler: Annotated[str | None, typer.Option("--scheduler", help="Address of a running Dask scheduler (tcp://host:8786); default: a local cluster, one worker per core.")] = None,  # noqa: E501
    workers: Annotated[int | None, typer.Option("--workers", help="Worker processes of the local cluster (default: one per core).")] = None,  # noqa: E501
    resume: Annotated[bool, typer.Option("--resume", help="Continue an interrupted study writing to the same --out.")] = False,  # noqa: E501
    chunk_size: Annotated[int | None, typer.Option("--chunk-size", help="Points per task.")] = None,
    about: Annotated[list[str], typer.Option("--about", help="modes: the equilibrium, COORDINATE=VALUE (theta=0); default: the one nearest the initial values, as `lagrangian modes`.")] = [],  # noqa: B006,E501
    lock: Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)] = [],  # noqa: B006
) -> None:
    """Evaluate modes, equilibria or simulations over a grid of parameters (and ensembles)."""
    if samples is not None:  # the old name of --members: one flag, one meaning (--time-samples)
        typer.echo("warning: --samples of a sweep is now --members (the ensemble's size); "
                   "--samples will be removed", err=True)
        if members and members != samples:
            raise InputError("give the ensemble's size once, as --members", field="--members")
        members = samples
    try:
        _run(model, vary, compute, out, plot, json_, set_, sample, members, seed, t_end,
             time_samples, method, rtol, atol, stop_when, trajectories, scheduler, workers,
             resume, chunk_size, about, lock)
    except ModelError as exc:
        raise _flagged(exc) from None


def _run(model, vary, compute, out, plot, json_, set_, sample, members, seed, t_end,
         time_samples, method, rtol, atol, stop_when, trajectories, scheduler, workers, resume,
         chunk_size, about, lock=()):
    from .. import parse_quantity, state_units
    from ..output.sweep import (
        check_study_path,
        check_study_plot_path,
        require_study_packages,
        study_summary,
        study_text,
    )

    require_study_packages(out)  # the extra [sweep], asked before the model is derived
    # the locked model's equations travel inside the Study to the Dask workers
    system = load_system(model, set_, lock)
    units = {p.name: p.unit for p in system.model.parameters}
    units.update(state_units(system.model))
    grid = {name: grid_values(text, units.get(name), f"vary.{name}")
            for name, text in assignments(vary, "--vary")}
    draws = dict(assignments(sample, "--sample"))
    point = state_assignments(system, about, "--about")
    end = parse_quantity(t_end, "s", "t_end") if t_end is not None else None
    if out is not None:
        check_study_path(out)
    elif resume:
        raise InputError("--resume continues the study written to --out; give --out", field="resume")
    if plot is not None:
        check_study_plot_path(plot)
    if workers is not None and workers < 1:
        raise InputError("at least one worker", field="workers")
    if chunk_size is not None and chunk_size < 1:
        raise InputError("at least one point per chunk", field="chunk_size")
    inputs = (Path(model),) if Path(model).exists() else ()
    for path in (out, plot):
        if path is not None and inputs and path.resolve() == inputs[0].resolve():
            raise InputError(f"{path}: refusing to overwrite the model file", field="out")

    with _Progress() as progress:
        try:
            dataset = system.sweep(
                grid, compute, sample=draws, members=members, seed=seed, t_end=end,
                method=method, rtol=rtol, atol=atol, samples=time_samples,
                stop_when=stop_when, trajectories=trajectories, out=out, resume=resume,
                scheduler=scheduler, workers=workers, chunk_size=chunk_size,
                progress=progress.update, about=point or None)
        except KeyboardInterrupt:
            progress.close()
            where = (f"; what finished is in {out}, continue with --resume" if out is not None
                     else "")
            typer.echo(f"interrupted{where}", err=True)
            raise SystemExit(130) from None
    summary = study_summary(dataset)
    for line in summary.get("warnings", []):
        warn(line)
    if summary["points"] and not summary["ok"]:  # nothing computed is a failure, not a result
        from ..errors import DerivationError

        reason, count = max(summary["missing"].items(), key=lambda item: item[1])
        raise DerivationError(f"none of the {summary['points']} points could be computed "
                              f"({reason}: {count} points)")
    if plot is not None:
        from ..output.sweep import write_study_plot

        write_study_plot(dataset, plot, protect=inputs)
    if json_:
        summary["written"] = {k: str(v) for k, v in (("out", out), ("plot", plot)) if v}
        print_json(summary)
    else:
        typer.echo(study_text(dataset, out), nl=False)
        if plot is not None:
            typer.echo(f"Plot drawn to {plot}")


def grid_values(text: str, unit: str | None, field: str) -> list[float]:
    """START:STOP:COUNT (evenly spaced, both ends), V1,V2,... or one VALUE, each with its unit."""
    import numpy as np

    from .. import parse_quantity

    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3 or not all(p.strip() for p in parts):
            raise InputError(f"a range is START:STOP:COUNT, got {text!r}", field=field)
        if not _COUNT.match(parts[2]) or int(parts[2]) < 1:
            raise InputError(f"the COUNT of {text!r} must be a whole number of values, at least 1",
                             field=field)
        count = int(parts[2])
        from .. import MAX_STUDY_POINTS

        if count > MAX_STUDY_POINTS:
            raise InputError(f"{count:,} values is more than a study holds (at most "
                             f"{MAX_STUDY_POINTS:,})", field=field)
        start = parse_quantity(parts[0].strip(), unit, field)
        stop = parse_quantity(parts[1].strip(), unit, field)
        return [float(v) for v in np.linspace(start, stop, count)]
    items = text.split(",")
    if not all(item.strip() for item in items):
        raise InputError(f"an empty value in {text!r}", field=field)
    return [parse_quantity(item.strip(), unit, field) for item in items]


def _flagged(error: ModelError) -> LagrangianError:
    """The error with the library's field named by this command's flag (vary.k -> --vary k)."""
    if error.source or not error.field:
        return error
    head, _, rest = error.field.partition(".")
    if head in SWEEP_FLAGS:
        return ModelError(error.message, field=f"{SWEEP_FLAGS[head]} {rest}".strip())
    return in_flags(error)


class _Progress:
    """A rich progress bar of the points done, on a terminal (stderr)."""

    def __init__(self):
        self.enabled = sys.stderr.isatty()
        self.bar = None
        self.task = None
        self.started = time.perf_counter()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def close(self):
        if self.bar is not None:
            self.bar.stop()
            self.bar = None

    def update(self, done: int, total: int) -> None:
        if not self.enabled:
            return
        if self.bar is None:
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )

            self.bar = Progress(TextColumn("sweep"), BarColumn(), MofNCompleteColumn(),
                                TimeElapsedColumn(), TimeRemainingColumn(),
                                console=Console(stderr=True), transient=True)
            self.bar.start()
            self.task = self.bar.add_task("sweep", total=total)
        self.bar.update(self.task, completed=done)
