"""A URDF planar joint (a mobile base): coordinates x, y in the joint frame's plane and theta
about its normal, rates their time derivatives (nq = nv = 3), through every backend; against
the closed form of one body in the plane and against Pinocchio's JointModelPlanar."""

from __future__ import annotations

import json

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import ModelError

LINK = ('<link name="{name}"><inertial><origin xyz="{com}" rpy="{rpy}"/><mass value="{m}"/>'
        '<inertia ixx="{i[0]}" ixy="{i[1]}" ixz="{i[2]}" iyy="{i[3]}" iyz="{i[4]}" izz="{i[5]}"/>'
        '</inertial></link>')

MOBILE_ARM = "".join([
    '<robot name="mobile_arm"><link name="floor"/>',
    LINK.format(name="base", com="0.1 0.02 0.05", rpy="0 0 0", m=12.0,
                i=(0.5, 0.01, 0.02, 0.6, 0.03, 0.8)),
    LINK.format(name="upper", com="0 0 0.2", rpy="0.1 0 0", m=2.0, i=(0.05, 0, 0, 0.05, 0, 0.01)),
    LINK.format(name="fore", com="0.15 0 0", rpy="0 0 0", m=1.0, i=(0.01, 0, 0, 0.02, 0, 0.02)),
    '<joint name="base_joint" type="planar"><parent link="floor"/><child link="base"/>'
    '<origin xyz="0.3 -0.2 0.1" rpy="0 0 0.4"/><axis xyz="0 0 1"/></joint>',
    '<joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>'
    '<origin xyz="0.2 0 0.3" rpy="0 0.2 0"/><axis xyz="0 1 0"/>'
    '<limit lower="-2" upper="2" effort="10" velocity="2"/></joint>',
    '<joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>'
    '<origin xyz="0 0 0.4"/><axis xyz="1 0 0"/>'
    '<limit lower="-3" upper="3" effort="5" velocity="3"/></joint></robot>'])


def one_body(normal="0 0 1", com="0.3 -0.1 0"):
    return "".join(['<robot name="puck"><link name="floor"/>',
                    LINK.format(name="puck", com=com, rpy="0 0 0", m=2.0,
                                i=(0.1, 0, 0, 0.1, 0, 0.25)),
                    '<joint name="slide" type="planar"><parent link="floor"/>'
                    f'<child link="puck"/><axis xyz="{normal}"/></joint></robot>'])


@pytest.fixture(scope="module")
def mobile_arm(tmp_path_factory):
    path = tmp_path_factory.mktemp("planar") / "mobile_arm.urdf"
    path.write_text(MOBILE_ARM)
    return path, lagrangian.load(path)


