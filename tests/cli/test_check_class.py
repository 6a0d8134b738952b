"""`lagrangian check MODEL ANSWERS...`: a class graded in one run (rows, --json records, --csv),
and --hints-only; one answer file keeps today's output and JSON (issue 20)."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

ANSWERS = Path(__file__).parents[1] / "check" / "answers"
RIGHT = '[energy]\nT = "1/2*m*L^2*theta_dot^2"\nV = "-m*g*L*cos(theta)"\n'
WRONG = '[energy]\nT = "1/2*m*L^2*theta_dot^2"\nV = "m*g*L*cos(theta)"\n'


@pytest.fixture
def klass(tmp_path):
    folder = tmp_path / "answers"
    folder.mkdir()
    (folder / "a.toml").write_text(RIGHT)
    (folder / "b.toml").write_text(WRONG)
    return folder


def test_one_file_keeps_todays_json_and_text(cli):
    code, out, _ = cli("check", "pendulum", str(ANSWERS / "pendulum_wrong_potential.toml"),
                       "--json")
    assert code == 1 and set(json.loads(out)) == {"verdict", "findings"}
    code, out, _ = cli("check", "pendulum", str(ANSWERS / "pendulum_wrong_potential.toml"))
    assert out.startswith("Checking ") and out.rstrip().endswith("verdict: incorrect")


def test_a_class_prints_one_row_per_file(cli, klass):
    code, out, err = cli("check", "pendulum", str(klass))
    assert code == 1 and err == ""
    lines = out.splitlines()
    assert lines[0] == "Checking 2 answer file(s) against Simple pendulum"
    assert "a.toml" in lines[1] and " correct " in lines[1] and "all 2 item(s) ok" in lines[1]
    assert "b.toml" in lines[2] and "incorrect" in lines[2] and "V: potential_sign" in lines[2]
    assert lines[-1] == "1 correct, 1 incorrect, 0 unreadable"


def test_all_correct_exits_0_and_files_globs_mix(cli, klass):
    (klass / "c.toml").write_text(RIGHT)
    code, out, _ = cli("check", "pendulum", str(klass / "a.toml"), str(klass / "[c]*.toml"))
    assert code == 0 and out.count(".toml") == 2


def test_unreadable_files_are_records_never_a_crash_or_empty_json(cli, klass):
    (klass / "bad.toml").write_text('[energy]\nV = "__import__(\'os\')"\n')
    code, out, err = cli("check", "pendulum", str(klass), str(klass / "missing.toml"), "--json")
    assert code == 2 and "Traceback" not in err
    document = json.loads(out)
    assert document["counts"] == {"correct": 1, "incorrect": 1, "unreadable": 2}
    errors = [r for r in document["records"] if r["verdict"] == "unreadable"]
    assert [Path(r["file"]).name for r in errors] == ["bad.toml", "missing.toml"]
    assert "energy.V" in errors[0]["error"] and "no such file" in errors[1]["error"]
    assert all(set(r) == {"file", "verdict", "item", "status", "code", "message", "expected",
                          "error"} for r in document["records"])


def test_a_folder_without_answers_is_a_record(cli, tmp_path):
    code, out, _ = cli("check", "pendulum", str(tmp_path), "--json")
    assert code == 2
    (record,) = json.loads(out)["records"]
    assert "no answer files" in record["error"]


def test_csv_is_written_and_read_back(cli, klass, tmp_path):
    table = tmp_path / "grades.csv"
    code, _, _ = cli("check", "pendulum", str(klass), "--csv", str(table))
    assert code == 1
    rows = list(csv.DictReader(table.open()))
    assert [(Path(r["file"]).name, r["item"], r["code"]) for r in rows] == [
        ("a.toml", "T", ""), ("a.toml", "V", ""), ("b.toml", "T", ""),
        ("b.toml", "V", "potential_sign")]
    # a CSV that check wrote is replaced by the next run
    (klass / "b.toml").write_text(RIGHT)
    assert cli("check", "pendulum", str(klass), "--csv", str(table)).code == 0
    assert "potential_sign" not in table.read_text()


@pytest.mark.parametrize("target", ["folder", "notes", "answer"])
def test_csv_refuses_a_folder_a_foreign_file_and_an_input(cli, klass, tmp_path, target):
    notes = tmp_path / "notes.csv"
    notes.write_text("name,mark\nada,10\n")
    path = {"folder": tmp_path, "notes": notes, "answer": klass / "a.toml"}[target]
    before = path.read_text() if path.is_file() else None
    code, out, err = cli("check", "pendulum", str(klass), "--csv", str(path))
    assert code == 2 and out == "" and err.startswith("error: --csv: ")
    assert err.count("\n") == 1 and "Traceback" not in err
    if before is not None:
        assert path.read_text() == before


def test_hints_only_show_no_expected_expression(cli):
    """The module's misconceptions with hints only: the diagnostic question, and none of the
    expected expressions that the full report prints."""
    for model, answer, question in [
            ("pendulum", "pendulum_wrong_potential.toml", "Does V increase as the body rises?"),
            ("virtual_work_link", "link_missing_force.toml",
             "Did I do virtual work for every non-potential load?"),
            ("pendulum", "pendulum_rod_tension.toml", "Do ideal reactions do any virtual work?"),
            ("cartesian_pendulum", "cartesian_pendulum_two_multipliers.toml",
             "Is there one λ per constraint?")]:
        full = json.loads(cli("check", model, str(ANSWERS / answer), "--json").out)
        expected = [f["expected"] for f in full["findings"] if f["expected"]]
        text = cli("check", model, str(ANSWERS / answer), "--hints-only").out
        document = cli("check", model, str(ANSWERS / answer), "--hints-only", "--json").out
        assert expected and question in text
        for shown in (text, document):
            assert "expected:" not in shown
            assert not any(e in shown for e in expected), (answer, expected)
        assert all(f["expected"] is None for f in json.loads(document)["findings"])


def test_one_unreadable_file_under_json_is_a_document_and_an_error_line(cli, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[energy]\nW = "m"\n')
    code, out, err = cli("check", "pendulum", str(bad), "--json")
    assert code == 2 and err.startswith("error: ") and err.count("\n") == 1
    document = json.loads(out)
    assert document["verdict"] == "unreadable" and document["findings"] == []
    assert "unknown key 'W'" in document["error"] and "bad.toml" in document["error"]
    code, out, _ = cli("check", "pendulum", str(bad))  # text: today's error line only
    assert code == 2 and out == ""


def test_a_class_with_hints_only_prints_each_question_under_its_row(cli, klass):
    code, out, _ = cli("check", "pendulum", str(klass), "--hints-only")
    assert code == 1 and "(hints only)" in out.splitlines()[0]
    assert "      V: Does V increase as the body rises?" in out
    assert "cos(theta)" not in out  # neither the expected V nor any term of it


def test_one_file_with_csv_writes_its_records(cli, klass, tmp_path):
    table = tmp_path / "one.csv"
    code, out, _ = cli("check", "pendulum", str(klass / "b.toml"), "--csv", str(table))
    assert code == 1 and out.startswith("Checking ")  # today's text, and the table beside it
    rows = list(csv.DictReader(table.open()))
    assert [r["code"] for r in rows] == ["", "potential_sign"]
