"""`lagrangian check`, `crosscheck` and `units`: exit statuses and the JSON contracts."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

ANSWERS = Path(__file__).parents[1] / "check" / "answers"


def test_check_wrong_potential_exits_1_with_the_contract(cli):
    code, out, _ = cli("check", "pendulum", str(ANSWERS / "pendulum_wrong_potential.toml"),
                       "--json")
    assert code == 1
    document = json.loads(out)
    assert set(document) == {"verdict", "findings"}
    assert document["verdict"] == "incorrect"
    for item in document["findings"]:
        assert set(item) == {"item", "status", "code", "message", "expected"}
        assert item["status"] in {"correct", "equivalent", "wrong", "note"}
    v = next(f for f in document["findings"] if f["item"] == "V")
    assert v["code"] == "potential_sign" and v["expected"] == "-L*g*m*cos(theta)"
    t = next(f for f in document["findings"] if f["item"] == "T")
    assert t["code"] is None and t["expected"] is None


def test_check_correct_answer_exits_0(cli):
    code, out, _ = cli("check", "pendulum", str(ANSWERS / "pendulum_other_datum.toml"))
    assert code == 0
    assert "potential_datum" in out and out.rstrip().endswith("verdict: correct")


def test_check_misprojected_load_text(cli):
    code, out, _ = cli("check", "virtual_work_link", str(ANSWERS / "link_misprojected.toml"))
    assert code == 1
    assert "Q[theta]: WRONG [generalized_force_projection]" in out
    assert "expected: F*L*cos(theta)" in out


@pytest.mark.parametrize(("answer", "message"), [
    ("missing.toml", "no such file"),
    ("unknown_key.toml", "unknown key 'W'"),
])
def test_check_unreadable_answer_exits_2(cli, tmp_path, answer, message):
    (tmp_path / "unknown_key.toml").write_text('[energy]\nW = "m"\n')
    code, out, err = cli("check", "pendulum", str(tmp_path / answer))
    assert code == 2 and out == ""
    assert err.startswith("error: ") and message in err and answer in err
    assert "Traceback" not in err


def test_check_injection_exits_2(cli, tmp_path):
    path = tmp_path / "evil.toml"
    path.write_text("[energy]\nV = \"__import__('os').system('echo hacked')\"\n")
    code, out, err = cli("check", "pendulum", str(path))
    assert code == 2 and "hacked" not in out and "evil.toml: energy.V" in err


def test_check_bad_model_exits_2(cli):
    code, _, err = cli("check", "no_such_model", str(ANSWERS / "pendulum_other_datum.toml"))
    assert code == 2 and "no such file or built-in example" in err


def test_crosscheck_json_contract(cli):
    code, out, _ = cli("crosscheck", "ladder_pendulum", "--json")
    assert code == 0
    document = json.loads(out)
    at_start = document["reactions"][0].pop("at_initial_state")
    assert document == {
        "agree": True,
        "coordinates": {"theta": {"agree": True, "difference": None}},
        "reactions": [{"joint": "bob", "components": [
            "-m*(L*theta_dot**2 + g*cos(theta))*sin(theta)",
            "m*(L*theta_dot**2 + g*cos(theta))*cos(theta)"],
            # added beside the first published keys: what "joint" holds, components by axis
            "body": "bob", "force": {
                "x": "-m*(L*theta_dot**2 + g*cos(theta))*sin(theta)",
                "y": "m*(L*theta_dot**2 + g*cos(theta))*cos(theta)"}}],
    }
    # and its value where the model starts: the rod's pull m (L theta_dot^2 + g cos theta)
    # along the rod toward the pivot
    import math

    import lagrangian

    model = lagrangian.load("ladder_pendulum").model
    p = {q.name: float(q.value) for q in model.parameters}
    theta, rate = float(model.coordinates[0].initial or 0), float(model.coordinates[0].rate or 0)
    pull = p["m"] * (p["L"] * rate**2 + p["g"] * math.cos(theta))
    assert at_start["force"]["x"] == pytest.approx(-pull * math.sin(theta), abs=1e-12)
    assert at_start["force"]["y"] == pytest.approx(pull * math.cos(theta), rel=1e-12)


def test_crosscheck_text_and_refusal(cli):
    code, out, _ = cli("crosscheck", "rolling_disk")
    assert code == 0 and "x: agree" in out and "R_y = sqrt(3)*g*m/2" in out
    code, _, err = cli("crosscheck", "pendulum")
    assert code == 2 and "[energy] T" in err


def test_units_lists_every_inconsistent_term(cli, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("""
[coordinates]
x = "m"
[parameters]
m = { value = 1.0, unit = "kg" }
k = { value = 2.0, unit = "N/m" }
[energy]
T = "1/2*m*x_dot"
V = "1/2*k*x^2 + k*x"
""")
    code, out, _ = cli("units", str(path))
    assert code == 1
    assert "m*x_dot/2" in out and "k*x has" in out and "2 inconsistent term(s)" in out
    code, out, _ = cli("units", str(path), "--json")
    document = json.loads(out)
    assert document["consistent"] is False
    assert [i["term"] for i in document["issues"]] == ["m*x_dot/2", "k*x"]
    code, out, _ = cli("units", "slider_crank")
    assert code == 0 and out.rstrip().endswith("consistent")
