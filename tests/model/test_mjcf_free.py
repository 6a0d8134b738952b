"""MJCF free joints in MuJoCo's own layout (model/mjcf_free.py): without floating_base a free
joint is three slides along the world's axes and a ball, so q = qpos, v = qvel and tau = qfrc
with no conversion: q = [x, y, z (m, world), qw, qx, qy, qz], v = [origin velocity in world axes,
angular velocity in body axes]. Against MuJoCo's mj_fullM, mj_inverse and mj_forward (1e-9) and
its body placements; a free top falls by 1/2 g t^2 and keeps its energy and angular momentum
in closed form; what a free joint does not take is refused in one line."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.model.mjcf_state import mujoco_layout

mujoco = pytest.importorskip("mujoco")
pytest.importorskip("yourdfpy")

# a free trunk placed and turned in the file (MuJoCo's qpos0), a hip with armature, a knee with
# damping and armature, a ball wrist; then a free ellipsoid top (its centre at its origin)
ROBOT = """<mujoco model="two_free">
  <option><flag contact="disable"/></option>
  <worldbody>
    <body name="trunk" pos="0.1 0.2 0.5" quat="0.9 0.1 0.2 0.3">
      <freejoint name="root"/>
      <inertial pos="0.01 0.02 -0.01" mass="4" fullinertia="0.1 0.2 0.25 0.01 -0.02 0.03"/>
      <body name="thigh" pos="0.2 0.1 0" euler="10 0 20">
        <joint name="hip" axis="0 1 0" pos="0 0 0.02" armature="0.3"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03"/>
        <body name="shin" pos="0 0 -0.3">
          <joint name="knee" axis="1 1 0" damping="0.05" armature="0.02"/>
          <geom type="box" size="0.02 0.03 0.15" pos="0 0 -0.15"/>
          <body name="hand" pos="0 0 -0.3">
            <joint name="wrist" type="ball" pos="0 0 0.01"/>
            <geom type="sphere" size="0.06" pos="0.08 0 0" mass="1"/>
          </body>
        </body>
      </body>
    </body>
    <body name="top" pos="1 0 0">
      <joint type="free" name="spin"/>
      <geom type="ellipsoid" size="0.1 0.2 0.3"/>
    </body>
  </worldbody>
</mujoco>"""
QUATERNIONS = (3, 9, 16)  # where each unit quaternion starts in qpos (root, wrist, spin)
# the top: an ellipsoid of MuJoCo's density 1000 kg/m^3, semi-axes a, b, c (m)
AXES_ABC = np.array([0.1, 0.2, 0.3])
TOP_MASS = 1000.0 * 4.0 / 3.0 * np.pi * AXES_ABC.prod()
TOP_INERTIA = TOP_MASS / 5 * np.diag([0.2**2 + 0.3**2, 0.1**2 + 0.3**2, 0.1**2 + 0.2**2])


@pytest.fixture(scope="module")
def robot(tmp_path_factory):
    path = tmp_path_factory.mktemp("mjcf_free") / "two_free.xml"
    path.write_text(ROBOT)
    system = lagrangian.load(path)
    return system, mujoco.MjModel.from_xml_path(str(path)), {
        "compiled": system.dynamics(actuators=True),
        "numpy": system.dynamics(actuators=True, backend="numpy")}


def _state(model, rng):
    qpos = rng.uniform(-1.0, 1.0, model.nq)
    for k in QUATERNIONS:
        qpos[k:k + 4] /= np.linalg.norm(qpos[k:k + 4])
    return qpos, rng.uniform(-1.0, 1.0, model.nv), rng.uniform(-1.0, 1.0, model.nv)


def test_the_state_is_mujocos_qpos_and_qvel_unchanged(robot):
    system, model, dynamics = robot
    d = dynamics["compiled"]
    assert (d.nq, d.nv) == (model.nq, model.nv) == (20, 17)
    assert d.coordinates[:7] == ("root_x", "root_y", "root_z", "root_qw", "root_qx", "root_qy",
                                 "root_qz")
    assert d.coordinates[13:] == ("spin_x", "spin_y", "spin_z", "spin_qw", "spin_qx",
                                  "spin_qy", "spin_qz")
    assert d.velocity_names[:6] == ("root_x", "root_y", "root_z", "root_wx", "root_wy",
                                    "root_wz")
    # the slides' massless bodies carry no frame of their own; the joint's frame is its body's
    assert not any("slide" in f or f in ("root_x", "spin_z") for f in d.frames)
    layout = mujoco_layout(system)
    qpos, qvel, qacc = _state(model, np.random.default_rng(1))
    for ours, theirs in zip(layout.from_mujoco(qpos, qvel, qacc), (qpos, qvel, qacc),
                            strict=True):
        assert np.array_equal(ours, theirs)
    assert np.array_equal(layout.force_to_mujoco(qpos, qacc), qacc)


def test_the_bodies_are_where_mujoco_puts_them(robot):
    """At MuJoCo's qpos0 (the file's pos and quat of a free body) and at a random qpos, each
    body's frame is MuJoCo's xpos, xmat."""
    _, model, dynamics = robot
    data = mujoco.MjData(model)
    d = dynamics["numpy"]  # (the compiled frames would be a compile of their own)
    for qpos in (model.qpos0, _state(model, np.random.default_rng(2))[0]):
        data.qpos[:] = qpos
        mujoco.mj_kinematics(model, data)
        for body in ("trunk", "shin", "top"):  # (a link's frame is at its joint's anchor)
            placement = d.placement(qpos, body)
            k = model.body(body).id
            np.testing.assert_allclose(placement[:3, 3], data.xpos[k], rtol=0, atol=1e-12)
            np.testing.assert_allclose(placement[:3, :3], data.xmat[k].reshape(3, 3), rtol=0,
                                       atol=1e-12)
    np.testing.assert_allclose(model.qpos0[:7], [0.1, 0.2, 0.5, *np.array([0.9, 0.1, 0.2, 0.3])
                                                 / np.linalg.norm([0.9, 0.1, 0.2, 0.3])])


@pytest.mark.parametrize("backend", ["compiled", "numpy"])
def test_mass_matrix_inverse_and_forward_dynamics_are_mujocos(robot, backend):
    """q = qpos, v = qvel, a = qacc, tau = qfrc: M = mj_fullM, ID = qfrc_inverse (armature
    and damping in both), FD = mj_forward's qacc, all to 1e-9 with no conversion."""
    _, model, dynamics = robot
    d = dynamics[backend]
    data = mujoco.MjData(model)
    rng = np.random.default_rng(8)
    for _ in range(3):
        qpos, qvel, qacc = _state(model, rng)
        data.qpos[:], data.qvel[:], data.qacc[:] = qpos, qvel, qacc
        mujoco.mj_inverse(model, data)
        M = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, M)
        np.testing.assert_allclose(d.mass_matrix(qpos), M, rtol=0, atol=1e-9)
        np.testing.assert_allclose(d.inverse_dynamics(qpos, qvel, qacc), data.qfrc_inverse,
                                   rtol=0, atol=1e-9)
        data.qfrc_applied[:] = rng.uniform(-2.0, 2.0, model.nv)
        mujoco.mj_forward(model, data)
        np.testing.assert_allclose(d.forward_dynamics(qpos, qvel, data.qfrc_applied),
                                   data.qacc, rtol=0, atol=1e-9)


