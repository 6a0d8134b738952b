"""`lagrangian statics`, and the other commands on a model without inertia (statics)."""

from __future__ import annotations

import json
import math

import pytest

import lagrangian
from statics_models import SLIDER_CRANK

LINK = """
name = "Worked example 2 as written"
[coordinates]
theta = "rad"
[parameters]
F = { value = 100, unit = "N" }
L = { value = 0.5, unit = "m" }
tau = { value = 0, unit = "N*m" }
[[loads]]
name = "tip_force"
point = ["L*sin(theta)", "L*cos(theta)"]
force = ["F", 0]
[[loads]]
name = "motor"
torque = "tau"
angle = "theta"
"""


@pytest.fixture
def files(tmp_path):
    link, crank = tmp_path / "link.toml", tmp_path / "crank.toml"
    link.write_text(LINK)
    crank.write_text(SLIDER_CRANK)
    return str(link), str(crank)


def test_the_seed_example_2_as_written_gives_43_30_newton_metres(cli, files):
    link, _ = files
    code, out, _ = cli("forces", link, "--at", "theta=30deg")
    assert code == 0
    assert "Q[theta] = 43.3013 N*m" in out
    code, out, _ = cli("derive", link)
    assert code == 0
    assert "[theta]  0 = F*L*cos(theta)" in out


def test_statics_finds_the_motor_torque_that_holds_the_link(cli, files):
    link, _ = files
    code, out, _ = cli("statics", link, "--at", "theta=40deg", "--solve-for", "tau", "--json")
    assert code == 0
    document = json.loads(out)
    # tau + F L cos(theta) = 0
    assert document["solved"]["tau"] == pytest.approx(-100 * 0.5 * math.cos(math.radians(40)))
    assert document["units"] == {"tau": "N*m"}
    shares = {s["source"]: s["value"] for s in document["shares"]}
    assert shares["tip_force"] == pytest.approx(-shares["motor"])


def test_statics_text_names_the_coordinates_found_from_the_constraints(cli, files):
    _, crank = files
    code, out, _ = cli("statics", crank, "--at", "theta=40deg", "--solve-for", "P")
    assert code == 0
    theta = math.radians(40)
    closed = 12.0 / (0.1 * math.sin(theta) * (1 + 0.1 * math.cos(theta)
                                              / math.sqrt(0.09 - 0.01 * math.sin(theta) ** 2)))
    assert f"P = {closed:.6g} N" in out
    assert "from the constraints: phi = " in out


@pytest.mark.parametrize("args, message", [
    (["--at", "theta=40deg", "--solve-for", "G"],
     "error: --solve-for: 'G' is not a parameter of this model; expected one of: F, L, tau\n"),
    (["--at", "theta=40deg"], "error: --solve-for: give at least one parameter to solve for\n"),
    (["--at", "theta=40deg", "--solve-for", "F,tau"],
     "error: --solve-for: too many unknowns: 'F' and 'tau' for 1 equilibrium conditions; solve "
     "for fewer\n"),
    (["--at", "theta=90deg", "--solve-for", "F"],
     "error: --solve-for: 'F' does no virtual work in this configuration (it is not in Q), so "
     "the equilibrium cannot fix it\n"),
    (["--at", "phi=1", "--solve-for", "tau"],
     "error: --at: 'phi' is not a coordinate or t of this model; expected one of: theta, t\n"),
])
def test_bad_statics_requests(cli, files, args, message):
    link, _ = files
    code, out, err = cli("statics", link, *args)
    assert (code, out, err) == (2, "", message)


def test_simulate_and_modes_refuse_a_model_without_inertia(cli, files):
    link, _ = files
    expected = ("needs inertia: the model has no mass, inertia or kinetic energy for 'theta' (a "
                "statics model: derive, forces, equilibria, check and statics work without it)\n")
    assert tuple(cli("simulate", link, "--t-end", "1")) == (2, "", "error: simulate " + expected)
    assert tuple(cli("modes", link)) == (2, "", "error: modes " + expected)


def test_equilibria_of_a_massless_mechanism_judge_stability_by_the_potential(cli, tmp_path):
    path = tmp_path / "spring.toml"
    path.write_text(LINK.replace("[[loads]]\nname = \"motor\"", "[[springs]]\nname = \"torsion\"")
                    .replace('torque = "tau"\nangle = "theta"', 'stiffness = 200\nlength = "theta"'))
    code, out, _ = cli("equilibria", str(path))
    assert code == 0
    # k theta = F L cos(theta): 200 theta = 50 cos(theta)
    system = lagrangian.load(str(path))
    (only,) = system.equilibria()
    theta = only.coordinates["theta"]
    assert 200 * theta == pytest.approx(50 * math.cos(theta), rel=1e-9)
    assert only.stable
    assert "stable" in out


def test_python_statics_method(files):
    _, crank = files
    report = lagrangian.load(crank).statics({"theta": math.radians(75)}, "P")
    assert isinstance(report, lagrangian.StaticsReport)
    assert set(report.reactions) == {"lambda_loop_y", "lambda_loop_x"}
