"""A link's inertial as a runtime parameter of a robot's dynamics (dynamics/tree/inertials.py):
``dynamics(parameters={"b.mass": ...})`` and ``--set b.mass=...`` equal the URDF edited so, and
Pinocchio with the link's inertia replaced; the compact kernel takes them without a rebuild."""

from __future__ import annotations

import json

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import InputError

pytest.importorskip("yourdfpy")

# An inertial rpy on b, a tool on a fixed joint below c (merged into c's body), a prismatic joint.
ARM = """<?xml version="1.0"?>
<robot name="spatial">
  <link name="base"/>
  <link name="a"><inertial><origin xyz="0.05 0.02 0.3" rpy="0.1 -0.2 0.3"/><mass value="1.2"/>
    <inertia ixx="0.02" ixy="0.001" ixz="-0.002" iyy="0.03" iyz="0.0015" izz="0.025"/></inertial></link>
  <link name="b"><inertial><origin xyz="0.25 -0.01 0.02" rpy="0 0.4 0"/><mass value="0.8"/>
    <inertia ixx="0.004" ixy="0.0005" ixz="0" iyy="0.02" iyz="-0.0007" izz="0.021"/></inertial></link>
  <link name="c"><inertial><origin xyz="0.1 0 0.03"/><mass value="0.5"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.0025"/></inertial></link>
  <link name="tool"><inertial><origin xyz="0 0 0.05"/><mass value="0.2"/>
    <inertia ixx="0.0002" ixy="0" ixz="0" iyy="0.0002" iyz="0" izz="0.0001"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.2" rpy="0 0 0.5"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0.03 0.04 0.5" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j3" type="prismatic"><parent link="b"/><child link="c"/>
    <origin xyz="0.4 0 -0.05" rpy="0.2 0.1 -0.3"/><axis xyz="0.6 0 0.8"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="c"/><child link="tool"/>
    <origin xyz="0.1 0.02 0" rpy="0 0.3 0"/></joint>
</robot>
"""

SET = {"b.mass": 1.7, "b.com_x": 0.3, "b.com_z": -0.04, "b.ixx": 0.006, "b.ixy": 0.001,
       "b.izz": 0.03, "tool.mass": 0.9, "tool.com_y": 0.02}
EDITED = (ARM.replace('<origin xyz="0.25 -0.01 0.02" rpy="0 0.4 0"/><mass value="0.8"/>',
                      '<origin xyz="0.3 -0.01 -0.04" rpy="0 0.4 0"/><mass value="1.7"/>')
          .replace('ixx="0.004" ixy="0.0005" ixz="0" iyy="0.02" iyz="-0.0007" izz="0.021"',
                   'ixx="0.006" ixy="0.001" ixz="0" iyy="0.02" iyz="-0.0007" izz="0.03"')
          .replace('<origin xyz="0 0 0.05"/><mass value="0.2"/>',
                   '<origin xyz="0 0.02 0.05"/><mass value="0.9"/>'))
FUNCTIONS = (("mass_matrix", 1), ("bias_forces", 2), ("gravity", 1), ("inverse_dynamics", 3),
             ("forward_dynamics", 3), ("kinetic_energy", 2), ("potential_energy", 1))


@pytest.fixture(scope="module")
def robots(tmp_path_factory):
    folder = tmp_path_factory.mktemp("arm")
    (folder / "arm.urdf").write_text(ARM)
    (folder / "edited.urdf").write_text(EDITED)
    return lagrangian.load(folder / "arm.urdf"), lagrangian.load(folder / "edited.urdf")


def states(count=6, seed=4):
    rng = np.random.default_rng(seed)
    return [rng.uniform(-1, 1, (count, 3)) for _ in range(3)]


@pytest.mark.parametrize("backend", ["auto", "numpy"])
def test_set_inertials_equal_the_edited_urdf(robots, backend):
    arm, edited = robots
    ours = arm.dynamics(parameters=SET, backend=backend)
    theirs = edited.dynamics()
    assert EDITED != ARM and ours.n == 3
    x = states()
    for name, count in FUNCTIONS:
        np.testing.assert_allclose(getattr(ours, name)(*x[:count]),
                                   getattr(theirs, name)(*x[:count]), rtol=1e-12, atol=1e-13,
                                   err_msg=name)
    # and different from the file's own (the parameters did something)
    assert not np.allclose(arm.dynamics().mass_matrix(x[0]), ours.mass_matrix(x[0]))


def test_new_values_need_no_rebuild(robots):
    arm, _ = robots
    first = arm.dynamics(parameters={"b.mass": 1.0})
    second = arm.dynamics(parameters={"b.mass": 2.0, "g": 1.62})
    assert first.kernel == second.kernel == "compact"
    assert first.module is second.module  # one compiled module, the tree an argument
    q = np.array([0.2, -0.3, 0.1])
    assert not np.allclose(first.gravity(q), second.gravity(q))


