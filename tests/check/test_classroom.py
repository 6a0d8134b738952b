"""Grading a class (issue 20): many answer files against one model, derived once; an unreadable
file is a result with its error; hints instead of answers."""

from __future__ import annotations

import csv
import io
import json

import pytest
from check_helpers import ANSWERS, system

from lagrangian.check.classroom import RECORD_KEYS, answer_files
from lagrangian.check.hints import HINTS

# The double pendulum, as a student writes it by hand (absolute angles from the downward
# vertical): T and V, and both equations of motion.
T = ("1/2*(m1 + m2)*l1^2*theta1_dot^2 + m2*l1*l2*theta1_dot*theta2_dot*cos(theta1 - theta2)"
     " + 1/2*m2*l2^2*theta2_dot^2")
V = "-(m1 + m2)*g*l1*cos(theta1) - m2*g*l2*cos(theta2)"
EQ1 = ("(m1 + m2)*l1^2*theta1_ddot + m2*l1*l2*theta2_ddot*cos(theta1 - theta2)"
       " + m2*l1*l2*theta2_dot^2*sin(theta1 - theta2) + (m1 + m2)*g*l1*sin(theta1) = 0")
EQ2 = ("m2*l2^2*theta2_ddot + m2*l1*l2*theta1_ddot*cos(theta1 - theta2)"
       " - m2*l1*l2*theta1_dot^2*sin(theta1 - theta2) + m2*g*l2*sin(theta2) = 0")
FLIPPED_V = "(m1 + m2)*g*l1*cos(theta1) + m2*g*l2*cos(theta2)"  # V positive downward


def answer(V_text: str = V) -> str:
    return (f'[energy]\nT = "{T}"\nV = "{V_text}"\n'
            f'[equations]\ntheta1 = "{EQ1}"\ntheta2 = "{EQ2}"\n')


@pytest.fixture
def klass(tmp_path):
    folder = tmp_path / "class"
    folder.mkdir()
    (folder / "ada.toml").write_text(answer())
    (folder / "bob.toml").write_text(answer(FLIPPED_V))
    (folder / "cy.toml").write_text("[energy]\nV = \n")  # not TOML
    (folder / "notes.txt").write_text("not an answer")
    (folder / ".hidden.toml").write_text("[energy]\nV = 1\n")
    return folder


def test_a_folder_is_graded_one_result_per_answer_file(klass):
    report = system("double_pendulum").check_many(klass)
    assert [r.file.rsplit("/", 1)[-1] for r in report] == ["ada.toml", "bob.toml", "cy.toml"]
    assert [r.verdict for r in report] == ["correct", "incorrect", "unreadable"]
    assert report.counts == {"correct": 1, "incorrect": 1, "unreadable": 1}
    assert report.exit_status == 2 and not report.passed
    bob = report.results[1].report
    assert bob.codes() == ["potential_sign"]  # V of both bobs flipped: the seed's sign error
    assert "cy.toml" in report.results[2].error and "invalid TOML" in report.results[2].error


def test_records_one_per_file_per_item_and_the_error_of_an_unreadable_file(klass):
    records = system("double_pendulum").check_many(klass).records()
    assert all(tuple(r) == RECORD_KEYS for r in records)
    by_file = {}
    for r in records:
        by_file.setdefault(r["file"].rsplit("/", 1)[-1], []).append(r)
    assert [r["item"] for r in by_file["ada.toml"]] == ["T", "V", "equation[theta1]",
                                                         "equation[theta2]"]
    (cy,) = by_file["cy.toml"]
    assert cy["verdict"] == "unreadable" and cy["item"] is None and "invalid TOML" in cy["error"]
    v = next(r for r in by_file["bob.toml"] if r["item"] == "V")
    assert v["code"] == "potential_sign" and v["expected"]


def test_globs_paths_and_missing_names(klass):
    entries = answer_files([str(klass / "a*.toml"), klass / "bob.toml", klass / "ada.toml",
                            str(klass / "zz*.toml"), klass / "gone.toml"])
    names = [(p.rsplit("/", 1)[-1], error) for p, error in entries]
    assert names[:2] == [("ada.toml", None), ("bob.toml", None)]  # ada.toml once
    assert "no file matches" in names[2][1] and "no such file" in names[3][1]


def test_the_model_file_in_the_answers_folder_is_not_graded(tmp_path):
    from lagrangian.model.examples import example_path

    (tmp_path / "model.toml").write_text(example_path("pendulum").read_text())
    (tmp_path / "mine.toml").write_text('[energy]\nV = "-m*g*L*cos(theta)"\n')
    import lagrangian

    report = lagrangian.load(str(tmp_path / "model.toml")).check_many(tmp_path)
    assert [r.file.rsplit("/", 1)[-1] for r in report] == ["mine.toml"] and report.passed


def test_derived_once_for_the_whole_class(klass, monkeypatch):
    import lagrangian
    from lagrangian.api import system as api

    calls = []
    original = api.derive

    def counting(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)

    monkeypatch.setattr(api, "derive", counting)
    api._derived.cache_clear()  # derivations are cached by content: none yet
    fresh = lagrangian.load("double_pendulum")
    fresh.check_many([klass / "ada.toml", klass / "bob.toml"] * 5)
    assert len(calls) == 1


def test_csv_and_html_escape_what_students_name(tmp_path):
    (tmp_path / "=cmd.toml").write_text('[energy]\nV = "-m*g*L*cos(theta)"\n')
    (tmp_path / "<b>x.toml").write_text('[energy]\nV = "m*g*L*cos(theta)"\n')
    report = system("pendulum").check_many(tmp_path)
    html = report._repr_html_()
    assert "<b>x" not in html and "&lt;b&gt;x.toml" in html
    rows = list(csv.reader(io.StringIO(report.csv_text())))
    assert tuple(rows[0]) == RECORD_KEYS
    assert all(not row[0].startswith("=") for row in rows[1:])  # never run as a formula
    json.dumps(report.records())


def test_hints_only_hide_every_expected_expression():
    """Each of the module's misconceptions, with hints only: its diagnostic question, and no
    expected expression or value anywhere in the finding."""
    cases = [("pendulum", "pendulum_wrong_potential.toml", "potential_sign"),
             ("virtual_work_link", "link_missing_force.toml", "generalized_force_missing"),
             ("pendulum", "pendulum_rod_tension.toml", "reaction_in_minimal_coordinates"),
             ("cartesian_pendulum", "cartesian_pendulum_two_multipliers.toml",
              "multiplier_count"),
             ("virtual_work_link", "link_misprojected.toml", "generalized_force_projection")]
    for model, file, code in cases:
        full = system(model).check(ANSWERS / file)
        hinted = system(model).check(ANSWERS / file, hints_only=True)
        assert code in hinted.codes() and hinted.verdict == full.verdict
        expected = {f.expected for f in full.findings if f.expected}
        assert expected
        for f in hinted.findings:
            assert f.expected is None
            assert not any(e in f.message for e in expected)
        finding = next(f for f in hinted.findings if f.code == code)
        assert HINTS[code].question in finding.message


def test_the_questions_are_the_seed_modules_own():
    from pathlib import Path

    seed = Path("/work/shared/seed")
    if not seed.exists():
        pytest.skip("the seed course module is not on this machine")
    text = "".join(p.read_text(encoding="utf-8") for p in seed.glob("*.txt"))
    for code in ("potential_sign", "generalized_force_missing", "reaction_in_minimal_coordinates",
                 "multiplier_count"):
        assert HINTS[code].question in text and HINTS[code].correction in text
