"""Batches of the compiled reach functions (reach_bindings.c: threads taking blocks of states
from a shared counter, four states at a time on vector lanes) equal the same states one call at
a time to 1e-14 (the lanes' code may fuse a multiply-add where one state's does not; inverse
dynamics with a wrench over many states: the tree's ID then J^T w, to 1e-12); inverse dynamics
with wrenches in its one Newton-Euler pass (reach_inverse.c) equals M a + b - J^T w from our
M, bias and frame Jacobian, on a fixed and a floating base, and where a parameter edits the
dynamics the answer stays the edited robot's. (Pinocchio's agreement: test_reach_pinocchio.py,
test_floating_reach.py.)"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from tests.dynamics.test_floating_base import FLOATING_URDF

import lagrangian

pytest.importorskip("yourdfpy")
COUNT = 2100  # above two threads' worth of states (RK_THREAD_STATES = 1024)
# test_dynamics_pinocchio.py's arm (revolute, prismatic on a tilted axis, a fixed tool), here
# so that these tests run without Pinocchio
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


def _robot(tmp_path, text: str):
    path = tmp_path / "robot.urdf"
    path.write_text(text)
    robot = lagrangian.load(path).dynamics(backend="c")
    if not robot._reach_kernel():
        pytest.skip("no C compiler")
    return robot


def _states(robot, count: int, seed: int = 5):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-1, 1, (count, len(robot.coordinates)))
    if robot.velocity_names is not None:
        q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
    v, a = rng.uniform(-1, 1, (2, count, robot.n))
    return q, v, a, rng.uniform(-5, 5, (count, 6))


def _frame(robot) -> str:
    return next(f for f in ("foot", "tool") if f in robot.frames)


def _batches(robot, q, v, a, w) -> dict[str, np.ndarray]:
    frame = _frame(robot)
    out = {"J_dot v": robot.jacobian_dot_times_v(q, v, frame),
           "A_g": robot.centroidal_momentum_matrix(q),
           "ID f_ext": robot.inverse_dynamics(q, v, a, f_ext={frame: w}),
           "ID shared f_ext": robot.inverse_dynamics(q, v, a, f_ext={frame: w[0]})}
    if robot.velocity_names is not None:
        out["C"] = robot.coriolis_matrix(q, v)
    return out


@pytest.mark.parametrize("text", [ARM, FLOATING_URDF], ids=["fixed", "floating"])
def test_a_batch_equals_each_state_alone(tmp_path, text):
    robot = _robot(tmp_path, text)
    q, v, a, w = _states(robot, COUNT)
    batches = _batches(robot, q, v, a, w)
    frame = _frame(robot)
    for k in range(0, COUNT, 37):  # one state per call: one thread, no blocks
        alone = {"J_dot v": robot.jacobian_dot_times_v(q[k], v[k], frame),
                 "A_g": robot.centroidal_momentum_matrix(q[k]),
                 "ID f_ext": robot.inverse_dynamics(q[k], v[k], a[k], f_ext={frame: w[k]}),
                 "ID shared f_ext": robot.inverse_dynamics(q[k], v[k], a[k],
                                                           f_ext={frame: w[0]})}
        if "C" in batches:
            alone["C"] = robot.coriolis_matrix(q[k], v[k])
        for name, value in alone.items():
            if name.startswith("ID"):  # many states: the tree's ID, then J^T w (one pass alone)
                np.testing.assert_allclose(batches[name][k], value, rtol=0, atol=1e-12 * (
                    1 + np.abs(value).max()), err_msg=name)
            else:
                _close(batches[name][k], value, name)
    few = robot.inverse_dynamics(q[:40], v[:40], a[:40], f_ext={frame: w[:40]})  # one pass
    for k in range(40):
        _close(few[k], robot.inverse_dynamics(q[k], v[k], a[k], f_ext={frame: w[k]}), "ID")


def _close(batch, alone, name: str) -> None:
    """Equal to 1e-14 of the entries' size (rounding: vector lanes against one state)."""
    np.testing.assert_allclose(batch, alone, rtol=0, atol=1e-14 * (1 + np.abs(alone).max()),
                               err_msg=name)


