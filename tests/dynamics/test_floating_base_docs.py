"""docs/floating-base.md: its Python example runs and prints what its comments say, and its
command gives the forward dynamics of the Python API, under which the free-falling robot's
centre of mass stays still (no external force: Newton for the whole robot)."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from tests.docs_blocks import block, block_file

import lagrangian

pytest.importorskip("yourdfpy")


def test_python_example_runs(capsys):
    code = re.findall(r"```python\n(.*?)```", block("floating-base"), re.S)[0]
    exec(compile(code, str(block_file("floating-base")), "exec"), {})
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "9 8"
    assert np.array(lines[1].strip("[]").split(), dtype=float).tolist() == [0, 0, 0]
    assert lines[2] == "1.0"


def test_command_gives_the_forward_dynamics_of_a_free_robot(cli):
    command = re.findall(r"\$ lagrangian (.*)", block("floating-base"))[0].split()
    result = cli(*command)
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert (document["nq"], document["nv"]) == (9, 8)
    assert document["velocities"][:6] == ["base_vx", "base_vy", "base_vz", "base_wx", "base_wy",
                                          "base_wz"]
    accel = np.array(document["forward_dynamics"])
    robot = lagrangian.load("two_link_arm", floating_base=True, gravity=(0, 0, 0),
                            payload={"base": (50.0, (-0.2, 0.1, 0.0))}).dynamics()
    q = np.array(document["q"])
    np.testing.assert_allclose(accel, robot.forward_dynamics(q, np.zeros(8), document["tau"]),
                               atol=1e-12)
    np.testing.assert_allclose(robot.center_of_mass_jacobian(q) @ accel, 0, atol=1e-12)
    assert abs(accel[6]) > 1  # the shoulder does turn


def test_simulate_example_falls_at_g(capsys):
    """The simulate example: from rest the centre of mass falls g t^2 / 2, |quaternion| = 1."""
    code = re.findall(r"```python\n(.*?)```", block("floating-base-simulate"), re.S)[0]
    exec(compile(code, str(block_file("floating-base")), "exec"), {})
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "(11, 9) (11, 8)"
    assert float(lines[1]) == pytest.approx(-0.5 * 9.81 * 0.25, abs=1e-6)
    assert float(lines[2]) == 0.0
    assert lines[3] == "(11, 9)"  # a controller's joint torques on the floating base


def test_simulate_command_runs(cli):
    command = re.findall(r"\$ lagrangian (.*)", block("floating-base-simulate"))[0].split()
    result = cli(*command)
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["status"] == "finished"
    assert abs(document["final_state"]["base_qw"] ** 2 + document["final_state"]["base_qx"] ** 2
               + document["final_state"]["base_qy"] ** 2
               + document["final_state"]["base_qz"] ** 2 - 1) < 1e-12


def test_the_planar_base_example_runs(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code = re.findall(r"```python\n(.*?)```", block("planar-base"), re.S)[0]
    exec(compile(code, str(block_file("planar-base")), "exec"), {})
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "('drive_x', 'drive_y', 'drive_theta', 'shaft')"
    assert np.array(lines[1].strip("[]").split(), dtype=float).tolist() == [0, 0]
    assert lines[2] == "True"
