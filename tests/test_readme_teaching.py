"""The "For students and teachers" section (docs/getting-started/students-and-teachers.md): its
commands run, in order, in a fresh folder, and the output it shows is what they print."""

from __future__ import annotations

import shlex

import pytest

import docs_blocks


def section() -> str:
    return docs_blocks.block("teaching")


def blocks(language: str) -> list[str]:
    """The fenced blocks of ``language`` ("" for plain output), in order."""
    found, current, kind = [], None, None
    for line in section().splitlines(keepends=True):
        if line.startswith("```"):
            if current is None:
                current, kind = [], line[3:].strip()
            else:
                if kind == language:
                    found.append("".join(current))
                current = None
        elif current is not None:
            current.append(line)
    return found


def commands() -> list[list[str]]:
    lines = [line.split("#")[0].strip() for block in blocks("bash") for line in block.splitlines()]
    return [shlex.split(line)[1:] for line in lines if line.startswith("lagrangian ")]


@pytest.fixture
def folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (answer,) = [b for b in blocks("toml") if b.startswith("# mine.toml")]
    (tmp_path / "mine.toml").write_text(answer, encoding="utf-8")
    return tmp_path


def test_every_command_runs_with_its_documented_status(cli, folder):
    statuses = {}
    for arguments in commands():
        result = cli(*arguments)
        assert "Traceback" not in result.err and not result.err.startswith("error:"), arguments
        statuses[" ".join(arguments)] = result.code
    assert statuses == {
        "check pendulum mine.toml --hints-only": 1,      # V positive downward
        "check pendulum mine.toml": 1,
        "crosscheck ladder_pendulum": 0,
        "examples --course --copy course": 0,
        "check pendulum course/worked_example_1/answers --csv grades.csv": 1,
    }
    grades = (folder / "grades.csv").read_text().splitlines()
    assert grades[0] == "file,verdict,item,status,code,message,expected,error"
    assert any(",potential_sign," in row for row in grades)


def test_the_output_shown_is_real(cli, folder):
    shown = [b for b in blocks("") if b.strip()]
    hints, klass = shown
    command, _, printed = hints.partition("\n")
    assert command == "$ lagrangian check pendulum mine.toml --hints-only"
    assert cli(*shlex.split(command)[2:]).out == printed
    cli("examples", "--course", "--copy", "course")
    assert cli("check", "pendulum", "course/worked_example_1/answers").out == klass


def test_the_python_sentence_holds(folder, cli):
    import lagrangian

    cli("examples", "--course", "--copy", "course")
    report = lagrangian.load("pendulum").check_many("course/worked_example_1/answers")
    assert report.counts == {"correct": 1, "incorrect": 2, "unreadable": 0}
    assert "<table>" in report._repr_html_() and report.csv_text().startswith("file,verdict")