@pytest.mark.parametrize("text", [ARM, FLOATING_URDF], ids=["fixed", "floating"])
def test_a_batch_not_a_multiple_of_the_lanes_equals_each_state(tmp_path, text):
    """37 states: nine groups of four on the lanes, the last one alone; each as its own call."""
    robot = _robot(tmp_path, text)
    q, v, a, w = _states(robot, 37, seed=11)
    frame = _frame(robot)
    batches = _batches(robot, q, v, a, w)
    batches["FD f_ext"] = robot.forward_dynamics(q, v, a, f_ext={frame: w})
    for k in range(37):
        alone = {"J_dot v": robot.jacobian_dot_times_v(q[k], v[k], frame),
                 "A_g": robot.centroidal_momentum_matrix(q[k]),
                 "ID f_ext": robot.inverse_dynamics(q[k], v[k], a[k], f_ext={frame: w[k]}),
                 "ID shared f_ext": robot.inverse_dynamics(q[k], v[k], a[k],
                                                           f_ext={frame: w[0]}),
                 "FD f_ext": robot.forward_dynamics(q[k], v[k], a[k], f_ext={frame: w[k]})}
        if "C" in batches:
            alone["C"] = robot.coriolis_matrix(q[k], v[k])
        for name, value in alone.items():
            _close(batches[name][k], value, name)


_ONE_THREAD = """
import sys, numpy as np, lagrangian
from tests.dynamics.test_reach_batches import _batches, _states
robot = lagrangian.load(sys.argv[1]).dynamics(backend="c")
out = _batches(robot, *_states(robot, int(sys.argv[2])))
np.savez(sys.argv[3], **out)
"""


def test_threads_give_the_numbers_of_one_thread(tmp_path):
    """The same batch with LAGRANGIAN_THREADS=1 (another process: the cap is read once)."""
    robot = _robot(tmp_path, FLOATING_URDF)
    q, v, a, w = _states(robot, COUNT)
    threaded = _batches(robot, q, v, a, w)
    saved = tmp_path / "one.npz"
    env = dict(os.environ, LAGRANGIAN_THREADS="1",
               PYTHONPATH=os.pathsep.join(sys.path))
    subprocess.run([sys.executable, "-c", _ONE_THREAD, str(tmp_path / "robot.urdf"), str(COUNT),
                    str(saved)], check=True, env=env, cwd=os.getcwd())
    one = np.load(saved)
    for name, value in threaded.items():
        assert np.array_equal(one[name], value), name


@pytest.mark.parametrize("text", [ARM, FLOATING_URDF], ids=["fixed", "floating"])
def test_inverse_dynamics_with_a_wrench_is_m_a_plus_b_less_j_transpose_w(tmp_path, text):
    robot = _robot(tmp_path, text)
    q, v, a, w = _states(robot, 40)
    frame = _frame(robot)
    expected = (np.einsum("nij,nj->ni", robot.mass_matrix(q), a) + robot.bias_forces(q, v)
                - np.einsum("nij,ni->nj", robot.jacobian(q, frame), w))
    got = robot.inverse_dynamics(q, v, a, f_ext={frame: w})
    assert robot._reach.inverse  # the one-pass kernel, not the two calls
    np.testing.assert_allclose(got, expected, atol=1e-11 * (1 + np.abs(expected).max()))


def test_parameters_that_edit_the_robot_keep_its_answer(tmp_path):
    """A link's mass, gravity and an actuator's force set by parameters: ID with a wrench is the
    edited robot's, as the numpy backend (recursive Newton-Euler, J^T w) computes it."""
    robot = _robot(tmp_path, ARM)
    values = {"c.mass": 1.5, robot.tree.gravity_parameter: 3.0, robot.tree.actuators[0]: 2.0}
    path = tmp_path / "robot.urdf"
    edited = lagrangian.load(path).dynamics(backend="c", parameters=values)
    slow = lagrangian.load(path).dynamics(backend="numpy", parameters=values)
    q, v, a, w = _states(edited, 20)
    expected = slow.inverse_dynamics(q, v, a, f_ext={"tool": w})
    np.testing.assert_allclose(edited.inverse_dynamics(q, v, a, f_ext={"tool": w}), expected,
                               atol=1e-11 * (1 + np.abs(expected).max()))
    # and against the formula on the edited robot's own M, b and J
    expected = (np.einsum("nij,nj->ni", slow.mass_matrix(q), a) + slow.bias_forces(q, v)
                - np.einsum("nij,ni->nj", slow.jacobian(q, "tool"), w))
    np.testing.assert_allclose(edited.inverse_dynamics(q, v, a, f_ext={"tool": w}), expected,
                               atol=1e-11 * (1 + np.abs(expected).max()))


