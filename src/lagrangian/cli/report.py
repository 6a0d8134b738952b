"""`lagrangian report MODEL [--out report.html] [--answer ANSWER.toml]`: one self-contained web page
of the model, its equations, equilibria, modes (each drawn moving), a simulation and the checks."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from . import app
from .common import FPS_HELP, LOCK_HELP, SET_HELP, SIZE_HELP, load_system, print_json


@app.command()
def report(
    model: Annotated[str, typer.Argument(help="Model file (TOML or URDF) or built-in example name.")],
    out: Annotated[Path, typer.Option("--out", help="The page to write (*.html); a file there that "
                                      "lagrangian did not write is refused.")] = Path("report.html"),
    answer: Annotated[Path | None, typer.Option("--answer", help="A hand derivation, ANSWER.toml, "
                                                "to check on the page (as `lagrangian check`).")] = None,
    t_end: Annotated[str | None, typer.Option("--t-end", help="Length of the simulation (s, or with "
                                              "a unit: 500ms); default 10 s.")] = None,
    set_: Annotated[list[str], typer.Option("--set", help=SET_HELP)] = [],  # noqa: B006
    lock: Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)] = [],  # noqa: B006
    size: Annotated[str | None, typer.Option("--size", help=SIZE_HELP.replace(
        "400x400 a drawing", "320x320 a mode, 400x400 the simulation"))] = None,
    fps: Annotated[int | None, typer.Option("--fps", help=FPS_HELP + " Default 15 a mode, 20 "
                                            "the simulation.")] = None,
    json_: Annotated[bool, typer.Option("--json", help="Print what each section shows as JSON.")] = False,
) -> None:
    """Write one self-contained HTML page (offline, math as MathML): the model and its drawing,
    T, V, L, generalized forces, equations, equilibria, modes, a simulation, the units check."""
    from .. import check_report_path, parse_quantity
    from ..output.media import check_fps, check_size

    system = load_system(model, set_, lock)
    # as modes --animate: checked before any work, by the same functions
    size, fps = check_size(size), None if fps is None else check_fps(fps)
    inputs = tuple(p for p in (Path(model), answer) if p is not None and p.exists())
    check_report_path(out, inputs)  # before any work: a path that cannot be written costs nothing
    end = parse_quantity(t_end, "s", "--t-end") if t_end is not None else None
    progress = None
    if sys.stderr.isatty():  # a big model takes a while: say which section is being made
        def progress(title: str) -> None:
            typer.echo(f"report: {title} ...", err=True)
    page = system.report(answer=str(answer) if answer is not None else None, t_end=end,
                         progress=progress, size=size, fps=fps)
    page.save(out, protect=inputs)
    if json_:
        print_json({"report": str(out), "model": page.model_name,
                    "sections": [{"section": s.key, "title": s.title, "status": s.status}
                                 for s in page.sections]})
        return
    shown = sum(s.shown for s in page.sections)
    lines = [f"Report of {page.model_name} written to {out} ({shown} of {len(page.sections)} "
             "sections shown)"]
    lines += [f"  {s.title}: {s.status}" for s in page.sections if not s.shown]
    typer.echo("\n".join(lines))
