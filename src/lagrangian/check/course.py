"""The seed course module's teaching set, shipped with the package (model/examples/course/):
lessons with their model (a built-in example), task and answer files, each with the verdict it
must get (right answers correct, each misconception's wrong answer diagnosed by its code)."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path


@dataclass(frozen=True)
class CourseAnswer:
    """One answer file of a lesson and what check must say of it."""

    file: str
    verdict: str
    code: str | None = None
    misconception: str | None = None


@dataclass(frozen=True)
class Lesson:
    """One lesson of the teaching set: its model (a built-in example), task and answer files."""

    name: str
    title: str
    model: str  # a built-in example's name
    task: str
    answers: tuple[CourseAnswer, ...]

    @property
    def folder(self) -> Path:
        """The lesson's answer files (in the installed package)."""
        return course_folder() / self.name

    def answer_path(self, answer: CourseAnswer) -> Path:
        return self.folder / answer.file


def course_folder() -> Path:
    """The teaching set's folder inside the installed package."""
    return Path(str(resources.files("lagrangian.model.examples") / "course"))


def course_lessons() -> list[Lesson]:
    """The lessons in the module's order: worked examples 1-3, the ladder, multipliers."""
    data = tomllib.loads((course_folder() / "course.toml").read_text(encoding="utf-8"))
    return [Lesson(name=item["name"], title=item["title"], model=item["model"], task=item["task"],
                   answers=tuple(CourseAnswer(**answer) for answer in item["answers"]))
            for item in data["lessons"]]


def course_document() -> dict:
    """The teaching set as JSON: each lesson with its model, task and answers (with paths)."""
    return {"course": "Multibody Dynamics, module 7: Lagrangian dynamics and virtual work",
            "folder": str(course_folder()),
            "lessons": [{"name": lesson.name, "title": lesson.title, "model": lesson.model,
                         "task": lesson.task,
                         "answers": [{"file": a.file, "path": str(lesson.answer_path(a)),
                                      "verdict": a.verdict, "code": a.code,
                                      "misconception": a.misconception}
                                     for a in lesson.answers]}
                        for lesson in course_lessons()]}


__all__ = ["CourseAnswer", "Lesson", "course_document", "course_folder", "course_lessons"]