def test_the_coordinates_are_x_y_theta_then_the_arm(mobile_arm):
    _, arm = mobile_arm
    assert tuple(arm.dynamics().coordinates) == (
        "base_joint_x", "base_joint_y", "base_joint_theta", "shoulder", "elbow")


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_one_body_in_the_plane_is_its_closed_form(tmp_path, backend):
    """p = (x, y) + R(theta) c: M = [[m, 0, m a], [0, m, m b], [m a, m b, I + m |c|^2]] with
    (a, b) = R'(theta) c; gravity along the normal does no work in the plane."""
    path = tmp_path / "puck.urdf"
    path.write_text(one_body())
    dynamics = lagrangian.load(path).dynamics(backend=backend)
    m, I, c = 2.0, 0.25, np.array([0.3, -0.1])
    for theta in (0.0, 0.7, 2.5):
        s, k = np.sin(theta), np.cos(theta)
        a, b = -s * c[0] - k * c[1], k * c[0] - s * c[1]
        expected = [[m, 0, m * a], [0, m, m * b], [m * a, m * b, I + m * c @ c]]
        np.testing.assert_allclose(dynamics.mass_matrix([0.4, -1.0, theta]), expected,
                                   rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(dynamics.gravity([0.4, -1.0, theta]), 0.0, atol=1e-12)


def test_the_plane_is_normal_to_the_axis(tmp_path):
    """axis x: the puck slides along e1 = y and e2 = x cross y = z, and turns about x."""
    path = tmp_path / "puck.urdf"
    path.write_text(one_body(normal="1 0 0", com="0 0 0"))
    dynamics = lagrangian.load(path).dynamics()
    X = dynamics.placement([0.5, 0.7, 0.3], "slide")
    np.testing.assert_allclose(X[:3, 3], [0.0, 0.5, 0.7], atol=1e-15)
    k, s = np.cos(0.3), np.sin(0.3)
    np.testing.assert_allclose(X[:3, :3], [[1, 0, 0], [0, k, -s], [0, s, k]], atol=1e-15)


def test_the_symbolic_equations_agree_with_the_recursions(mobile_arm):
    """Two derivations: Lagrange's equations of the URDF's symbolic bodies, and the tree's
    recursive algorithms in C."""
    path, arm = mobile_arm
    numeric, dynamics = arm.numeric(backend="numpy"), arm.dynamics()
    rng = np.random.default_rng(3)
    q, v = rng.uniform(-1.0, 1.0, (2, 4, 5))
    np.testing.assert_allclose(numeric.mass_matrix(q, v), dynamics.mass_matrix(q), rtol=1e-10,
                               atol=1e-12)
    np.testing.assert_allclose(numeric.forcing(q, v), -dynamics.bias_forces(q, v), rtol=1e-10,
                               atol=1e-10)


@pytest.mark.parametrize("kernel", ["unrolled", "compact"])
def test_a_mobile_arm_agrees_with_pinocchios_planar_joint(mobile_arm, kernel):
    """Pinocchio's planar q is (x, y, cos theta, sin theta) and v its twist in the moving
    axes: v_b = R^T (x_dot, y_dot), and the accelerations differ by omega x v_b."""
    pin = pytest.importorskip("pinocchio")
    path, arm = mobile_arm
    model = pin.buildModelFromUrdf(str(path))
    assert model.joints[1].shortname() == "JointModelPlanar"
    data = model.createData()
    dynamics = arm.dynamics(kernel=kernel)
    rng = np.random.default_rng(5)
    for _ in range(4):
        q, v, tau = rng.uniform(-1.5, 1.5, (3, 5))
        k, s = np.cos(q[2]), np.sin(q[2])
        R = np.array([[k, -s], [s, k]])
        qp = np.array([q[0], q[1], k, s, *q[3:]])
        vp = np.concatenate([R.T @ v[:2], v[2:]])
        taup = np.concatenate([R.T @ tau[:2], tau[2:]])
        assert dynamics.kinetic_energy(q, v) == pytest.approx(
            pin.computeKineticEnergy(model, data, qp, vp), rel=1e-9)
        assert dynamics.potential_energy(q) == pytest.approx(
            pin.computePotentialEnergy(model, data, qp), rel=1e-9)
        ap = pin.aba(model, data, qp, vp, taup)
        w, vb = v[2], vp[:2]
        expected = np.concatenate([R @ (ap[:2] + w * np.array([-vb[1], vb[0]])), ap[2:]])
        np.testing.assert_allclose(dynamics.forward_dynamics(q, v, tau), expected, rtol=1e-9,
                                   atol=1e-9)


def test_the_joints_frame_is_its_child_links(mobile_arm, cli):
    path, arm = mobile_arm
    dynamics = arm.dynamics()
    q = [1.0, 2.0, 0.5, 0.0, 0.0]
    np.testing.assert_array_equal(dynamics.placement(q, "base_joint"),
                                  dynamics.placement(q, "base"))
    code, out, _ = cli("kinematics", str(path), "--frame", "base_joint", "--q", "1,2,0.5,0,0",
                       "--json")
    assert code == 0
    k, s = np.cos(0.9), np.sin(0.9)  # the origin's rpy 0.4 and theta 0.5
    origin = np.array([0.3, -0.2]) + np.array([[np.cos(0.4), -np.sin(0.4)],
                                               [np.sin(0.4), np.cos(0.4)]]) @ [1.0, 2.0]
    placement = np.array(json.loads(out)["placement"])
    np.testing.assert_allclose(placement[:2, :2], [[k, -s], [s, k]], atol=1e-12)
    np.testing.assert_allclose(placement[:3, 3], [*origin, 0.1], atol=1e-12)


def test_a_planar_joint_is_locked_by_its_coordinates(tmp_path):
    path = tmp_path / "puck.urdf"
    path.write_text(one_body())
    with pytest.raises(ModelError, match="joint 'slide' is planar: lock its coordinates "
                                         "'slide_x', 'slide_y', 'slide_theta'"):
        lagrangian.load(path, lock={"slide": 0.0})
    locked = lagrangian.load(path, lock={"slide_theta": 0.0}).dynamics()
    np.testing.assert_allclose(locked.mass_matrix([0.1, 0.2]), 2.0 * np.eye(2), rtol=1e-12)


def test_a_planar_axis_of_zero_length_is_named(tmp_path):
    path = tmp_path / "puck.urdf"
    path.write_text(one_body(normal="0 0 0"))
    with pytest.raises(ModelError, match=r"joint 'slide'.axis: the axis \(the plane's normal\) "
                                         "has zero length"):
        lagrangian.load(path)
