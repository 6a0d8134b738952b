"""simulate on a floating base (issue 23): q (+) v dt with the quaternion kept of norm 1; the
physics checked by conservation laws and by free fall, not by the code's own numbers."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import InputError

pytest.importorskip("yourdfpy")

# a trunk and a two-joint leg, nothing symmetric: gyroscopic coupling between base and joints
URDF = """<?xml version="1.0"?>
<robot name="hopper">
  <link name="trunk"><inertial><origin xyz="0.02 -0.01 0.05" rpy="0.1 0.2 -0.1"/><mass value="3.0"/>
    <inertia ixx="0.05" ixy="0.002" ixz="-0.001" iyy="0.07" iyz="0.003" izz="0.06"/></inertial></link>
  <link name="thigh"><inertial><origin xyz="0 0 -0.15"/><mass value="0.8"/>
    <inertia ixx="0.006" ixy="0" ixz="0.0004" iyy="0.006" iyz="0" izz="0.001"/></inertial></link>
  <link name="shank"><inertial><origin xyz="0.01 0 -0.1"/><mass value="0.4"/>
    <inertia ixx="0.002" ixy="0.0001" ixz="0" iyy="0.002" iyz="0" izz="0.0004"/></inertial></link>
  <joint name="hip" type="revolute"><parent link="trunk"/><child link="thigh"/>
    <origin xyz="0.1 0.05 -0.05" rpy="0 0 0.2"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="100"/></joint>
  <joint name="knee" type="revolute"><parent link="thigh"/><child link="shank"/>
    <origin xyz="0 0 -0.3"/><axis xyz="0.6 0.8 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="100"/></joint>
</robot>
"""
START = {"base_qx": 0.3, "base_qy": -0.2, "base_qz": 0.1, "base_qw": float(np.sqrt(0.86)),
         "base_vx": 0.4, "base_vy": -0.1, "base_vz": 0.3, "base_wx": 1.5, "base_wy": -0.7,
         "base_wz": 2.0, "hip": 0.3, "knee": -0.4, "hip_dot": 1.0, "knee_dot": -2.0}


def _momentum(dynamics, q, v):
    """Linear momentum and angular momentum about the CoM, world axes: the base rows of M v
    are the base's spatial momentum in its own axes, about its origin."""
    from lagrangian.dynamics.tree.free_flyer import quaternion_matrix

    base = np.einsum("kij,kj->ki", dynamics.mass_matrix(q)[:, :6], v)
    R = quaternion_matrix(q[:, 3:7])
    p = np.einsum("kij,kj->ki", R, base[:, :3])
    about_origin = np.einsum("kij,kj->ki", R, base[:, 3:])
    return np.concatenate([p, about_origin + np.cross(q[:, :3] - dynamics.center_of_mass(q), p)],
                          axis=1)


@pytest.fixture(scope="module")
def robot(tmp_path_factory):
    path = tmp_path_factory.mktemp("hopper") / "hopper.urdf"
    path.write_text(URDF)
    return lagrangian.load(path, floating_base=True)


def test_free_floating_robot_conserves_energy_and_momenta(robot):
    """Gravity off, no torques: T, the linear momentum and the angular momentum about the CoM
    are constant, and the CoM moves on a straight line at constant speed."""
    weightless = robot.with_parameters(g=0.0)
    run = weightless.simulate(1.0, initial=START, rtol=1e-11, atol=1e-11, samples=51)
    assert run.status == "finished"
    assert run.q.shape[1] == 9 and run.q_dot.shape[1] == 8
    dynamics = weightless.dynamics()
    energy = dynamics.kinetic_energy(run.q, run.q_dot)
    assert np.ptp(energy) / energy[0] < 1e-8
    momentum = _momentum(dynamics, run.q, run.q_dot)
    assert np.abs(momentum - momentum[0]).max() < 1e-8 * np.abs(momentum[0]).max()
    com = dynamics.center_of_mass(run.q)
    straight = com[0] + np.outer(run.t - run.t[0], momentum[0, :3] / 4.2)
    assert np.abs(com - straight).max() < 1e-8
    assert np.abs(np.linalg.norm(run.q[:, 3:7], axis=1) - 1).max() < 1e-12


def test_under_gravity_the_centre_of_mass_falls_at_g(robot):
    """Zero torques under gravity: the CoM follows c0 + v0 t - g t^2/2 z, whatever the
    robot's tumbling; the quaternion stays of norm 1 to 1e-12."""
    run = robot.simulate(0.8, initial=START, rtol=1e-11, atol=1e-11, samples=41)
    dynamics = robot.dynamics()
    com = dynamics.center_of_mass(run.q)
    h0 = _momentum(dynamics, run.q[:1], run.q_dot[:1])[0]
    t = run.t - run.t[0]
    g = robot.parameters["g"]
    expected = com[0] + np.outer(t, h0[:3] / 4.2) - 0.5 * g * np.outer(t * t, [0, 0, 1])
    assert np.abs(com - expected).max() < 1e-8
    assert np.abs(np.linalg.norm(run.q[:, 3:7], axis=1) - 1).max() < 1e-12
    frame = run.to_pandas()
    assert {"base_qw", "base_wz", "hip", "hip_dot", "knee_dot"} <= set(frame.columns)
    assert run.summary()["relative_energy_drift"] < 1e-6  # E0 small beside T: relative to it


