"""MJCF armature, joint equalities and a free joint against MuJoCo: M (mj_fullM), the bias
(mj_rne, qacc = 0), inverse dynamics (mj_rne with qacc) and forward dynamics, MuJoCo's numbers
carried into our coordinates by the change of variables qvel = G v (model/mjcf_state.py):

    M = G^T M_mj G,   tau = G^T qfrc,   b = G^T (M_mj G' v + b_mj).

MuJoCo holds a joint equality softly, so the constrained forward dynamics it stands for is
solved here from its own M, bias and passive forces: a = (G^T M_mj G)^-1 G^T (qfrc_applied +
qfrc_passive - M_mj G' v - b_mj); without an equality, mj_forward's qacc itself."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import lagrangian
from lagrangian.errors import InputError, ModelError
from lagrangian.model.mjcf_state import mujoco_layout

# A floating trunk, a hip with armature, a knee with damping and armature, and a toe that
# follows the knee (toe = 0.1 - 0.5 knee) with armature and damping of its own; degrees.
LEG = """
<mujoco model="leg">
  <compiler angle="degree"/>
  <default><joint damping="0.05"/></default>
  <worldbody>
    <body name="trunk" pos="0 0 0.4">
      <freejoint name="root"/>
      <inertial pos="0.01 0.02 -0.01" mass="5" fullinertia="0.1 0.2 0.25 0.01 -0.02 0.03"/>
      <body name="thigh" pos="0.2 0.1 0" euler="10 0 20">
        <joint name="hip" axis="0 1 0" pos="0 0 0.02" armature="0.3" damping="0"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03"/>
        <body name="shin" pos="0 0 -0.3">
          <joint name="knee" axis="1 1 0" armature="0.02" range="-90 90"/>
          <geom type="box" size="0.02 0.03 0.15" pos="0 0 -0.15"/>
          <body name="foot" pos="0 0 -0.3">
            <joint name="toe" axis="0 1 0" armature="0.01" damping="0.2"/>
            <geom type="sphere" size="0.04" pos="0.05 0 0"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <equality><joint joint1="toe" joint2="knee" polycoef="0.1 -0.5 0 0 0"/></equality>
