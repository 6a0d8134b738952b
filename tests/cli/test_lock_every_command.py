"""`--lock NAME=VALUE` on every command that takes a model: the URDF joint is frozen (one
coordinate fewer), an unknown joint or a model without joints is one line, exit 2; `units`
passes on a URDF robot (its numbers are SI by the format)."""

from __future__ import annotations

import json

import pytest


def test_simulate_with_a_locked_elbow(cli):
    code, out, err = cli("simulate", "two_link_arm", "--t-end", "0.1", "--lock", "elbow=0.1")
    assert code == 0, err
    assert "shoulder =" in out and "elbow =" not in out


def test_derive_with_a_locked_elbow_has_one_coordinate(cli):
    code, out, err = cli("derive", "two_link_arm", "--lock", "elbow=30deg", "--json")
    assert code == 0, err
    document = json.loads(out)
    assert document["coordinates"] == ["shoulder"]


@pytest.mark.parametrize("command", [
    ("units",), ("equilibria",), ("forces", "--at", "shoulder=0.1"), ("modes",),
    ("crosscheck",), ("statics", "--at", "shoulder=0.1", "--solve-for", "tau_shoulder"),
])
def test_commands_accept_lock(cli, command):
    code, out, err = cli(command[0], "two_link_arm", *command[1:], "--lock", "elbow=0.2")
    assert code in (0, 1), err  # 1: a report that did not pass, never a usage error
    assert "elbow_dot" not in out  # the locked joint is no coordinate


def test_units_of_a_urdf_robot_are_consistent(cli):
    code, out, err = cli("units", "two_link_arm")
    assert code == 0, err
    assert "consistent" in out


@pytest.mark.parametrize("command", [("derive",), ("units",), ("modes",), ("equilibria",),
                                     ("simulate", "--t-end", "0.1")])
def test_bad_lock_is_one_line(cli, command):
    code, _, err = cli(*command, "two_link_arm", "--lock", "elbw=0.1")
    assert code == 2
    assert err.strip().count("\n") == 0 and "did you mean 'elbow'" in err
    code, _, err = cli(*command, "pendulum", "--lock", "x=1")
    assert code == 2 and "only a URDF model has joints to lock" in err
