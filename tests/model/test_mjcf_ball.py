"""MJCF ball joints (model/mjcf_ball.py): the tree's spherical joint in MuJoCo's own layout, so
qpos, qvel, qacc and qfrc move unchanged for a fixed base, and through model/mjcf_state.py's
maps (only the free joint's numbers change) for a floating one; MuJoCo's mj_fullM, mj_inverse
and mj_forward reproduced to 1e-9; what a ball joint does not take yet refused in one line."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.model.mjcf_state import mujoco_layout

mujoco = pytest.importorskip("mujoco")
pytest.importorskip("yourdfpy")

# a floating trunk (its full inertia), a shoulder ball joint at an anchor off the limb's origin
# (inertia from its geom), then an elbow with armature
LIMB = """<mujoco model="limb">
  <worldbody>
    <body name="trunk" pos="0 0 0.5">
      <freejoint name="root"/>
      <inertial pos="0.01 0.02 -0.01" mass="4" fullinertia="0.1 0.2 0.25 0.01 -0.02 0.03"/>
      <body name="arm" pos="0.2 0.1 0" euler="10 0 20">
        <joint name="shoulder" type="ball" pos="0 0 0.03"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03"/>
        <body name="forearm" pos="0 0 -0.3">
          <joint name="elbow" axis="1 1 0" armature="0.02"/>
          <geom type="box" size="0.02 0.03 0.15" pos="0 0 -0.15"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>"""


@pytest.fixture(scope="module")
def limb(tmp_path_factory):
    path = tmp_path_factory.mktemp("mjcf_ball") / "limb.xml"
    path.write_text(LIMB)
    system = lagrangian.load(path, floating_base=True)
    return system, mujoco.MjModel.from_xml_path(str(path)), mujoco_layout(system)


def _state(model, rng):
    qpos = rng.uniform(-1.0, 1.0, model.nq)
    qpos[3:7] /= np.linalg.norm(qpos[3:7])
    qpos[7:11] /= np.linalg.norm(qpos[7:11])
    return qpos, rng.uniform(-1.0, 1.0, model.nv), rng.uniform(-1.0, 1.0, model.nv)


def test_the_layout_of_a_floating_limb_with_a_ball_joint(limb):
    system, model, layout = limb
    d = system.dynamics()
    assert (layout.nq, layout.nv) == (model.nq, model.nv) == (12, 10)
    assert (layout.our_nq, layout.our_nv) == (d.nq, d.nv) == (12, 10)
    assert d.coordinates[7:] == ("shoulder_qw", "shoulder_qx", "shoulder_qy", "shoulder_qz",
                                 "elbow")
    assert d.velocity_names[6:] == ("shoulder_wx", "shoulder_wy", "shoulder_wz", "elbow")
    rng = np.random.default_rng(5)
    qpos, qvel, qacc = _state(model, rng)
    q, v, a = layout.from_mujoco(qpos, qvel, qacc)
    assert np.array_equal(q[7:], qpos[7:]) and np.array_equal(v[6:], qvel[6:])  # unchanged
    back = layout.to_mujoco(q, v, a)
    for ours, theirs in zip(back, (qpos, qvel, qacc), strict=True):
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-14)


@pytest.mark.parametrize("backend", ["compiled", "numpy"])
def test_inverse_and_forward_dynamics_agree_with_mujoco(limb, backend):
    system, model, layout = limb
    d = system.dynamics(actuators=True, **({} if backend == "compiled" else {"backend": "numpy"}))
    assert d.actuators["elbow"]["armature"] == 0.02
    data = mujoco.MjData(model)
    rng = np.random.default_rng(8)
    for _ in range(4):
        qpos, qvel, qacc = _state(model, rng)
        data.qpos[:], data.qvel[:], data.qacc[:] = qpos, qvel, qacc
        mujoco.mj_inverse(model, data)
        q, v, a = layout.from_mujoco(qpos, qvel, qacc)
        # M = G^T M_mj G, G = d qvel / d v (the base's linear rows turned; the armature in both)
        G = np.column_stack([layout.to_mujoco(q, e)[1] for e in np.eye(model.nv)])
        M_mj = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, M_mj)
        np.testing.assert_allclose(d.mass_matrix(q), G.T @ M_mj @ G, rtol=0, atol=1e-9)
        tau = layout.force_from_mujoco(qpos, data.qfrc_inverse)
        np.testing.assert_allclose(d.inverse_dynamics(q, v, a), tau, rtol=0, atol=1e-9)
        data.qfrc_applied[:] = rng.uniform(-2.0, 2.0, model.nv)
        mujoco.mj_forward(model, data)
        _, _, expected = layout.from_mujoco(qpos, qvel, data.qacc)
        ours = d.forward_dynamics(q, v, layout.force_from_mujoco(qpos, data.qfrc_applied))
        np.testing.assert_allclose(ours, expected, rtol=0, atol=1e-9)


def test_integrate_and_difference_on_a_floating_base_with_a_ball(limb):
    """q (+) v dt moves the base by its twist and the shoulder by exp(w dt), both quaternions
    kept unit; difference is its inverse; the ball's part as MuJoCo's mj_integratePos."""
    system, model, layout = limb
    d = system.dynamics()
    rng = np.random.default_rng(2)
    qpos, qvel, _ = _state(model, rng)
    q, v = layout.from_mujoco(qpos, qvel)
    moved = d.integrate(q, v, 0.2)
    assert np.linalg.norm(moved[3:7]) == pytest.approx(1.0, abs=1e-15)
    np.testing.assert_allclose(d.difference(q, moved), 0.2 * v, rtol=0, atol=1e-12)
    expected = qpos.copy()
    mujoco.mj_integratePos(model, expected, qvel, 0.2)
    ball = moved[7:11] * np.sign(moved[7:11] @ expected[7:11])
    np.testing.assert_allclose(ball, expected[7:11], rtol=0, atol=1e-12)
    np.testing.assert_allclose(moved[11], expected[11], rtol=0, atol=1e-12)


@pytest.mark.parametrize("joint, message", [
    ('<joint type="ball" damping="0.1"/>', "damping on a ball joint"),
    ('<joint type="ball" frictionloss="0.1"/>', "frictionloss on a ball joint"),
    ('<joint type="ball" limited="true" range="0 30"/>', "a ball joint's range"),
    ('<joint type="ball" name="j"/><joint name="j"/>', "two joints are named 'j'"),
])
def test_what_a_ball_joint_does_not_take_is_refused_in_one_line(joint, message, tmp_path):
    path = tmp_path / "robot.xml"
    path.write_text(f"<mujoco><worldbody><body>{joint}<geom size='0.1'/></body></worldbody>"
                    "</mujoco>")
    with pytest.raises(ModelError, match=message) as caught:
        lagrangian.load(path)
    assert "\n" not in str(caught.value)


def test_a_locked_ball_joint_is_refused(tmp_path):
    path = tmp_path / "robot.xml"
    path.write_text("<mujoco><worldbody><body><joint type='ball' name='b'/><geom size='0.1'/>"
                    "<body pos='0 0 -1'><joint name='h'/><geom size='0.1'/></body></body>"
                    "</worldbody></mujoco>")
    for lock in ({"b": 0.0}, {"b__x": 0.0}):
        with pytest.raises(ModelError, match="ball joint 'b' cannot be locked"):
            lagrangian.load(path, lock=lock)