def _rotation(quaternion_wxyz):
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, np.asarray(quaternion_wxyz, float))
    return R.reshape(3, 3)


def test_a_spinning_top_falls_by_half_g_t_squared_and_keeps_its_energy(robot):
    """No contact: the top's origin (its centre) moves as x0 + v0 t + 1/2 g t^2; its
    T + V = 1/2 m |p_dot|^2 + 1/2 w.I w + m g z and its angular momentum R I w in world axes
    stay constant while it tumbles about its middle axis (w in body axes, I from the file)."""
    system, _, _ = robot
    start = {"spin_x": 0.5, "spin_z": 2.0, "spin_qw": 0.8, "spin_qx": 0.6, "spin_x_dot": 0.3,
             "spin_z_dot": 1.0, "spin_wx": 0.1, "spin_wy": 6.0, "spin_wz": 0.2,
             "root_qw": 1.0, "wrist_qw": 1.0, "hip_dot": 1.0}
    run = system.simulate(1.5, initial=start, rtol=1e-11, atol=1e-11, samples=31)
    assert run.status == "finished"
    names = list(run.coordinates)
    t, q, w = run.t, run.q, run.q_dot
    p = q[:, names.index("spin_x"):names.index("spin_z") + 1]
    np.testing.assert_allclose(p, np.c_[0.5 + 0.3 * t, 0 * t, 2.0 + t - 0.5 * 9.81 * t**2],
                               rtol=0, atol=1e-9)
    rates = list(run.velocity_names)
    p_dot = w[:, rates.index("spin_x"):rates.index("spin_z") + 1]
    omega = w[:, rates.index("spin_wx"):rates.index("spin_wz") + 1]
    turn = q[:, names.index("spin_qw"):names.index("spin_qz") + 1]
    energy = [0.5 * TOP_MASS * v @ v + 0.5 * o @ TOP_INERTIA @ o + TOP_MASS * 9.81 * z
              for v, o, z in zip(p_dot, omega, p[:, 2], strict=True)]
    momentum = np.array([_rotation(r) @ TOP_INERTIA @ o for r, o in zip(turn, omega,
                                                                          strict=True)])
    np.testing.assert_allclose(np.array(energy) - energy[0], 0.0, rtol=0, atol=1e-8)
    np.testing.assert_allclose(momentum - momentum[0], 0.0, rtol=0, atol=1e-9)
    assert np.ptp(omega[:, 0]) > 0.5  # it tumbles: w in body axes is far from constant
    assert run.energy_drift < 1e-9  # the whole robot's T + V, the trunk swinging its leg


