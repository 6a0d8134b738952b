"""`dynamics --q` beyond a URDF position limit (issue 27): one `warning:` line naming the file's
joint and its limit; within the limits, or a joint without one (continuous), nothing."""

from __future__ import annotations

import json

import pytest

import lagrangian

pytest.importorskip("yourdfpy")

ROBOT = """<?xml version="1.0"?>
<robot name="limited">
  <link name="base"/>
  <link name="rod"><inertial><origin xyz="0.5 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="tip"><inertial><mass value="0.5"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <link name="wheel"><inertial><mass value="0.2"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.002"/></inertial></link>
  <joint name="hinge.1" type="revolute"><parent link="base"/><child link="rod"/>
    <axis xyz="0 -1 0"/><limit lower="-1.5" upper="2" effort="5" velocity="2"/></joint>
  <joint name="slide" type="prismatic"><parent link="rod"/><child link="tip"/>
    <origin xyz="0.5 0 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.5" effort="5" velocity="1"/>
  </joint>
  <joint name="spin" type="continuous"><parent link="tip"/><child link="wheel"/>
    <axis xyz="0 0 1"/></joint>
</robot>
"""


@pytest.fixture
def robot(tmp_path):
    path = tmp_path / "limited.urdf"
    path.write_text(ROBOT)
    return path


def warnings_of(result):
    return [line for line in result.err.splitlines() if line.startswith("warning: ")]


def test_the_api_reads_the_limits(robot):
    system = lagrangian.load(robot)
    assert system.joint_limits == {"hinge_1": (-1.5, 2.0), "slide": (0.0, 0.5)}  # spin: none
    assert lagrangian.load("pendulum").joint_limits == {}


@pytest.mark.parametrize("q, joint, words", [
    ("2.5,0.1,0", "hinge.1", ["hinge_1=2.5 rad", "[-1.5, 2] rad"]),
    ("0.3,-0.1,0", "slide", ["slide=-0.1 m", "[0, 0.5] m"]),
])
def test_beyond_a_limit_is_one_warning_line(cli, robot, q, joint, words):
    result = cli("dynamics", str(robot), "--q", q)
    assert result.code == 0, result.err
    (line,) = warnings_of(result)
    assert f"URDF joint '{joint}'" in line and "position limit" in line
    for word in words:
        assert word in line


def test_within_the_limits_and_a_continuous_joint_warn_of_nothing(cli, robot):
    result = cli("dynamics", str(robot), "--q", "2,0.5,5")  # on the limits; spin has none
    assert result.code == 0 and warnings_of(result) == []


def test_each_joint_beyond_its_limit_and_the_json(cli, robot):
    result = cli("dynamics", str(robot), "--q", "-2,0.9,0", "--json")
    assert result.code == 0, result.err
    assert len(warnings_of(result)) == 2
    document = json.loads(result.out)
    assert [w for w in document["warnings"] if "hinge.1" in w] and \
        [w for w in document["warnings"] if "slide" in w]