def test_against_pinocchio_with_the_link_inertia_replaced(robots):
    pin = pytest.importorskip("pinocchio")
    arm, _ = robots
    mass, com, tensor, rpy = 2.2, np.array([0.2, 0.03, -0.01]), np.array(
        [[0.01, 0.002, 0.0], [0.002, 0.03, -0.001], [0.0, -0.001, 0.025]]), (0, 0.4, 0)
    values = {"b.mass": mass, "b.com_x": com[0], "b.com_y": com[1], "b.com_z": com[2],
              "b.ixx": tensor[0, 0], "b.ixy": tensor[0, 1], "b.ixz": tensor[0, 2],
              "b.iyy": tensor[1, 1], "b.iyz": tensor[1, 2], "b.izz": tensor[2, 2]}
    f = arm.dynamics(parameters=values)
    model = pin.buildModelFromXML(ARM)
    turn = pin.rpy.rpyToMatrix(*rpy)
    model.inertias[model.getJointId("j2")] = pin.Inertia(mass, com, turn @ tensor @ turn.T)
    data = model.createData()
    q, v, tau = states(seed=9)
    forward, mass_matrix = f.forward_dynamics(q, v, tau), f.mass_matrix(q)
    for k in range(len(q)):
        m = pin.crba(model, data, q[k]).copy()
        np.testing.assert_allclose(mass_matrix[k], np.triu(m) + np.triu(m, 1).T, rtol=1e-10,
                                   atol=1e-12)
        np.testing.assert_allclose(forward[k], pin.aba(model, data, q[k], v[k], tau[k]),
                                   rtol=1e-9, atol=1e-11)
        np.testing.assert_allclose(f.inverse_dynamics(q[k], v[k], tau[k]),
                                   pin.rnea(model, data, q[k], v[k], tau[k]), rtol=1e-10,
                                   atol=1e-12)


@pytest.mark.parametrize(("name", "value", "words"), [
    ("bb.mass", 1.0, "no link 'bb'; did you mean 'b'"),
    ("b.mas", 1.0, "did you mean 'mass'"),
    ("b.mass", -1.0, "0 kg or more"),
    ("b.com_x", float("nan"), "finite"),
    ("b.ixx", "heavy", "not a number"),
    ("b.ixy", 0.5, "not positive semidefinite"),
])
def test_bad_link_parameters_are_refused_in_one_line(robots, name, value, words):
    arm, _ = robots
    with pytest.raises(InputError, match=words) as caught:
        arm.dynamics(parameters={name: value})
    assert caught.value.field.startswith("parameters.b")
    assert "\n" not in str(caught.value)


def test_a_link_left_without_mass_is_named(robots):
    arm, _ = robots
    weightless = {"c.mass": 0.0, "tool.mass": 0.0}  # the prismatic joint then moves nothing
    weightless.update({f"{link}.{i}": 0.0 for link in ("c", "tool")
                       for i in ("ixx", "iyy", "izz")})
    with pytest.raises(InputError, match="not positive definite"):
        arm.dynamics(parameters=weightless)


def test_a_model_without_links_refuses_them():
    with pytest.raises(InputError, match="robot read from URDF"):
        lagrangian.load("double_pendulum").dynamics(parameters={"bob.mass": 2.0})


def test_cli_set_equals_the_edited_file(cli, tmp_path):
    (tmp_path / "arm.urdf").write_text(ARM)
    (tmp_path / "edited.urdf").write_text(EDITED)
    settings = ",".join(f"{k}={v}" for k, v in SET.items())
    ours = cli("dynamics", str(tmp_path / "arm.urdf"), "--q", "0.3,-0.2,0.1", "--v", "1,0.5,-0.2",
               "--tau", "0.1,0.2,0.3", "--set", settings, "--set", "g=9.7", "--json")
    theirs = cli("dynamics", str(tmp_path / "edited.urdf"), "--q", "0.3,-0.2,0.1", "--v",
                 "1,0.5,-0.2", "--tau", "0.1,0.2,0.3", "--set", "g=9.7", "--json")
    assert ours.code == theirs.code == 0, ours.err
    a, b = json.loads(ours.out), json.loads(theirs.out)
    for key in ("mass_matrix", "bias_forces", "forward_dynamics", "kinetic_energy"):
        np.testing.assert_allclose(a[key], b[key], rtol=1e-12, atol=1e-13)
    bad = cli("dynamics", str(tmp_path / "arm.urdf"), "--set", "bb.mass=2")
    assert bad.code == 2
    assert bad.err.strip() == "error: --set bb.mass: no link 'bb'; did you mean 'b'?"