@pytest.mark.parametrize("body, message", [
    ('<body><joint/><geom size="0.1"/><body><freejoint/><geom size="0.1"/></body></body>',
     "a free joint must be the only joint of a body at the top of the worldbody"),
    ('<body><freejoint name="f"/><joint/><geom size="0.1"/></body>', "the only joint"),
    ('<body><joint type="free" armature="0.1"/><geom size="0.1"/></body>',
     "armature on a free joint"),
    ('<body><freejoint align="true"/><geom size="0.1"/></body>', "align on a free joint"),
    ('<body><freejoint name="f"/><geom size="0.1"/></body><body><joint name="f_x"/>'
     '<geom size="0.1"/></body>', "two joints are named 'f_x'"),
])
def test_what_a_free_joint_does_not_take_is_refused_in_one_line(body, message, tmp_path):
    path = tmp_path / "robot.xml"
    path.write_text(f"<mujoco><worldbody>{body}</worldbody></mujoco>")
    with pytest.raises(ModelError, match=message) as caught:
        lagrangian.load(path)
    assert "\n" not in str(caught.value) and "robot.xml" in str(caught.value)


def test_a_free_joint_cannot_be_locked_and_floating_base_takes_one(tmp_path):
    path = tmp_path / "robot.xml"
    path.write_text("<mujoco><worldbody><body><freejoint name='a'/><geom size='0.1'/></body>"
                    "<body><freejoint name='b'/><geom size='0.1'/></body></worldbody></mujoco>")
    for lock in ({"a": 0.0}, {"a_z": 0.0}):
        with pytest.raises(ModelError, match="the free joint 'a' cannot be locked"):
            lagrangian.load(path, lock=lock)
    with pytest.raises(ModelError, match="with floating_base the model has one free joint"):
        lagrangian.load(path, floating_base=True)


def test_derivatives_and_integrate_are_mujocos_on_its_tangent(robot):
    """d tau/dq and d tau/dv along MuJoCo's tangent (mj_integratePos: the position moved in
    world axes, the quaternion by exp(w) in body axes) equal central differences of its
    mj_inverse (rigid bodies: no armature or damping) to 1e-6; integrate is mj_integratePos."""
    system, model, _ = robot
    rigid = mujoco.MjModel.from_xml_string(ROBOT)
    rigid.dof_armature[:] = 0.0
    rigid.dof_damping[:] = 0.0
    data = mujoco.MjData(rigid)
    qpos, qvel, qacc = _state(rigid, np.random.default_rng(3))

    def inverse(qp, qv):
        data.qpos[:], data.qvel[:], data.qacc[:] = qp, qv, qacc
        mujoco.mj_inverse(rigid, data)
        return data.qfrc_inverse.copy()

    h, nv = 1e-6, rigid.nv
    by_q, by_v = np.zeros((nv, nv)), np.zeros((nv, nv))
    for i, step in enumerate(np.eye(nv) * h):
        moved = [qpos.copy(), qpos.copy()]
        mujoco.mj_integratePos(rigid, moved[0], step, 1.0)
        mujoco.mj_integratePos(rigid, moved[1], -step, 1.0)
        by_q[:, i] = (inverse(moved[0], qvel) - inverse(moved[1], qvel)) / (2 * h)
        by_v[:, i] = (inverse(qpos, qvel + step) - inverse(qpos, qvel - step)) / (2 * h)
    d = system.dynamics(backend="numpy")
    d_q, d_v = d.inverse_dynamics_derivatives(qpos, qvel, qacc)
    np.testing.assert_allclose(d_q, by_q, rtol=0, atol=1e-6)
    np.testing.assert_allclose(d_v, by_v, rtol=0, atol=1e-6)
    expected = qpos.copy()
    mujoco.mj_integratePos(model, expected, qvel, 0.3)
    np.testing.assert_allclose(d.integrate(qpos, qvel, 0.3), expected, rtol=0, atol=1e-12)


def test_the_command_line_names_the_free_joint(tmp_path, cli):
    path = tmp_path / "top.xml"
    path.write_text("<mujoco><worldbody><body><freejoint name='top'/><geom size='0.1'/>"
                    "</body></worldbody></mujoco>")
    result = cli("dynamics", str(path), "--q", "0,0,1,0.5,0,0,0")
    assert result.code == 2 and "free joint 'top' quaternion (q[3:7], w x y z) has norm 0.5" \
        in result.err and len(result.err.strip().splitlines()) == 1
    # the C export takes it in MuJoCo's layout: q 7 numbers (x y z, qw qx qy qz), v 6
    result = cli("codegen", str(path), "--out", str(tmp_path / "c"))
    assert result.code == 0, result.err
    header = next((tmp_path / "c").glob("*.h")).read_text()
    assert "_N 6\n" in header and "_NQ 7\n" in header and "top_qw" in header
