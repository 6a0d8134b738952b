"""MJCF robots (lagrangian.load("robot.xml")) against MuJoCo itself: M(q) (mj_fullM), the bias
forces C q_dot + g (qfrc_bias), inverse (mj_inverse) and forward dynamics (mj_forward), in
MuJoCo's own qpos/qvel layout; and the same robot read as URDF and as the MJCF MuJoCo writes."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pytest

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.model.urdf import example_urdf
from mjcf_models import leg

# Every supported feature: fullinertia, inertia from geoms (capsule by fromto, box with a mass,
# sphere, cylinder with a density, ellipsoid turned by xyaxes), default classes and childclass,
# euler in degrees, quat, axisangle, a hinge's anchor, a slide and a hinge in one body, a range,
# damping, a <frame> turning a body, zaxis, an <inertial> over geoms, and gravity of the
# <option>.
ARM = """
<mujoco model="arm">
  <compiler angle="degree" eulerseq="zyx"/>
  <option gravity="0.5 -1 -9.7"><flag contact="disable"/></option>
  <default>
    <joint damping="0.1"/>
    <default class="link">
      <geom type="capsule" size="0.05"/>
      <default class="heavy"><geom density="3000"/></default>
    </default>
  </default>
  <worldbody>
    <geom type="plane" size="1 1 0.1"/>
    <body name="base" pos="0 0 0.5" euler="10 20 30">
      <joint name="j1" type="hinge" axis="0 0 1" pos="0.01 0.02 0.03"/>
      <inertial pos="0.1 0 0" mass="2" fullinertia="0.2 0.25 0.3 0.01 0.02 0.03"/>
      <body name="upper" pos="0.2 0 0" quat="0.9 0.1 0.2 0.3" childclass="link">
        <joint name="j2" type="hinge" axis="0 1 1" range="-90 90"/>
        <geom fromto="0 0 0 0.4 0.1 0"/>
        <geom type="box" size="0.05 0.02 0.03" pos="0.4 0 0" mass="0.5" euler="0 45 0"/>
        <frame pos="0.4 0 0" axisangle="0 0 1 15">
          <body name="slider" axisangle="1 1 0 30">
            <joint name="s" type="slide" axis="1 0 0"/>
            <joint name="j3" type="hinge" axis="0 0 1" pos="0.1 0 0"/>
            <geom type="sphere" size="0.07" pos="0.1 0.05 0" class="heavy"/>
            <geom type="cylinder" size="0.03 0.1" density="500"/>
            <geom type="ellipsoid" size="0.03 0.04 0.05" pos="0 0 0.1" xyaxes="0 1 0 -1 0 0"/>
            <body name="hand" pos="0.2 0 0" zaxis="0 1 1">
              <joint name="j4" axis="1 0 0" pos="0 0 -0.05"/>
              <inertial pos="0 0.1 0" quat="0.9 0 0.1 0.2" mass="0.3"
                        diaginertia="0.01 0.02 0.025"/>
              <geom type="box" size="0.5 0.5 0.5"/>
            </body>
          </body>
        </frame>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def states(nq: int, count: int = 4, seed: int = 0):
    rng = np.random.default_rng(seed)
    return [(rng.uniform(-1, 1, nq), rng.uniform(-2, 2, nq), rng.uniform(-3, 3, nq))
            for _ in range(count)]


def mujoco_terms(model, q, v, tau):
    """M, bias, qacc (tau applied, damping acting) and the inverse dynamics of that qacc."""
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:], data.qfrc_applied[:] = q, v, tau
    mujoco.mj_forward(model, data)
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    bias, qacc, passive = data.qfrc_bias.copy(), data.qacc.copy(), data.qfrc_passive.copy()
    mujoco.mj_inverse(model, data)
    return M, bias, qacc, data.qfrc_inverse.copy(), passive


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    path = tmp_path_factory.mktemp("mjcf") / "arm.xml"
    path.write_text(ARM)
    return lagrangian.load(path), mujoco.MjModel.from_xml_path(str(path))


