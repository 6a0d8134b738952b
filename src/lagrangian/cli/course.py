"""`lagrangian examples --course`: the seed course module's teaching set (list, --json, --copy)."""

from __future__ import annotations

from pathlib import Path

import typer

from .. import course_document, course_folder, course_lessons, example_path
from ..errors import ModelError
from .common import print_json


def course_command(json_: bool, copy: str | None) -> None:
    if copy is not None:
        written = copy_course(Path(copy))
        typer.echo(f"wrote {len(written)} files of the teaching set to {copy}")
        typer.echo(f"check a lesson's answers with, e.g.: lagrangian check "
                   f"{Path(copy) / 'worked_example_1' / 'model.toml'} "
                   f"{Path(copy) / 'worked_example_1' / 'answers'}")
        return
    if json_:
        print_json(course_document())
        return
    typer.echo("The course module's teaching set (module 7: Lagrangian dynamics and virtual "
               "work):")
    for lesson in course_lessons():
        typer.echo(f"{lesson.name}  {lesson.title} (model: {lesson.model})")
        typer.echo(f"    task: {lesson.task}")
        width = max(len(a.file) for a in lesson.answers)
        for answer in lesson.answers:
            said = answer.verdict + (f" [{answer.code}] {answer.misconception}"
                                     if answer.code else "")
            typer.echo(f"    {answer.file:<{width}}  {said}")
    typer.echo(f"\nFiles: {course_folder()}")
    typer.echo(f"Check a lesson's answers, e.g.: lagrangian check pendulum "
               f"{course_folder() / 'worked_example_1'}")
    typer.echo("Copy the set to a folder of your own: lagrangian examples --course --copy course")


def copy_course(target: Path) -> list[Path]:
    """Write each lesson's folder (model.toml, the built-in model, and answers/ with its answer
    files) into ``target``, a new or empty folder; nothing is overwritten."""
    from ..output.files import atomic_write, check_output_path

    if target.exists() and (not target.is_dir() or any(target.iterdir())):
        raise ModelError(f"{target} exists and is not an empty folder: refusing to write the "
                         "teaching set into it", field="--copy")
    check_output_path(target / "course.toml", "--copy")
    written = []
    for lesson in course_lessons():
        folder = target / lesson.name
        written.append(atomic_write(folder / "model.toml",
                                    example_path(lesson.model).read_text(encoding="utf-8")))
        for answer in lesson.answers:
            written.append(atomic_write(folder / "answers" / answer.file,
                                        lesson.answer_path(answer).read_text(encoding="utf-8")))
    return written
