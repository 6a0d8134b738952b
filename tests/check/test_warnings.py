"""Warnings where a user is probably wrong (issue 21): one line each on stderr after a success
and under `warnings` in the JSON; never on a refusal, which stays one `error:` line."""

from __future__ import annotations

import json

import pytest

import lagrangian

PENDULUM = """
[coordinates]
theta = {{ unit = "rad", initial = 0.3 }}
[parameters]
m = {{ value = 1.0, unit = "kg" }}
L = {{ value = 0.5, unit = "m" }}
g = {{ value = 9.81, unit = "{g_unit}" }}
c = {{ value = 2.0, unit = "N" }}
{gravity}
[[particles]]
name = "bob"
mass = "m"
position = ["L*sin(theta)", "-L*cos(theta)"]
"""


def model(tmp_path, g_unit="m/s^2", gravity=True):
    path = tmp_path / "pendulum.toml"
    path.write_text(PENDULUM.format(g_unit=g_unit,
                                    gravity='[gravity]\ng = "g"\n' if gravity else ""))
    return path


def warnings_of(result) -> list[str]:
    return [line[len("warning: "):] for line in result.err.splitlines()
            if line.startswith("warning: ")]


def test_a_correct_model_has_no_warning(cli, tmp_path):
    result = cli("modes", str(model(tmp_path)), "--json")
    assert result.code == 0 and result.err == ""
    assert "warnings" not in json.loads(result.out)


def test_g_declared_without_gravity(cli, tmp_path):
    """V = 0 then: the pendulum has no restoring force, so its one mode has zero frequency."""
    result = cli("modes", str(model(tmp_path, gravity=False)), "--json")
    assert result.code == 0
    (line,) = warnings_of(result)
    assert line.startswith("parameter 'g' is declared but the model has no [gravity]")
    document = json.loads(result.out)
    assert document["warnings"] == [line]
    assert document["modes"][0]["frequency"] == 0


def test_g_in_the_wrong_unit_is_said_by_every_command(cli, tmp_path):
    path = model(tmp_path, g_unit="m/s")
    for command in (["derive"], ["modes"], ["simulate", "--t-end", "0.1"], ["equilibria"]):
        result = cli(*command, str(path))
        assert result.code == 0, result.err
        assert any(line.startswith("units: gravity.g") for line in warnings_of(result)), \
            (command, result.err)


def test_a_parameter_no_equation_contains_given_a_value(cli, tmp_path):
    result = cli("derive", str(model(tmp_path)), "--set", "c=3", "--json")
    assert result.code == 0
    assert warnings_of(result) == ["'c' is set but appears in no equation of motion: its "
                                   "value changes nothing"]
    assert json.loads(result.out)["warnings"] == warnings_of(result)
    assert cli("derive", str(model(tmp_path)), "--set", "m=3").err == ""


@pytest.mark.parametrize("value, warned", [("30", True), ("-7", True), ("6", False),
                                           ("30deg", False), ("pi/2", False)])
def test_a_bare_angle_beyond_a_turn(cli, value, warned):
    result = cli("forces", "pendulum", "--at", f"theta={value}")
    assert result.code == 0, result.err
    lines = warnings_of(result)
    if warned:
        assert lines == [f"--at theta={value} is read as {value} rad "
                         f"({float(value) * 57.29577951308232:.6g} deg); write {value}deg for "
                         "degrees"]
    else:
        assert lines == []


def test_a_refusal_stays_one_line_with_its_warnings_dropped(cli, tmp_path):
    result = cli("modes", str(model(tmp_path, gravity=False)), "--about", "nope=1")
    assert result.code == 2 and result.err.count("\n") == 1 and result.err.startswith("error: ")


def test_the_python_api_says_the_same():
    pendulum = lagrangian.load("pendulum")
    assert pendulum.warnings() == []
    assert pendulum.warnings(set_parameters={"m": 2.0}) == []


@pytest.mark.parametrize("command", [("dynamics", "pendulum", "--q", "30"),
                                     ("dynamics", "cart_pendulum", "--q", "0.1,30", "--json")])
def test_a_bare_angle_in_a_list_of_coordinates(cli, command):
    """--q lists the coordinates in order: the angle is named (cart_pendulum: x, theta)."""
    result = cli(*command)
    assert result.code == 0, result.err
    assert warnings_of(result) == ["--q theta=30 is read as 30 rad (1718.87 deg); write 30deg "
                                   "for degrees"]
    assert cli("dynamics", "cart_pendulum", "--q", "30,30deg").err == ""  # x = 30 m is a length


INCLINE = """
[coordinates]
s = { unit = "m" }
[parameters]
m = { value = 1.0, unit = "kg" }
a = { value = 9.81, unit = "m/s^2" }
alpha = { value = 0.3, unit = "rad" }
c = { value = 0.1, unit = "N*s" }
Omega = { value = 5.0, unit = "rad/s" }
[energy]
T = "m*s_dot^2/2"
V = "m*a*sin(alpha)*s + c*Omega*s"
"""


def test_a_bare_angle_parameter_beyond_a_turn(cli, tmp_path):
    path = tmp_path / "incline.toml"
    path.write_text(INCLINE)
    result = cli("derive", str(path), "--set", "alpha=30,Omega=30")  # a rate is no angle
    assert result.code == 0, result.err
    assert warnings_of(result) == ["--set alpha=30 is read as 30 rad (1718.87 deg); write 30deg "
                                   "for degrees"]
    assert cli("derive", str(path), "--set", "alpha=30deg").err == ""