def test_hand_written_arm_agrees_with_mujoco(arm):
    system, model = arm
    assert list(system.joint_names) == [model.joint(i).name for i in range(model.njnt)]
    rigid = system.dynamics(backend="numpy")
    damped = system.dynamics(backend="numpy", actuators=True)
    for q, v, tau in states(model.nq):
        M, bias, qacc, inverse, passive = mujoco_terms(model, q, v, tau)
        assert np.allclose(rigid.mass_matrix(q), M, rtol=0, atol=1e-9)
        assert np.allclose(rigid.bias_forces(q, v), bias, rtol=0, atol=1e-9)
        assert np.allclose(passive, -0.1 * v, rtol=0, atol=1e-12)  # the default class's damping
        assert np.allclose(damped.forward_dynamics(q, v, tau), qacc, rtol=0, atol=1e-9)
        # mj_inverse: the force that gives qacc, passive forces acting: tau itself
        assert np.allclose(inverse, tau, rtol=0, atol=1e-9)
        assert np.allclose(damped.inverse_dynamics(q, v, qacc), tau, rtol=0, atol=1e-9)
    assert system.joint_limits["j2"] == pytest.approx((-np.pi / 2, np.pi / 2))


def mjcf_written_by_mujoco(urdf_path, tmp_path, strip_mimic: bool = False):
    """The MJCF MuJoCo writes (mj_saveLastXML) from a URDF, meshes left out."""
    from lxml import etree

    root = etree.parse(str(urdf_path)).getroot()
    for tag in ("visual", "collision") + (("mimic",) if strip_mimic else ()):
        for element in list(root.iter(tag)):
            element.getparent().remove(element)
    mujoco.MjModel.from_xml_string(etree.tostring(root).decode())
    out = tmp_path / f"{urdf_path.stem}.xml"
    mujoco.mj_saveLastXML(str(out), mujoco.MjModel.from_xml_string(
        etree.tostring(root).decode()))
    return out


@pytest.mark.parametrize("name", ["two_link_arm", "ur5", "solo12", "panda"])
def test_mjcf_written_by_mujoco_from_a_urdf(name, tmp_path):
    """MuJoCo reads the URDF and writes MJCF; that MJCF read by us and by MuJoCo agree on M, the
    bias, forward (mj_forward) and inverse dynamics (mj_inverse) to 1e-9, and with our reading
    of the URDF to MuJoCo's printed precision (6 digits). The Panda's mimic finger is made a
    joint of its own here (MuJoCo writes a mimic as a joint equality, read back as the mimic:
    tests/model/test_mjcf_state.py)."""
    urdf = example_urdf(name)
    if urdf is None:
        pytest.skip(f"{name}: example-robot-data is not installed")
    path = mjcf_written_by_mujoco(urdf, tmp_path, strip_mimic=name == "panda")
    model = mujoco.MjModel.from_xml_path(str(path))
    # the states run past the joints' ranges: MuJoCo's limit constraints off, as ours
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_LIMIT)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        system = lagrangian.load(path)
    ours = system.dynamics(backend="numpy")
    damped = system.dynamics(backend="numpy", actuators=True)  # the Panda's damping 0.3
    assert ours.nv == model.nv
    for q, v, tau in states(model.nq, 2):
        M, bias, qacc, inverse, _ = mujoco_terms(model, q, v, tau)
        assert np.allclose(ours.mass_matrix(q), M, rtol=0, atol=1e-9)
        assert np.allclose(ours.bias_forces(q, v), bias, rtol=0, atol=1e-9)
        assert np.allclose(inverse, tau, rtol=0, atol=1e-9)  # MuJoCo's FD and ID consistent
        assert np.allclose(damped.forward_dynamics(q, v, tau), qacc, rtol=0, atol=1e-9)
        assert np.allclose(damped.inverse_dynamics(q, v, qacc), tau, rtol=0, atol=1e-9)
    if name == "two_link_arm":  # the same robot as URDF: MuJoCo printed its short numbers whole
        urdf_system = lagrangian.load(urdf).dynamics(backend="numpy")
        for q, v, _ in states(model.nq, 2):
            assert np.allclose(urdf_system.mass_matrix(q), ours.mass_matrix(q), atol=1e-12)
            assert np.allclose(urdf_system.bias_forces(q, v), ours.bias_forces(q, v),
                               atol=1e-12)