def test_one_step_agrees_with_pinocchio(robot, tmp_path):
    """A short run against Pinocchio's aba and integrate by small explicit steps (RK4)."""
    pin = pytest.importorskip("pinocchio")
    path = tmp_path / "hopper.urdf"
    path.write_text(URDF)
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = model.createData()
    run = robot.simulate(0.05, initial=START, rtol=1e-12, atol=1e-12, samples=2)
    q, v = run.q[0].copy(), run.q_dot[0].copy()
    tau, h = np.zeros(model.nv), 0.05 / 200

    def acc(q, v):
        return pin.aba(model, data, q, v, tau)

    for _ in range(200):  # RK4 on the manifold: stages by integrate
        k1v, k1a = v, acc(q, v)
        q2, v2 = pin.integrate(model, q, k1v * h / 2), v + k1a * h / 2
        k2v, k2a = v2, acc(q2, v2)
        q3, v3 = pin.integrate(model, q, k2v * h / 2), v + k2a * h / 2
        k3v, k3a = v3, acc(q3, v3)
        q4, v4 = pin.integrate(model, q, k3v * h), v + k3a * h
        k4v, k4a = v4, acc(q4, v4)
        q = pin.integrate(model, q, (k1v + 2 * k2v + 2 * k3v + k4v) * h / 6)
        v = v + (k1a + 2 * k2a + 2 * k3a + k4a) * h / 6
    assert np.abs(pin.difference(model, run.q[-1], q)).max() < 1e-6
    assert np.abs(run.q_dot[-1] - v).max() < 1e-6


def test_a_quaternion_off_norm_one_is_refused(robot):
    with pytest.raises(InputError, match="quaternion") as error:
        robot.simulate(0.1, initial={"base_qw": 0.5})
    assert error.value.field == "initial"
    with pytest.raises(InputError, match="base_qq"):
        robot.simulate(0.1, initial={"base_qq": 0.5})


def test_joint_torques_of_a_controller_are_internal_and_do_their_work(robot):
    """A PD law on the joints, gravity off: joint torques are internal forces, so the linear
    momentum and the angular momentum about the CoM stay constant while the joints settle,
    and T(t) - T(0) is the controller's work (summed from the samples: dense ones)."""
    weightless = robot.with_parameters(g=0.0)
    target = np.array([0.5, 0.2])

    def pd(t, q, v):
        return 0.5 * (target - q[7:]) - 0.05 * v[6:]

    run = weightless.simulate(3.0, initial=START, controller=pd, rtol=1e-11, atol=1e-11,
                              samples=6001)
    assert run.status == "finished"
    dynamics = weightless.dynamics()
    momentum = _momentum(dynamics, run.q, run.q_dot)
    assert np.abs(momentum - momentum[0]).max() < 1e-8 * np.abs(momentum[0]).max()
    kinetic = dynamics.kinetic_energy(run.q, run.q_dot)
    assert np.abs(kinetic - kinetic[0] - run.work).max() < 1e-5 * kinetic[0]
    # the damping takes the joints' rates (2 rad/s at the start) down
    assert np.abs(run.q_dot[-1, 6:]).max() < 0.1 * np.abs(run.q_dot[0, 6:]).max()


def test_a_wrench_on_the_base_accelerates_the_centre_of_mass_by_f_over_m(robot):
    """All nv entries: a world-fixed force F at the base origin (given in base axes each
    call), gravity off: m c'' = F whatever the tumbling."""
    from lagrangian.dynamics.tree.free_flyer import quaternion_matrix

    weightless = robot.with_parameters(g=0.0)
    force = np.array([1.2, -0.6, 2.1])

    def thruster(t, q, v):
        R = quaternion_matrix(q[None, 3:7])[0]
        return np.concatenate([R.T @ force, np.zeros(3), np.zeros(2)])

    run = weightless.simulate(0.8, initial=START, controller=thruster, rtol=1e-11, atol=1e-11,
                              samples=41)
    dynamics = weightless.dynamics()
    com = dynamics.center_of_mass(run.q)
    h0 = _momentum(dynamics, run.q[:1], run.q_dot[:1])[0]
    t = run.t - run.t[0]
    expected = com[0] + np.outer(t, h0[:3] / 4.2) + 0.5 * np.outer(t * t, force / 4.2)
    assert np.abs(com - expected).max() < 1e-8


def test_a_controller_of_the_wrong_shape_is_one_line(robot):
    with pytest.raises(InputError, match=r"shape \(3,\); expected \(2,\) joint torques or \(8,\)"
                       ) as caught:
        robot.simulate(0.1, initial=START, controller=lambda t, q, v: np.zeros(3))
    assert caught.value.field == "controller" and "\n" not in str(caught.value)
    with pytest.raises(InputError, match="callable"):
        robot.simulate(0.1, initial=START, controller=2.0)
    with pytest.raises(InputError, match="not finite"):
        robot.simulate(0.1, initial=START, controller=lambda t, q, v: np.full(2, np.nan))
