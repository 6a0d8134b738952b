"""A URDF's joint names and the model's coordinate names (issue 27): joint names are made
identifiers ("joint_8.0" -> "joint_8_0"), and System.joint_names / System.coordinate_names map
one to the other, in the API, `dynamics --json` and `examples --show`."""

from __future__ import annotations

import json

import numpy as np
import pytest

import lagrangian

pytest.importorskip("yourdfpy")

LINK = """<link name="{0}"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
  <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>"""
JOINT = """<joint name="{0}" type="revolute"><parent link="{1}"/><child link="{2}"/>
  <origin xyz="0.4 0 0"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>"""
ODD = ("<?xml version='1.0'?><robot name='odd'><link name='base'/>"
       + "".join(LINK.format(n) for n in ("l1", "l2", "l3", "l4"))
       + JOINT.format("joint_8.0", "base", "l1") + JOINT.format("joint_8_0", "l1", "l2")
       + JOINT.format("elbow-1", "l2", "l3") + JOINT.format("g", "l3", "l4")
       + "</robot>")


@pytest.fixture
def odd(tmp_path):
    path = tmp_path / "odd.urdf"
    path.write_text(ODD)
    return path


def test_each_coordinate_names_its_joint_and_back(odd):
    system = lagrangian.load(odd)
    names = system.joint_names
    assert list(names.values()) == ["joint_8.0", "joint_8_0", "elbow-1", "g"]
    assert list(names) == [c.name for c in system.model.coordinates]  # the model's order
    # identifiers, "joint_8.0" and "joint_8_0" two coordinates, g left to gravity
    assert list(names) == ["joint_8_0", "joint_8_0_", "elbow_1", "g_joint"]
    assert system.coordinate_names == {j: c for c, j in names.items()}
    # a locked joint has no coordinate
    locked = lagrangian.load(odd, lock={"elbow-1": 0.3})
    assert "elbow-1" not in locked.coordinate_names and len(locked.joint_names) == 3


def test_a_model_file_has_no_joint_names():
    assert lagrangian.load("pendulum").joint_names == {}


def test_dynamics_json_carries_the_map(cli, odd):
    result = cli("dynamics", str(odd), "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert list(document["joint_names"].values()) == ["joint_8.0", "joint_8_0", "elbow-1", "g"]
    assert list(document["joint_names"]) == document["coordinates"]
    assert np.asarray(document["mass_matrix"]).shape == (4, 4)  # the other keys as before


def test_examples_show_names_the_joints_and_stays_a_urdf(cli, tmp_path):
    result = cli("examples", "--show", "two_link_arm")
    assert result.code == 0, result.err
    assert "shoulder = 'shoulder', elbow = 'elbow'" in result.out.splitlines()[-1]
    copy = tmp_path / "copy.urdf"
    copy.write_text(result.out)  # still a URDF that reads as the example
    assert lagrangian.load(copy).joint_names == lagrangian.load("two_link_arm").joint_names
    document = json.loads(cli("examples", "--show", "two_link_arm", "--json").out)
    assert document["joint_names"] == {"shoulder": "shoulder", "elbow": "elbow"}
    assert document["text"].startswith("<?xml")
    plain = cli("examples", "--show", "pendulum")
    assert "lagrangian coordinates" not in plain.out
