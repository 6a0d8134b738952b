"""The seed course module's teaching set (issue 20): every shipped answer gets the verdict the set
says, each misconception's wrong answer is diagnosed with its code, and the files are in the
wheel's package data."""

from __future__ import annotations

import json
import tomllib
from fnmatch import fnmatch
from pathlib import Path

import pytest

import lagrangian
from lagrangian.check.course import course_folder, course_lessons
from lagrangian.check.hints import HINTS

ROOT = Path(__file__).resolve().parents[2]
LESSONS = course_lessons()


@pytest.mark.parametrize("lesson", LESSONS, ids=[lesson.name for lesson in LESSONS])
def test_each_shipped_answer_gets_its_verdict(lesson):
    system = lagrangian.load(lesson.model)
    for answer in lesson.answers:
        report = system.check(lesson.answer_path(answer))
        assert report.verdict == answer.verdict, (answer.file, report)
        if answer.code:
            assert answer.code in report.codes(), (answer.file, report)
        else:
            assert all(f.status in ("correct", "equivalent") for f in report.findings)


def test_the_set_covers_the_modules_examples_ladder_and_four_misconceptions():
    models = [lesson.model for lesson in LESSONS]
    assert models[:6] == ["pendulum", "virtual_work_link", "two_mass", "ladder_pendulum",
                          "ladder_vertical_force", "ladder_spring_mass"]
    module = [lesson for lesson in LESSONS if not lesson.name.startswith("conserved_")]
    wrong = {a.code: a.misconception for lesson in module for a in lesson.answers if a.code}
    assert wrong == {code: HINTS[code].mistake for code in (
        "potential_sign", "generalized_force_missing", "reaction_in_minimal_coordinates",
        "multiplier_count")}
    beyond = {a.code: a.misconception for lesson in LESSONS if lesson not in module
              for a in lesson.answers if a.code}  # what L conserves (issue 40)
    assert beyond == {code: HINTS[code].mistake for code in (
        "not_cyclic", "momentum_wrong", "energy_not_conserved")}
    assert all(any(a.verdict == "correct" for a in lesson.answers) for lesson in LESSONS)


def test_every_file_of_the_set_is_package_data():
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())
    patterns = data["tool"]["setuptools"]["package-data"]["lagrangian"]
    # the package as imported: the source tree (editable) or the installed copy (pip install .)
    package = Path(lagrangian.__file__).resolve().parent
    files = [p.resolve() for p in course_folder().rglob("*")
             if p.is_file() and p.suffix == ".toml"]
    assert len(files) == 1 + sum(len(lesson.answers) for lesson in LESSONS)
    for path in files:
        relative = path.relative_to(package).as_posix()
        assert any(fnmatch(relative, pattern) and relative.count("/") == pattern.count("/")
                   for pattern in patterns), relative


def test_examples_course_lists_json_and_copies(cli, tmp_path):
    code, out, _ = cli("examples", "--course")
    assert code == 0 and "worked_example_1" in out and "[potential_sign]" in out
    document = json.loads(cli("examples", "--course", "--json").out)
    assert [lesson["name"] for lesson in document["lessons"]] == [x.name for x in LESSONS]
    assert all(Path(a["path"]).is_file() for lesson in document["lessons"]
               for a in lesson["answers"])
    target = tmp_path / "course"
    assert cli("examples", "--course", "--copy", str(target)).code == 0
    code, out, _ = cli("check", str(target / "multipliers" / "model.toml"),
                       str(target / "multipliers" / "answers"))
    assert code == 1 and "multiplier_count" in out and "1 correct, 1 incorrect" in out
    # never over an existing folder's files
    code, _, err = cli("examples", "--course", "--copy", str(target))
    assert code == 2 and err.startswith("error: --copy: ") and "not an empty folder" in err
