"""[statics]: the load magnitudes and reactions that hold a mechanism at rest (`statics
--solve-for` in an answer file), against closed forms by virtual work, to the precision written;
a wrong value explained by the slip that reproduces it, in the seed module's words."""

from __future__ import annotations

import math

import pytest

import lagrangian
from lagrangian import ModelError
from lagrangian.cli import main
from statics_models import SLIDER_CRANK

# A uniform link (m, L) pinned at the top, theta from the downward vertical, a torsion spring k
# on the pin, a known pin torque tau and a horizontal tip force F (the unknown):
# delta W = 0:  F L cos(theta) + tau - k theta - m g (L/2) sin(theta) = 0.
HELD = """
name = "Link held by a horizontal tip force"
[coordinates]
theta = { unit = "rad", initial = 0.5 }
[parameters]
m = { value = 2.0, unit = "kg" }
L = { value = 1.0, unit = "m" }
g = { value = 9.81, unit = "m/s^2" }
k = { value = 3.0, unit = "N*m" }
tau = { value = 1.0, unit = "N*m" }
F = { unit = "N" }
[gravity]
g = "g"
direction = [0, -1]
[[bodies]]
name = "link"
mass = "m"
inertia = "m*L^2/12"
position = ["L/2*sin(theta)", "-L/2*cos(theta)"]
angle = "theta"
[[springs]]
name = "coil"
stiffness = "k"
length = "theta"
[[loads]]
name = "pin_torque"
torque = "tau"
angle = "theta"
[[loads]]
name = "push"
point = ["L*sin(theta)", "-L*cos(theta)"]
force = ["F", 0]
"""
THETA = math.radians(30)
WEIGHT = 2.0 * 9.81 * 0.5 * math.sin(THETA)  # m g L/2 sin(theta), N m
SPRING = 3.0 * THETA


def force(weight=WEIGHT, spring=SPRING, torque=1.0) -> float:
    return (weight + spring - torque) / (1.0 * math.cos(THETA))


@pytest.fixture(scope="module")
def held(tmp_path_factory):
    path = tmp_path_factory.mktemp("statics") / "held.toml"
    path.write_text(HELD)
    return lagrangian.load(path)


@pytest.fixture(scope="module")
def crank(tmp_path_factory):
    path = tmp_path_factory.mktemp("statics") / "crank.toml"
    path.write_text(SLIDER_CRANK)
    return lagrangian.load(path)


def statics(system, value: str, **more: str):
    return system.check({"statics": {"at": {"theta": "30deg"}, "F": value, **more}})


def test_the_load_that_holds_the_link_is_accepted_to_the_figures_written(held):
    assert force() == pytest.approx(6.32290, abs=1e-5)  # the closed form
    (finding,) = statics(held, "6.323 N").findings
    assert finding.item == "statics.F" and finding.status == "correct"
    assert "4 significant figures" in finding.message and "30 deg" in finding.message
    assert statics(held, "6.3 N").verdict == "correct"
    assert statics(held, "6.33 N").verdict == "incorrect"
    assert statics(held, "0.006323 kN").verdict == "correct"  # any unit of force


@pytest.mark.parametrize(("value", "code", "words"), [
    (-force(), "statics_load", "opposite sign"),
    (force(torque=0.0), "statics_load", "without the load 'pin_torque' (tau = 0)"),
    (force(weight=0.0), "statics_potential", "without the weights (g = 0)"),
    (force(weight=-WEIGHT), "statics_potential", "potential -m g h of the wrong sign"),
    (force(spring=0.0), "statics_potential", "without the spring 'coil' (k = 0)"),
    (force(torque=-1.0), "statics_load", "the load 'pin_torque' of the wrong sign"),
    (1.0, "statics_value", "delta W = 0 for every admissible delta q"),
])
def test_a_wrong_load_is_explained_by_the_slip_that_gives_it(held, value, code, words):
    (finding,) = statics(held, f"{value:.4g} N").findings
    assert finding.code == code, finding
    assert words in finding.message
    assert finding.expected == "6.3229 N"
    seed = {"statics_load": "Did I do virtual work for every non-potential load?",
            "statics_potential": "Does V increase as the body rises?"}
    assert seed.get(code, "delta W") in finding.message


def test_hints_only_gives_the_seed_question_without_the_value(held):
    report = held.check({"statics": {"at": {"theta": "30deg"}, "F": f"{force(weight=0):.4g} N"}},
                        hints_only=True)
    (finding,) = report.findings
    assert finding.message.startswith("Does V increase as the body rises?")
    assert finding.expected is None and "6.32" not in finding.message


def test_slider_crank_piston_force_and_reactions(crank):
    # P = tau / (r sin(theta) (1 + r cos(theta) / sqrt(l^2 - r^2 sin^2(theta)))); the x
    # equation lambda_loop_x = P, the phi equation lambda_loop_y = lambda_loop_x tan(phi).
    r, l, tau, theta = 0.1, 0.3, 12.0, math.radians(40)
    p = tau / (r * math.sin(theta) * (1 + r * math.cos(theta)
                                      / math.sqrt(l**2 - (r * math.sin(theta))**2)))
    phi = math.asin(r * math.sin(theta) / l)
    answer = {"statics": {"at": {"theta": "40deg"}, "P": f"{p:.1f} N",  # 148.0: 4 figures
                          "lambda_loop_x": f"{p:.1f}",
                          "lambda_loop_y": f"{p * math.tan(phi):.2f}"}}
    report = crank.check(answer)
    assert report.verdict == "correct", report
    assert "from the constraints" in report.findings[0].message
    answer["statics"]["lambda_loop_y"] = f"{-p * math.tan(phi):.2f}"
    findings = {f.item: f for f in crank.check(answer).findings}
    assert findings["statics.lambda_loop_y"].code == "statics_load"  # the opposite sign
    assert findings["statics.lambda_loop_x"].status == "correct"


@pytest.mark.parametrize(("table", "field", "words"), [
    ({"F": "6 N"}, "statics.at", "give the configuration"),
    ({"at": {"theta": "30deg"}}, "statics", "give each load magnitude"),
    ({"at": {"theta": "30deg"}, "f": "6 N"}, "statics.f", "did you mean"),
    ({"at": {"theta": "30deg"}, "F": "6 m"}, "statics.F", "not in units compatible"),
    ({"at": {"theta": "30deg"}, "F": "6 N", "k": "3 N*m"}, "statics", "too many unknowns"),
])
def test_a_malformed_statics_table_is_refused_naming_the_field(held, table, field, words):
    with pytest.raises(ModelError) as error:
        held.check({"statics": table})
    assert error.value.field == field and words in str(error.value).lower() or \
        words in str(error.value), str(error.value)
    assert "\n" not in str(error.value)


def test_check_cli_reads_a_statics_table_and_exits_with_its_verdict(tmp_path, capsys):
    (tmp_path / "held.toml").write_text(HELD)
    (tmp_path / "answer.toml").write_text('[statics]\nat = { theta = "30deg" }\nF = "6.32 N"\n')
    with pytest.raises(SystemExit) as stop:
        main(["check", str(tmp_path / "held.toml"), str(tmp_path / "answer.toml"), "--json"])
    assert stop.value.code == 0
    assert '"item": "statics.F"' in capsys.readouterr().out
    (tmp_path / "answer.toml").write_text('[statics]\nat = { theta = "30deg" }\nG = "6.32 N"\n')
    with pytest.raises(SystemExit) as stop:
        main(["check", str(tmp_path / "held.toml"), str(tmp_path / "answer.toml")])
    assert stop.value.code == 2
    assert "statics.G" in capsys.readouterr().err
