"""simulate on a floating base stops as on a fixed one: ``stop_when`` (which may name the base's
numbers) where the condition turns true, located on the step's dense output, and a joint's URDF
position limit with status 'limit'; checked by free fall (z = -g t^2 / 2) and by the joint's
angle at the stop, through the API and the CLI."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from tests.docs_blocks import block, block_file

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.kinds import RunStatus

pytest.importorskip("yourdfpy")

# a trunk and a one-joint leg; the hip limited to +-0.5 rad
URDF = """<?xml version="1.0"?>
<robot name="hopper">
  <link name="trunk"><inertial><origin xyz="0.02 -0.01 0.05"/><mass value="3.0"/>
    <inertia ixx="0.05" ixy="0.002" ixz="-0.001" iyy="0.07" iyz="0.003" izz="0.06"/></inertial></link>
  <link name="thigh"><inertial><origin xyz="0 0 -0.15"/><mass value="0.8"/>
    <inertia ixx="0.006" ixy="0" ixz="0.0004" iyy="0.006" iyz="0" izz="0.001"/></inertial></link>
  <joint name="hip" type="revolute"><parent link="trunk"/><child link="thigh"/>
    <origin xyz="0.1 0.05 -0.05"/><axis xyz="0 1 0"/>
    <limit lower="-0.5" upper="0.5" effort="1" velocity="100"/></joint>
</robot>
"""


@pytest.fixture(scope="module")
def path(tmp_path_factory):
    target = tmp_path_factory.mktemp("hopper") / "hopper.urdf"
    target.write_text(URDF)
    return target


def test_free_fall_stops_when_the_base_reaches_a_height(path):
    """From rest, every body falls at g (no internal force): base_z < -h turns true at
    t = sqrt(2 h / g), to the event's tolerance."""
    robot = lagrangian.load(path, floating_base=True)
    g, h = robot.parameters["g"], 0.3
    run = robot.simulate(1.0, stop_when=f"base_z < -{h}", samples=101)
    assert run.status == RunStatus.STOPPED
    assert run.t[-1] == pytest.approx(np.sqrt(2 * h / g), abs=1e-9)
    assert run.q[-1, 2] == pytest.approx(-h, abs=1e-9)
    assert run.summary()["stop_when"] == f"base_z < -{h}"
    # a velocity of the base and a joint's name in one condition: base_vz = -g t in base axes
    both = robot.simulate(1.0, stop_when="base_vz + 0*hip < -2", samples=11)
    assert both.t[-1] == pytest.approx(2 / g, abs=1e-9)


def test_a_joint_limit_stops_a_floating_robot(path):
    """The hip swung towards +0.5 rad in free fall: status 'limit' where it reaches it (the
    base turns back as it swings, so not at t = 0.5 / rate), as on a fixed base; with
    limits=False the joint runs through."""
    robot = lagrangian.load(path, floating_base=True)
    run = robot.simulate(2.0, initial={"hip_dot": 2.0}, samples=101)
    assert run.status == RunStatus.LIMIT
    assert run.q[-1, 7] == pytest.approx(0.5, abs=1e-9)
    assert run.message.startswith("joint 'hip' (hip) reached its position limit 0.5 rad at t =")
    assert np.all(run.q[:-1, 7] < 0.5)
    free = robot.simulate(2.0, initial={"hip_dot": 2.0}, samples=11, limits=False)
    assert free.status == RunStatus.FINISHED and free.q[-1, 7] > 0.5
    # the condition first: it wins where it turns true before the limit
    early = robot.simulate(2.0, initial={"hip_dot": 2.0}, samples=11, stop_when="hip > 0.2")
    assert early.status == RunStatus.STOPPED and early.q[-1, 7] == pytest.approx(0.2, abs=1e-9)


def test_an_unknown_name_is_one_line(path):
    """As on a fixed base (the condition's grammar is the model's), the base's names known."""
    robot = lagrangian.load(path, floating_base=True)
    with pytest.raises(ModelError, match="stop_when: unknown name 'base_height'") as info:
        robot.simulate(1.0, stop_when="base_height < 0")
    assert "\n" not in str(info.value)


def test_the_command_stops_at_the_height(cli, path):
    result = cli("simulate", str(path), "--floating-base", "--t-end", "1",
                 "--stop-when", "base_z < -0.3", "--samples", "11", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["status"] == "stopped" and document["stop_when"] == "base_z < -0.3"
    g = lagrangian.load(path, floating_base=True).parameters["g"]
    assert document["final_state"]["base_z"] == pytest.approx(-0.3, abs=1e-9)
    assert document["t_final"] == pytest.approx(np.sqrt(0.6 / g), abs=1e-9)
    bad = cli("simulate", str(path), "--floating-base", "--t-end", "1",
              "--stop-when", "base_height < 0")
    assert bad.code == 2 and bad.err.startswith("error:") and "base_height" in bad.err
    assert "Traceback" not in bad.err


def test_docs_example_runs(capsys):
    """docs/floating-base.md: the fall stops at sqrt(2 h / g), the swing at the limit."""
    code = re.findall(r"```python\n(.*?)```", block("floating-base-stop"), re.S)[0]
    exec(compile(code, str(block_file("floating-base-stop")), "exec"), {})
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == f"stopped {np.sqrt(2 * 0.3 / 9.81):.4f}" == "stopped 0.2473"
    assert lines[1] == "limit 3.1"


def test_docs_command_runs(cli):
    command = re.findall(r"\$ lagrangian (.*)", block("floating-base-stop"))[0]
    result = cli(*[part.strip('"') for part in re.findall(r'"[^"]*"|\S+', command)])
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["status"] == "stopped"
    assert document["t_final"] == pytest.approx(np.sqrt(2 * 0.3 / 9.81), abs=1e-9)
