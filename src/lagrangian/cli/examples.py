"""`lagrangian examples`: the built-in example models."""

from __future__ import annotations

from typing import Annotated

import typer

from .. import example_names, example_path, example_summary
from . import app
from .common import print_json


@app.command()
def examples(
    show: Annotated[str | None, typer.Option("--show", help="Print one example's model file.")] = None,
    json_: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
) -> None:
    """List the built-in examples (use a name wherever a MODEL file is expected)."""
    if show is not None:
        typer.echo(example_path(show).read_text(encoding="utf-8"), nl=False)
        return
    summaries = [example_summary(name) for name in example_names()]
    if json_:
        print_json({"examples": summaries})
        return
    width = max(len(s["name"]) for s in summaries)
    for s in summaries:
        typer.echo(f"{s['name']:<{width}}  {s['title']}")
    typer.echo("\nRun one with, e.g.: lagrangian derive pendulum")