REFUSALS = [
    ('<body><joint type="ball" damping="1"/><geom size="0.1"/></body>',
     "damping on a ball joint is not supported"),
    ('<body><joint/><geom size="0.1"/><body><freejoint/><geom size="0.1"/></body></body>',
     "a free joint must be the only joint of a body at the top of the worldbody"),
    ('<body><joint/><freejoint/><geom size="0.1"/></body>', "a free joint must be the only"),
    ('<body><joint ref="10"/><geom size="0.1"/></body>', "ref other than 0"),
    ('<body><joint stiffness="3"/><geom size="0.1"/></body>', "stiffness other than 0"),
    ('<body><joint type="spin"/><geom size="0.1"/></body>', "unknown joint type 'spin'"),
    ('<body><joint/><geom type="mesh" mesh="m"/></body>', "inertia of a mesh geom"),
    ('<body><joint/><geom type="box" size="0.1 0.1"/></body>', "a box needs 3 positive"),
    ('<body><joint/><geom size="0.1" class="nope"/></body>', "no default class 'nope'"),
    ('<body><joint axis="0 0 0"/><geom size="0.1"/></body>', "the axis has zero length"),
    ('<body pos="0 0 nan"><joint/><geom size="0.1"/></body>', "not finite"),
    ('<body quat="1 0 0"><joint/><geom size="0.1"/></body>', "expected 4 numbers, got 3"),
    ('<body><joint range="1 -1"/><geom size="0.1"/></body>', "the range 1 -1 is empty"),
    ('<body><geom size="0.1"/></body>', "no hinge, slide or ball joint"),
]


@pytest.mark.parametrize("body, message", REFUSALS)
def test_unsupported_or_bad_bodies_refused_in_one_line(body, message, tmp_path):
    path = tmp_path / "robot.xml"
    path.write_text(f"<mujoco><worldbody>{body}</worldbody></mujoco>")
    with pytest.raises(ModelError, match=message) as caught:
        lagrangian.load(path)
    assert str(caught.value).startswith(str(path)) and "\n" not in str(caught.value)


@pytest.mark.parametrize("document, message", [
    ("<mujoco><worldbody/><tendon><fixed name='t'/></tendon></mujoco>", "tendons are not"),
    ("<mujoco><equality><weld body1='a'/></equality><worldbody/></mujoco>", "equality"),
    ("<mujoco><include file='other.xml'/></mujoco>", "<include> of other files"),
    ("<mujoco><actuator><muscle joint='j'/></actuator><worldbody/></mujoco>",
     "actuator with dynamics"),
    ('<!DOCTYPE m [<!ENTITY x "y">]><mujoco><worldbody/></mujoco>', "DOCTYPE"),
    ("<world/>", "not <mujoco> \\(MJCF\\) or <robot> \\(URDF\\)"),
    ("<mujoco><worldbody>", "not well-formed XML"),
    ("<mujoco><compiler angle='grad'/><worldbody/></mujoco>", "neither degree nor radian"),
])
def test_unsupported_or_bad_documents_refused_in_one_line(document, message, tmp_path):
    path = tmp_path / "robot.xml"
    path.write_text(document)
    with pytest.raises(ModelError, match=message) as caught:
        lagrangian.load(path)
    assert str(caught.value).startswith(str(path)) and "\n" not in str(caught.value)


