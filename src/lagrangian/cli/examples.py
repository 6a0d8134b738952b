"""`lagrangian examples`: the built-in example models."""

from __future__ import annotations

from typing import Annotated

import typer

from .. import example_names, example_path, example_robots, example_summary, example_text
from . import app
from .common import print_json


def _show(name: str, json_: bool) -> None:
    """The example's file; for a robot (URDF) its coordinates' joint names after it, as an XML
    comment (the text stays a valid URDF), or with --json a document of both."""
    path = example_path(name)
    text = example_text(name)
    joint_names: dict[str, str] = {}
    if path.suffix == ".urdf":
        from .. import load

        joint_names = load(name).joint_names
    if json_:
        print_json({"name": name, "file": path.name, "text": text, "joint_names": joint_names})
        return
    typer.echo(text, nl=False)
    if joint_names:
        pairs = ", ".join(f"{c} = '{j}'" for c, j in joint_names.items())
        # "--" may not appear inside an XML comment; URDF names rarely hold it
        typer.echo(f"<!-- lagrangian coordinates (coordinate = URDF joint): "
                   f"{pairs.replace('--', '- -')} -->")


def _robots(json_: bool) -> None:
    """example-robot-data's robots by short name and path; a name a built-in example also has
    is marked: the built-in example comes first, the robot loads by its path."""
    listing = example_robots()
    if json_:
        print_json({"robots": listing})
        return
    if not listing:
        typer.echo("example-robot-data is not installed (pip install example-robot-data, or "
                   "set EXAMPLE_ROBOT_DATA_DIR to its robots/ folder)")
        return
    width = max(len(robot["name"]) for robot in listing)
    for robot in listing:
        mark = "  (a built-in example has this name: load the robot by its path)" \
            if robot["shadowed"] else ""
        typer.echo(f"{robot['name']:<{width}}  {robot['path']}{mark}")
    typer.echo("\nLoad one by its name, e.g.: lagrangian dynamics panda --q 0,0,0,-1.5,0,1.5,0,0")


@app.command()
def examples(
    show: Annotated[str | None, typer.Option("--show", help="Print one example's model file.")] = None,
    json_: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    course: Annotated[bool, typer.Option(
        "--course", help="List the course module's teaching set: its lessons' models, right "
                         "answers and one wrong answer per misconception.")] = False,
    copy: Annotated[str | None, typer.Option(
        "--copy", help="With --course: write the teaching set into this new folder (each "
                       "lesson's model.toml and answer files).")] = None,
    robots: Annotated[bool, typer.Option(
        "--robots", help="List example-robot-data's URDFs installed here, with their paths "
                         "(a short name loads one: lagrangian dynamics panda).")] = False,
) -> None:
    """List the built-in examples (use a name wherever a MODEL file is expected)."""
    if robots:
        _robots(json_)
        return
    if course or copy is not None:
        from .course import course_command

        course_command(json_, copy)
        return
    if show is not None:
        _show(show, json_)
        return
    summaries = [example_summary(name) for name in example_names()]
    if json_:
        print_json({"examples": summaries})
        return
    width = max(len(s["name"]) for s in summaries)
    for s in summaries:
        typer.echo(f"{s['name']:<{width}}  {s['title']}")
    typer.echo("\nRun one with, e.g.: lagrangian derive pendulum")
