"""A robot with ball joints in CasADi (the numpy reference's recursions over casadi SX): a ball,
a hinge and a ball under tilted gravity. Its M, bias and accelerations agree with MuJoCo (whose
qpos/qvel are ours: w x y z, the angular velocity in the child's axes) and with our forward
dynamics; q_dot is d/dt of MuJoCo's and our step q (+) v t at t = 0; casadi's Jacobian of rhs is a
central difference of our forward dynamics. An MJCF free joint (three slides and a ball) is
MuJoCo's in M, qacc and mj_integratePos's rate. (A floating joint between links, and one on a
floating base, are checked against Pinocchio in tests/model/test_urdf_floating_mid_tree.py.)"""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from mjcf_models import BALL_HINGE_BALL, leg

casadi = pytest.importorskip("casadi")
mujoco = pytest.importorskip("mujoco")

INPUTS = ["shoulder_wy", "tau_elbow", "wrist_wz"]


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    """(system, its CasADi functions, our dynamics, MuJoCo's model, three random states)."""
    path = tmp_path_factory.mktemp("ball") / "chain.xml"
    path.write_text(BALL_HINGE_BALL)
    system = lagrangian.load(path)
    rng = np.random.default_rng(4)
    states = []
    for _ in range(3):
        q = rng.uniform(-1, 1, 9)
        q[0:4] /= np.linalg.norm(q[0:4])
        q[5:9] /= np.linalg.norm(q[5:9])
        states.append((q, rng.uniform(-1, 1, 7), rng.uniform(-1, 1, 3)))
    return (system, system.to_casadi(inputs=INPUTS), system.dynamics(),
            mujoco.MjModel.from_xml_path(str(path)), states)


def _torque(u):
    """The generalized force of the inputs: a moment on the upper arm about its y, the elbow's
    torque, a moment on the hand about its z."""
    tau = np.zeros(7)
    tau[[1, 3, 6]] = u
    return tau


def test_the_layout_is_ours_and_mujocos(chain):
    system, functions, dynamics, _, _ = chain
    assert functions.configuration == tuple(dynamics.coordinates)
    assert functions.velocities == ("shoulder_wx", "shoulder_wy", "shoulder_wz", "elbow_dot",
                                    "wrist_wx", "wrist_wy", "wrist_wz")
    assert not functions.floating_base and functions.input_coordinates == (1, 3, 6)


def test_a_ball_chain_agrees_with_mujoco_and_our_dynamics(chain):
    _, functions, dynamics, model, states = chain
    data = mujoco.MjData(model)
    for q, v, u in states:
        data.qpos[:], data.qvel[:], data.qfrc_applied[:] = q, v, _torque(u)
        mujoco.mj_forward(model, data)
        M_mj = np.zeros((7, 7))
        mujoco.mj_fullM(model, data, M_mj)
        M = np.asarray(functions.mass_matrix(q))
        x_dot = np.asarray(functions.rhs(np.r_[q, v], u)).ravel()
        np.testing.assert_allclose(M, M_mj, rtol=0, atol=1e-9)
        np.testing.assert_allclose(np.asarray(functions.forcing(q, v, u)).ravel(),
                                   _torque(u) - data.qfrc_bias, rtol=0, atol=1e-9)
        np.testing.assert_allclose(x_dot[9:], data.qacc, rtol=0, atol=1e-9)
        a = dynamics.forward_dynamics(q, v, _torque(u))
        np.testing.assert_allclose(x_dot[9:], a, rtol=0,
                                   atol=1e-10 * max(1.0, np.abs(a).max()))
        h = 1e-6  # q_dot: the rate of q exp(v t), MuJoCo's step and ours
        ahead, behind = q.copy(), q.copy()
        mujoco.mj_integratePos(model, ahead, v, h)
        mujoco.mj_integratePos(model, behind, v, -h)
        np.testing.assert_allclose(x_dot[:9], (ahead - behind) / (2 * h), rtol=0, atol=1e-8)
        rate = (dynamics.integrate(q, v, h) - dynamics.integrate(q, v, -h)) / (2 * h)
        np.testing.assert_allclose(x_dot[:9], rate, rtol=0, atol=1e-8)