</mujoco>
"""


def skew(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def rotation(quaternion_wxyz):
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, np.asarray(quaternion_wxyz, float))
    return R.reshape(3, 3)


def change(layout, qpos, qvel):
    """G = d qvel / d v and G' v at (qpos, qvel), built from the joints and MuJoCo's R."""
    G = np.zeros((layout.nv, layout.our_nv))
    Gdot_v = np.zeros(layout.nv)
    base = 0
    if layout.floating:
        R = rotation(qpos[3:7])
        G[:3, :3], G[3:6, 3:6] = R, np.eye(3)
        v_body, w = R.T @ qvel[:3], qvel[3:6]
        Gdot_v[:3] = R @ skew(w) @ v_body  # d/dt (R v_b) at constant v_b
        base = 6
    for k, (c, multiplier, _, _) in enumerate(layout.joints):
        G[base + k, base + c] = multiplier
    return G, Gdot_v


def mujoco_numbers(model, qpos, qvel, qacc=None):
    """M, the bias (rne at qacc = 0), M qacc + bias (rne with the armature), and the passive
    forces."""
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = qpos, qvel
    mujoco.mj_forward(model, data)
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    bias = data.qfrc_bias.copy()
    inverse = None
    if qacc is not None:
        inverse = np.zeros(model.nv)
        data.qacc[:] = qacc
        mujoco.mj_rne(model, data, 1, inverse)
        inverse += model.dof_armature * qacc  # mj_rne is the rigid body's; M_mj holds them
    return M, bias, inverse, data.qfrc_passive.copy(), data


def random_state(layout, rng):
    """A state of ours: a unit quaternion, joints and rates at random (SI)."""
    quaternion = rng.normal(size=4)
    q = np.r_[rng.normal(size=3), quaternion / np.linalg.norm(quaternion),
              rng.uniform(-1, 1, layout.n)]
    return q, rng.normal(size=layout.our_nv), rng.normal(size=layout.our_nv)


@pytest.fixture(scope="module")
def leg(tmp_path_factory):
    path = tmp_path_factory.mktemp("mjcf_state") / "leg.xml"
    path.write_text(LEG)
    system = lagrangian.load(path, floating_base=True)
    return system, mujoco.MjModel.from_xml_path(str(path)), mujoco_layout(system)


def test_the_layouts_of_a_floating_leg_with_a_mimic_toe(leg):
    system, model, layout = leg
    assert (layout.nq, layout.nv) == (model.nq, model.nv) == (10, 9)
    assert (layout.our_nq, layout.our_nv) == (9, 8)
    assert [c.name for c in system.model.coordinates] == ["hip", "knee"]
    # the file's armature, the toe's folded onto the knee by its virtual work: k^2 I
    assert dict(system.model.source_armature) == pytest.approx(
        {"hip": 0.3, "knee": 0.02 + 0.25 * 0.01})
    rng = np.random.default_rng(3)
    q, v, a = random_state(layout, rng)
    qpos, qvel, qacc = layout.to_mujoco(q, v, a)
    assert qpos[3:7] == pytest.approx(np.r_[q[6], q[3:6]])  # w first
    assert qpos[9] == pytest.approx(0.1 - 0.5 * q[8])       # the toe: c0 + c1 knee
    back = layout.from_mujoco(qpos, qvel, qacc)
    for ours, again in zip((q, v, a), back, strict=True):
        assert np.allclose(ours, again, rtol=0, atol=1e-14)
    # MuJoCo's linear velocity in world axes: the trunk origin's velocity, as mj_objectVelocity
    # gives it for the body frame (world axes, flg_local 0); its angular velocity in body axes
    *_, data = mujoco_numbers(model, qpos, qvel)
    twist = np.zeros(6)
    mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_XBODY, 1, twist, 0)
    assert np.allclose(twist[3:], qvel[:3], atol=1e-12)
    assert np.allclose(rotation(qpos[3:7]) @ v[:3], qvel[:3], atol=1e-12)
    # the equality holds exactly at the converted state: MuJoCo's own residual is 0
    assert data.nefc >= 1 and abs(data.efc_pos[0]) < 1e-14
    # a batch converts row by row
    many = layout.to_mujoco(np.stack([q, q]), np.stack([v, 2 * v]))
    assert np.allclose(many[1][1], layout.to_mujoco(q, 2 * v)[1], atol=1e-15)


def test_armature_free_joint_and_equality_agree_with_mujoco(leg):
    system, model, layout = leg
    rigid = system.dynamics(backend="numpy")
    motors = system.dynamics(backend="numpy", actuators=True)  # armature and damping
    engine = system.dynamics(actuators=True)
    rng = np.random.default_rng(7)
    for _ in range(3):
        q, v, a = random_state(layout, rng)
        qpos, qvel = layout.to_mujoco(q, v)
        G, Gdot_v = change(layout, qpos, qvel)
        qacc = G @ a + Gdot_v
        assert np.allclose(layout.to_mujoco(q, v, a)[2], qacc, rtol=0, atol=1e-12)
        M_mj, bias_mj, inverse_mj, passive, _ = mujoco_numbers(model, qpos, qvel, qacc)
        M = G.T @ M_mj @ G
        bias = G.T @ (M_mj @ Gdot_v + bias_mj)
        for dynamics in (motors, engine):
            assert np.allclose(dynamics.mass_matrix(q), M, rtol=0, atol=1e-9)
            # the damping: MuJoCo's passive forces carried to ours
            assert np.allclose(dynamics.bias_forces(q, v),
                               bias - layout.force_from_mujoco(qpos, passive), rtol=0,
                               atol=1e-9)
            assert np.allclose(dynamics.inverse_dynamics(q, v, a),
                               layout.force_from_mujoco(qpos, inverse_mj - passive), rtol=0,
                               atol=1e-9)
            tau = rng.normal(size=layout.our_nv)
            expected = np.linalg.solve(M, tau + G.T @ passive - bias)
            assert np.allclose(dynamics.forward_dynamics(q, v, tau), expected, rtol=0,
                               atol=1e-9)
        # the armature is the actuators' alone: the rigid body's M is MuJoCo's without it
        armature = np.diag(model.dof_armature)
        assert np.allclose(rigid.mass_matrix(q), G.T @ (M_mj - armature) @ G, rtol=0,
                           atol=1e-9)


LEG_NO_MIMIC = LEG.replace('<equality><joint joint1="toe" joint2="knee" polycoef="0.1 -0.5 0 0 '
                           '0"/></equality>', "")


def test_mj_forward_itself_through_the_layout(tmp_path):
    """Without the equality, MuJoCo's own qacc (armature, damping, the free joint) converted to
    ours is our forward dynamics, and our tau converted to MuJoCo's gives that qacc."""
    path = tmp_path / "leg.xml"
    path.write_text(LEG_NO_MIMIC)
    system = lagrangian.load(path, floating_base=True)
    model = mujoco.MjModel.from_xml_path(str(path))
    layout = mujoco_layout(system)
    dynamics = system.dynamics(actuators=True)
    rng = np.random.default_rng(11)
    for _ in range(3):
        q, v, _ = random_state(layout, rng)
        tau = rng.normal(size=layout.our_nv)
        qpos, qvel = layout.to_mujoco(q, v)
        data = mujoco.MjData(model)
        data.qpos[:], data.qvel[:] = qpos, qvel
        data.qfrc_applied[:] = layout.force_to_mujoco(q, tau)
        mujoco.mj_forward(model, data)
        assert np.allclose(layout.force_from_mujoco(qpos, data.qfrc_applied), tau, atol=1e-12)
        _, _, a = layout.from_mujoco(qpos, qvel, data.qacc)
        assert np.allclose(dynamics.forward_dynamics(q, v, tau), a, rtol=0, atol=1e-9)