@pytest.mark.parametrize("robot_text", ["arm", "floating"])
def test_compiled_frames_and_centre_of_mass_are_the_kinematics_walks(tmp_path, robot_text):
    """placement, jacobian (each reference), center_of_mass and its Jacobian in the reach
    module's C, a batch and a single state, equal frames.py's numpy walks (an independent
    derivation: a point Jacobian per body, where the C sums each joint's subtree), to 1e-13;
    ground-fixed and moving frames alike; the centre of mass's velocity J_c q_dot is the
    difference quotient of the centre of mass along q_dot."""
    robot = _robot(tmp_path, ARM if robot_text == "arm" else FLOATING_URDF)
    walks = robot.kinematics
    rng = np.random.default_rng(21)
    q = rng.uniform(-1.0, 1.0, (COUNT, len(robot.coordinates)))
    floating = robot.velocity_names is not None
    if floating:
        q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
    assert robot._reach.frame_index and robot._reach.center_of_mass is not None
    for frame in robot.frames:
        for ours, theirs in ((robot.placement(q, frame), walks.placement(q, frame)),
                             (robot.placement(q[7], frame), walks.placement(q[7], frame))):
            np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-13)
        for reference in ("world", "local", "local_world_aligned"):
            np.testing.assert_allclose(robot.jacobian(q, frame, reference),
                                       walks.jacobian(q, frame, reference), rtol=0, atol=1e-13)
    np.testing.assert_allclose(robot.center_of_mass(q), walks.center_of_mass(q), rtol=0,
                               atol=1e-13)
    J = robot.center_of_mass_jacobian(q)
    np.testing.assert_allclose(J, walks.center_of_mass_jacobian(q), rtol=0, atol=1e-13)
    if not floating:  # c(q + h q_dot) - c(q - h q_dot) = 2 h J_c q_dot + O(h^3)
        v, h = rng.uniform(-1.0, 1.0, (COUNT, robot.n)), 1e-6
        central = (robot.center_of_mass(q + h * v) - robot.center_of_mass(q - h * v)) / (2 * h)
        np.testing.assert_allclose(np.einsum("kij,kj->ki", J, v), central, rtol=0, atol=1e-8)


def test_turns_of_any_size_place_frames_as_numpy_does(tmp_path):
    """The kernels' own sine and cosine (tree_c.py: a reduction by pi/2, the quadrant chosen
    by selects) in every quadrant, large angles and beyond the reduction's range (libm there),
    one state and on the lanes: placements and Jacobians equal numpy's sin and cos walks."""
    robot = _robot(tmp_path, ARM)
    slow = lagrangian.load(tmp_path / "robot.urdf").dynamics(backend="numpy")
    quarter = np.pi / 2
    angles = np.concatenate([k * quarter + np.array([-0.3, 0.0, 0.4]) for k in range(-5, 6)]
                            + [[1000.3, -777.7, 5.0e4, -9.9e4, 2.0e5, -3.0e7]])
    q = np.zeros((angles.size, 3))
    q[:, 0], q[:, 1] = angles, angles[::-1]
    for frame in ("tool", "b"):
        fast_pose, slow_pose = robot.placement(q, frame), slow.placement(q, frame)
        np.testing.assert_allclose(fast_pose, slow_pose, rtol=0, atol=1e-12)
        for k in range(0, len(q), 7):  # one state at a time: the scalar kernel
            np.testing.assert_allclose(robot.placement(q[k], frame), slow_pose[k], rtol=0,
                                       atol=1e-12)
        np.testing.assert_allclose(robot.jacobian(q, frame), slow.jacobian(q, frame), rtol=0,
                                   atol=1e-12)