def test_the_jacobian_of_rhs_is_our_forward_dynamics_differentiated(chain):
    """d v_dot / dx by casadi's AD equals a central difference of forward_dynamics in each
    number of q and v: off the unit sphere the rotation is that of q / |q| (ours within the
    quaternions' tolerance), so the quaternions are normalised before our dynamics see them."""
    _, functions, dynamics, _, states = chain
    q, v, u = states[0]
    x = casadi.SX.sym("x", 16)
    jacobian = casadi.Function("J", [x], [casadi.jacobian(functions.rhs(x, u), x)])
    J = np.asarray(jacobian(np.r_[q, v]))[9:]
    step = 1e-5

    def forward(y):
        y = y.copy()
        for k in (0, 5):  # the balls' quaternions
            y[k:k + 4] /= np.linalg.norm(y[k:k + 4])
        return dynamics.forward_dynamics(y[:9], y[9:], _torque(u))

    for i in range(16):
        plus, minus = np.r_[q, v], np.r_[q, v]
        plus[i] += step
        minus[i] -= step
        column = (forward(plus) - forward(minus)) / (2 * step)
        np.testing.assert_allclose(J[:, i], column, rtol=0,
                                   atol=1e-5 * max(1.0, np.abs(column).max()), err_msg=f"x[{i}]")


def test_a_scaled_quaternion_turns_its_body_as_the_unit_one(chain):
    """R(q / |q|): collocation leaves |q| off 1 by its error, and M does not move."""
    _, functions, _, _, states = chain
    q = states[1][0]
    scaled = q.copy()
    scaled[5:9] *= 1.5
    np.testing.assert_allclose(np.asarray(functions.mass_matrix(scaled)),
                               np.asarray(functions.mass_matrix(q)), rtol=0, atol=1e-12)


def test_an_mjcf_free_joint_is_mujocos_in_casadi(tmp_path):
    """A free joint in MuJoCo's layout (x y z, qw qx qy qz; the linear velocity in world axes,
    the angular in the body's): M = mj_fullM, the accelerations = mj_forward's qacc, and
    q_dot = d/dt of mj_integratePos(q, v, t) at t = 0 (central difference)."""
    path = tmp_path / "leg.xml"
    path.write_text(leg())
    functions = lagrangian.load(path).to_casadi(inputs=["hip", "knee"])
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    rng = np.random.default_rng(6)
    for _ in range(2):
        q = np.r_[rng.normal(size=3), rng.normal(size=4), rng.uniform(-1, 1, 2)]
        q[3:7] /= np.linalg.norm(q[3:7])
        v, u = rng.uniform(-1, 1, 8), rng.uniform(-1, 1, 2)
        data.qpos[:], data.qvel[:], data.qfrc_applied[:] = q, v, np.r_[np.zeros(6), u]
        mujoco.mj_forward(model, data)
        M = np.zeros((8, 8))
        mujoco.mj_fullM(model, data, M)
        np.testing.assert_allclose(np.asarray(functions.mass_matrix(q)), M, rtol=0, atol=1e-9)
        x_dot = np.asarray(functions.rhs(np.r_[q, v], u)).ravel()
        np.testing.assert_allclose(x_dot[9:], data.qacc, rtol=0, atol=1e-9)
        h = 1e-6
        ahead, behind = q.copy(), q.copy()
        mujoco.mj_integratePos(model, ahead, v, h)
        mujoco.mj_integratePos(model, behind, v, -h)
        np.testing.assert_allclose(x_dot[:9], (ahead - behind) / (2 * h), rtol=0, atol=1e-8)