def test_armature_kept_for_the_actuators_agrees_with_mujoco(arm, tmp_path):
    """MuJoCo's armature adds to M's diagonal: kept in the model (source_armature) and added
    by System.dynamics(actuators=True) with the damping, matching MuJoCo's M, mj_forward's qacc
    and mj_inverse; the rigid body's M leaves it out, and armature= overrides the file's."""
    armed = ARM.replace('name="j1" type="hinge"', 'name="j1" armature="0.2" type="hinge"') \
        .replace('name="s" type="slide"', 'name="s" armature="0.05" type="slide"')
    path = tmp_path / "armed.xml"
    path.write_text(armed)
    system = lagrangian.load(path)
    assert dict(system.model.source_armature) == {"j1": 0.2, "s": 0.05}
    model = mujoco.MjModel.from_xml_path(str(path))
    dynamics = system.dynamics(backend="numpy", actuators=True)
    rigid = system.dynamics(backend="numpy")
    for q, v, tau in states(model.nq, 2):
        M, _, qacc, inverse, _ = mujoco_terms(model, q, v, tau)
        assert np.allclose(dynamics.mass_matrix(q), M, rtol=0, atol=1e-9)
        assert np.allclose(rigid.mass_matrix(q), M - np.diag(model.dof_armature), atol=1e-9)
        assert np.allclose(dynamics.forward_dynamics(q, v, tau), qacc, rtol=0, atol=1e-9)
        assert np.allclose(dynamics.inverse_dynamics(q, v, qacc), tau, rtol=0, atol=1e-9)
    given = system.dynamics(backend="numpy", actuators=True, armature={"j1": 0.5})
    assert given.actuators["j1"]["armature"] == 0.5 and given.actuators["s"]["armature"] == 0.05


def test_a_urdf_saved_as_xml_is_read_as_a_urdf(tmp_path):
    path = tmp_path / "arm.xml"
    path.write_text(example_urdf("two_link_arm").read_text())
    assert lagrangian.load(path).coordinates == lagrangian.load("two_link_arm").coordinates


QUADRUPED_LEG = leg(trunk_height=0.4)


def test_a_free_joint_with_floating_base_is_mujocos_body_in_pinocchios_layout(tmp_path):
    """q = [p, qx, qy, qz, qw, joints] for MuJoCo's [p, qw, qx, qy, qz, joints]; v = T v_mj
    with T = diag(R^T, 1, ...) (MuJoCo's linear velocity is in world axes): so M_mj = T^T M T
    and, the accelerations differing by T' v, bias_mj = T^T (M T' v_mj + b)."""
    path = tmp_path / "leg.xml"
    path.write_text(QUADRUPED_LEG)
    system = lagrangian.load(path, floating_base=True)
    dynamics = system.dynamics(backend="numpy")
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    assert (dynamics.nq, dynamics.nv) == (model.nq, model.nv) == (9, 8)
    rng = np.random.default_rng(4)
    for _ in range(3):
        quaternion = rng.normal(size=4)
        quaternion /= np.linalg.norm(quaternion)
        data.qpos[:] = np.r_[rng.normal(size=3), quaternion, rng.uniform(-1, 1, 2)]
        data.qvel[:] = rng.normal(size=8)
        mujoco.mj_forward(model, data)
        M = np.zeros((8, 8))
        mujoco.mj_fullM(model, data, M)
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, quaternion)
        R = R.reshape(3, 3)
        q = np.r_[data.qpos[:3], quaternion[1:], quaternion[0], data.qpos[7:]]
        T = np.eye(8)
        T[:3, :3] = R.T
        w = data.qvel[3:6]
        T_dot = np.zeros((8, 8))
        T_dot[:3, :3] = -np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]) @ R.T
        ours = dynamics.mass_matrix(q)
        assert np.allclose(T.T @ ours @ T, M, rtol=0, atol=1e-9)
        bias = T.T @ (ours @ T_dot @ data.qvel + dynamics.bias_forces(q, T @ data.qvel))
        assert np.allclose(bias, data.qfrc_bias, rtol=0, atol=1e-9)
    with pytest.raises(ModelError, match="only joint of the one body at the top"):
        bad = tmp_path / "bad.xml"
        bad.write_text(QUADRUPED_LEG.replace('<joint name="hip"', '<freejoint/><joint name="hip"'))
        lagrangian.load(bad, floating_base=True)