def test_the_panda_as_mujoco_writes_it_with_its_mimic_finger(tmp_path):
    """MuJoCo writes the URDF's mimic finger as a joint equality: read back as the mimic."""
    from lxml import etree

    from lagrangian.model.urdf import example_urdf

    urdf = example_urdf("panda")
    if urdf is None:
        pytest.skip("example-robot-data is not installed")
    root = etree.parse(str(urdf)).getroot()
    for tag in ("visual", "collision"):  # meshes left out
        for element in list(root.iter(tag)):
            element.getparent().remove(element)
    path = tmp_path / "panda.xml"
    mujoco.mj_saveLastXML(str(path), mujoco.MjModel.from_xml_string(etree.tostring(root).decode()))
    model = mujoco.MjModel.from_xml_path(str(path))
    assert model.neq == 1
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        system = lagrangian.load(path)
        from_urdf = lagrangian.load(urdf)
    assert system.coordinates == from_urdf.coordinates
    layout = mujoco_layout(system)
    assert (layout.nq, layout.our_nq) == (model.nq, model.nq - 1)
    dynamics = system.dynamics(backend="numpy")
    rng = np.random.default_rng(5)
    q, v = rng.uniform(-1, 1, layout.our_nq) * 0.04, rng.normal(size=layout.our_nv)
    qpos, qvel = layout.to_mujoco(q, v)
    G, Gdot_v = change(layout, qpos, qvel)
    M_mj, bias_mj, *_ = mujoco_numbers(model, qpos, qvel)
    assert np.allclose(dynamics.mass_matrix(q), G.T @ M_mj @ G, rtol=0, atol=1e-9)
    assert np.allclose(dynamics.bias_forces(q, v), G.T @ (M_mj @ Gdot_v + bias_mj), rtol=0,
                       atol=1e-9)


EQUALITY_REFUSALS = [
    ('<weld body1="a"/>', "a <weld> equality is not supported"),
    ('<connect body1="a" anchor="0 0 0"/>', "a <connect> equality is not supported"),
    ('<joint joint1="b" joint2="a" polycoef="0 1 0.5 0 0"/>', "degree above 1"),
    ('<joint joint1="b"/>', "joint1 'b' is held at 0"),
    ('<joint joint1="b" joint2="a" polycoef="0 1 0"/>', "expected 5 numbers, got 3"),
    ('<joint joint1="b" joint2="nope"/>', "no joint 'nope'"),
    ('<joint joint1="b" joint2="b"/>', "joint1 and joint2 are both 'b'"),
    ('<joint joint1="b" joint2="a"/><joint joint1="b" joint2="a"/>', "joint1 of two"),
    ('<joint joint1="b" joint2="a"/><joint joint1="a" joint2="b"/>', "a cycle of joint"),
]


@pytest.mark.parametrize("equality, message", EQUALITY_REFUSALS)
def test_other_equalities_refused_in_one_line(equality, message, tmp_path):
    path = tmp_path / "robot.xml"
    path.write_text("<mujoco><worldbody><body><joint name='a'/><geom size='0.1'/><body>"
                    "<joint name='b'/><geom size='0.1'/></body></body></worldbody>"
                    f"<equality>{equality}</equality></mujoco>")
    with pytest.raises(ModelError, match=message) as caught:
        lagrangian.load(path)
    assert str(caught.value).startswith(str(path)) and "\n" not in str(caught.value)


def test_an_inactive_equality_changes_nothing(tmp_path):
    path = tmp_path / "robot.xml"
    path.write_text("<mujoco><worldbody><body><joint name='a'/><geom size='0.1'/><body>"
                    "<joint name='b'/><geom size='0.1'/></body></body></worldbody><equality>"
                    "<joint joint1='b' joint2='a' active='false'/></equality></mujoco>")
    assert [c.name for c in lagrangian.load(path).model.coordinates] == ["a", "b"]


@pytest.mark.parametrize("joint, message", [
    ('<joint type="ball" name="shoulder" armature="0.1"/>',
     "joint 'shoulder'.*armature on a ball joint"),
    ('<joint type="free" damping="0.1"/>', "damping on a free joint"),
    ('<joint armature="-1"/>', "armature -1 is negative"),
])
def test_ball_joints_and_bad_losses_refused_in_one_line(joint, message, tmp_path):
    path = tmp_path / "robot.xml"
    path.write_text(f"<mujoco><worldbody><body>{joint}<geom size='0.1'/></body></worldbody>"
                    "</mujoco>")
    with pytest.raises(ModelError, match=message) as caught:
        lagrangian.load(path, floating_base=True)
    assert "\n" not in str(caught.value)


def test_the_layout_refuses_bad_widths_and_models_without_a_tree(leg):
    _, _, layout = leg
    with pytest.raises(InputError, match="expected 10 numbers a state.*lock"):
        layout.from_mujoco(np.zeros(9))
    with pytest.raises(InputError, match="norm"):
        layout.from_mujoco(np.zeros(10), np.zeros(9))
    with pytest.raises(ModelError, match="only a robot read from MJCF or URDF"):
        mujoco_layout(lagrangian.load("pendulum"))
