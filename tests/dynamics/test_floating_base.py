"""A floating base (a free-flyer root joint, nq = n + 7, nv = n + 6): the dynamics and the frames of
legged, humanoid and flying robots against Pinocchio's buildModelFromUrdf(path,
JointModelFreeFlyer()) (skipped where Pinocchio or example-robot-data is missing), the
configuration manifold against pin.integrate, and Newton's law for the whole robot without
Pinocchio."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

import lagrangian
from robot_data import robots as _robots

pytest.importorskip("yourdfpy")

# A base with its own origin under a URDF floating joint, a leg of two revolute joints and a
# prismatic one, a fixed foot: Pinocchio reads the floating joint as a free flyer.
FLOATING_URDF = """<?xml version="1.0"?>
<robot name="hopper">
  <link name="world"/>
  <link name="trunk"><inertial><origin xyz="0.02 -0.01 0.05" rpy="0.1 0.2 -0.1"/><mass value="3.0"/>
    <inertia ixx="0.05" ixy="0.002" ixz="-0.001" iyy="0.07" iyz="0.003" izz="0.06"/></inertial></link>
  <link name="thigh"><inertial><origin xyz="0 0 -0.15"/><mass value="0.8"/>
    <inertia ixx="0.006" ixy="0" ixz="0.0004" iyy="0.006" iyz="0" izz="0.001"/></inertial></link>
  <link name="shank"><inertial><origin xyz="0.01 0 -0.1"/><mass value="0.4"/>
    <inertia ixx="0.002" ixy="0.0001" ixz="0" iyy="0.002" iyz="0" izz="0.0004"/></inertial></link>
  <link name="rod"><inertial><mass value="0.1"/>
    <inertia ixx="0.0001" ixy="0" ixz="0" iyy="0.0001" iyz="0" izz="0.00002"/></inertial></link>
  <link name="foot"><inertial><origin xyz="0 0 -0.02"/><mass value="0.05"/>
    <inertia ixx="0.00001" ixy="0" ixz="0" iyy="0.00001" iyz="0" izz="0.00001"/></inertial></link>
  <joint name="free" type="floating"><parent link="world"/><child link="trunk"/>
    <origin xyz="0.1 0.2 0.5" rpy="0.3 -0.2 0.4"/></joint>
  <joint name="hip" type="revolute"><parent link="trunk"/><child link="thigh"/>
    <origin xyz="0.1 0.05 -0.05" rpy="0 0 0.2"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="knee" type="revolute"><parent link="thigh"/><child link="shank"/>
    <origin xyz="0 0 -0.3"/><axis xyz="0.6 0.8 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="slide" type="prismatic"><parent link="shank"/><child link="rod"/>
    <origin xyz="0 0 -0.2" rpy="0.1 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-0.1" upper="0.1" effort="1" velocity="1"/></joint>
  <joint name="ankle" type="fixed"><parent link="rod"/><child link="foot"/>
    <origin xyz="0 0 -0.05"/></joint>
</robot>
"""
REFERENCES = ("world", "local", "local_world_aligned")




def _layout(model, ours):
    """Indices into Pinocchio's q and v of ours: the base first, then our joints by name
    (Pinocchio visits sibling joints by name, the URDF's reader in the file's order)."""
    names = [j.name for j in ours.tree.joints[1:]]
    ids = [model.getJointId(name) for name in names]
    return (np.array(list(range(7)) + [model.idx_qs[i] for i in ids]),
            np.array(list(range(6)) + [model.idx_vs[i] for i in ids]))


def _close(ours, theirs):
    """To 1e-12 of the size of the reference (SI numbers of order 1 to 100)."""
    theirs = np.asarray(theirs)
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-12 * max(1.0, np.abs(theirs).max()))


def _close_forward(ours, theirs, mass, bias, tau):
    """q_ddot to 1e-12 of its size times M's condition number beyond 1e4 (the fingers of a
    humanoid's hands: 1e7 rad/s^2 from 1e-7 kg m^2), and M q_ddot + b = tau to 1e-12."""
    scale = max(1.0, np.abs(theirs).max()) * max(1.0, np.linalg.cond(mass) / 1e4)
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-12 * scale)
    # the backward error of a solve, against |M| |q_ddot| (not |M q_ddot|, which cancels)
    force = max(1.0, np.abs(tau).max(), np.abs(bias).max(), (np.abs(mass) @ np.abs(ours)).max())
    np.testing.assert_allclose(mass @ ours + bias, tau, rtol=0, atol=1e-12 * force)


def _compare_dynamics(model, ours, states: int = 4, seed: int = 1):
    import pinocchio as pin

    data = model.createData()
    assert (ours.nq, ours.nv) == (model.nq, model.nv)
    iq, iv = _layout(model, ours)
    rng = np.random.default_rng(seed)
    q = np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
                  for _ in range(states)])
    v, a, tau = (rng.uniform(-1, 1, (states, model.nv)) for _ in range(3))
    mass, bias = ours.mass_matrix(q[:, iq]), ours.bias_forces(q[:, iq], v[:, iv])
    gravity, inverse = ours.gravity(q[:, iq]), ours.inverse_dynamics(q[:, iq], v[:, iv], a[:, iv])
    forward = ours.forward_dynamics(q[:, iq], v[:, iv], tau[:, iv])
    kinetic, potential = ours.kinetic_energy(q[:, iq], v[:, iv]), ours.potential_energy(q[:, iq])
    for k in range(states):
        m = pin.crba(model, data, q[k]).copy()
        _close(mass[k], (np.triu(m) + np.triu(m, 1).T)[np.ix_(iv, iv)])
        _close(bias[k], pin.rnea(model, data, q[k], v[k], np.zeros(model.nv))[iv])
        _close(gravity[k], pin.computeGeneralizedGravity(model, data, q[k])[iv])
        _close(inverse[k], pin.rnea(model, data, q[k], v[k], a[k])[iv])
        _close_forward(forward[k], pin.aba(model, data, q[k], v[k], tau[k])[iv],
                       mass[k], bias[k], tau[k, iv])
        _close(kinetic[k], pin.computeKineticEnergy(model, data, q[k], v[k]))
        _close(potential[k], pin.computePotentialEnergy(model, data, q[k]))


@pytest.mark.parametrize("robot", [
    "solo_description/robots/solo12.urdf",
    "anymal_b_simple_description/robots/anymal.urdf",
    "go1_description/urdf/go1.urdf",
    "talos_data/robots/talos_reduced.urdf",
    "borinot_description/urdf/borinot_flying_arm_2.urdf",
])
def test_floating_robots_match_pinocchio(robot):
    """Quadrupeds whose trunk is the root link or welded below a massless one, a humanoid, a
    flying arm: M, bias, g, inverse and forward dynamics and the energies to 1e-12."""
    import pinocchio as pin

    path = _robots() / robot
    if not path.is_file():
        pytest.skip(f"{robot} is not in this example-robot-data")
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    ours = lagrangian.load(path, floating_base=True).dynamics(backend="numpy")
    assert ours.coordinates[:7] == ("base_x", "base_y", "base_z", "base_qx", "base_qy",
                                    "base_qz", "base_qw")
    assert ours.velocity_names[:6] == ("base_vx", "base_vy", "base_vz", "base_wx", "base_wy",
                                       "base_wz")
    _compare_dynamics(model, ours)


def _pinocchio_frame(model, name):
    import pinocchio as pin

    for kind in (pin.FrameType.BODY, pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT):
        if model.existFrame(name, kind):
            return model.getFrameId(name, kind)
    raise AssertionError(f"Pinocchio has no frame {name}")


def _compare_frames(model, ours, states: int = 3):
    import pinocchio as pin

    data = model.createData()
    iq, iv = _layout(model, ours)
    q = np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
                  for _ in range(states)])
    kinematics = ours.kinematics
    for name in ours.frames:
        frame = _pinocchio_frame(model, name)
        placement = kinematics.placement(q[:, iq], name)
        jacobians = {ref: kinematics.jacobian(q[:, iq], name, ref) for ref in REFERENCES}
        for k in range(states):
            pin.forwardKinematics(model, data, q[k])
            pin.updateFramePlacements(model, data)
            pin.computeJointJacobians(model, data, q[k])
            _close(placement[k], data.oMf[frame].homogeneous)
            for ref in REFERENCES:
                expected = pin.getFrameJacobian(model, data, frame,
                                                getattr(pin.ReferenceFrame, ref.upper()))
                _close(jacobians[ref][k], expected[:, iv])
    centre, centre_jacobian = ours.center_of_mass(q[:, iq]), ours.center_of_mass_jacobian(q[:, iq])
    for k in range(states):
        _close(centre[k], pin.centerOfMass(model, data, q[k]))
        _close(centre_jacobian[k], pin.jacobianCenterOfMass(model, data, q[k])[:, iv])


def test_solo_frames_match_pinocchio():
    """Every link and joint frame of Solo12 on its floating base, its Jacobian in the three
    references (the base's six columns first), the centre of mass and its Jacobian."""
    import pinocchio as pin

    path = _robots() / "solo_description/robots/solo12.urdf"
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    ours = lagrangian.load(path, floating_base=True).dynamics(backend="numpy")
    assert "root_joint" in ours.frames and "base_link" in ours.frames
    _compare_frames(model, ours)


@pytest.mark.parametrize("backend", ["numpy", "auto"])  # auto: generated C where it compiles
def test_a_urdf_floating_joint_is_the_free_flyer(tmp_path, backend):
    """A URDF floating joint (with an origin of its own) is read as Pinocchio reads it."""
    pin = pytest.importorskip("pinocchio")
    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    model = pin.buildModelFromXML(FLOATING_URDF)
    ours = lagrangian.load(path).dynamics(backend=backend)
    assert (ours.nq, ours.nv, ours.tree.joints[0].name) == (10, 9, "free")
    _compare_dynamics(model, ours, states=6)  # beyond the vector lanes of the C batch
    _compare_frames(model, ours)
    with pytest.raises(lagrangian.InputError, match="norm 3") as info:
        ours.forward_dynamics(np.r_[0, 0, 0, 0, 0, 0, 3.0, 0, 0, 0], np.zeros(9), np.zeros(9))
    assert info.value.field == "q"


def test_integrate_and_difference_match_pinocchio(tmp_path):
    """q (+) v on the manifold and its inverse, against pin.integrate and pin.difference; the
    quaternion comes back of norm 1."""
    pin = pytest.importorskip("pinocchio")
    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    model = pin.buildModelFromXML(FLOATING_URDF)
    ours = lagrangian.load(path).dynamics()
    rng = np.random.default_rng(4)
    for scale in (1e-9, 0.1, 3.0):  # the small-angle series, and beyond a half turn
        q = pin.randomConfiguration(model, -np.ones(10), np.ones(10))
        v = scale * rng.uniform(-1, 1, 9)
        reached = ours.integrate(q, v, 0.5)
        expected = pin.integrate(model, q, 0.5 * v)
        if np.dot(reached[3:7], expected[3:7]) < 0:  # q and -q: one rotation
            expected[3:7] *= -1
        _close(reached, expected)
        assert abs(np.linalg.norm(reached[3:7]) - 1) < 1e-15
        _close(ours.difference(q, reached), 0.5 * v)
        _close(ours.difference(q, reached), pin.difference(model, q, reached))


def test_newton_for_the_whole_robot(tmp_path):
    """Without Pinocchio: at rest, whatever the joint torques, the centre of mass of a free
    robot falls at g (its internal forces cancel), and without gravity it stays still."""
    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    for gravity in ((0.0, 0.0, -9.81), (1.0, -2.0, -3.0)):
        robot = lagrangian.load(path, gravity=gravity).dynamics(backend="numpy")
        rng = np.random.default_rng(2)
        q = robot.integrate(np.r_[0, 0, 0, 0, 0, 0, 1, 0, 0, 0], rng.uniform(-1, 1, (5, 9)))
        tau = np.concatenate([np.zeros((5, 6)), rng.uniform(-5, 5, (5, 3))], axis=1)
        a = robot.forward_dynamics(q, np.zeros(9), tau)
        accel = np.einsum("nij,nj->ni", robot.center_of_mass_jacobian(q), a)
        np.testing.assert_allclose(accel, np.broadcast_to(gravity, (5, 3)), atol=1e-12)


def test_fixed_base_results_are_unchanged_and_say_so_once():
    """Without the option a legged robot is bolted as before, and says so once, naming the
    option; a root link named 'world' or a massless root says nothing."""
    path = _robots() / "solo_description/robots/solo12.urdf"
    fixed = lagrangian.load(path)
    lines = [w for w in fixed.warnings() if "floating" in w]
    assert len(lines) == 1 and "--floating-base" in lines[0] and "base_link" in lines[0]
    assert len(fixed.model.coordinates) == 12 and not fixed.model.kinematic_tree.floating_base
    assert not [w for w in lagrangian.load(path, floating_base=True).warnings()
                if "floating" in w]
    assert not [w for w in lagrangian.load("two_link_arm").warnings() if "floating" in w]


def test_bad_input_is_refused_in_one_line(tmp_path):
    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    system = lagrangian.load(path)
    robot = system.dynamics()
    q = np.r_[0, 0, 0, 0, 0, 0, 1.0, 0, 0, 0]
    with pytest.raises(lagrangian.InputError, match="norm 0.9") as info:
        robot.mass_matrix(np.r_[q[:6], 0.9, q[7:]])
    assert info.value.field == "q"
    with pytest.raises(lagrangian.InputError, match="in state 1"):
        robot.placement(np.stack([q, np.r_[q[:6], 2.0, q[7:]]]), "foot")
    robot.mass_matrix(np.r_[q[:6], 1 + 1e-7, q[7:]])  # within QUATERNION_TOLERANCE
    with pytest.raises(lagrangian.InputError, match=r"expected 9 values \(base_vx"):
        robot.bias_forces(q, np.zeros(10))
    with pytest.raises(lagrangian.InputError, match="expected 10 values"):
        robot.jacobian(np.zeros(9), "foot")
    # the regressor checks the quaternion and the widths as the dynamics do
    with pytest.raises(lagrangian.InputError, match="norm 0.9") as info:
        robot.regressor(np.r_[q[:6], 0.9, q[7:]], np.zeros(9), np.zeros(9))
    assert info.value.field == "q"
    with pytest.raises(lagrangian.InputError, match=r"expected 10 values \(base_x"):
        robot.regressor(q[:9], np.zeros(9), np.zeros(9))
    with pytest.raises(lagrangian.ModelError, match="already floats the base"):
        lagrangian.load(path, floating_base=True)
    with pytest.raises(lagrangian.InputError, match="only a URDF model has a base to float"):
        lagrangian.load("pendulum", floating_base=True)
    with pytest.raises(lagrangian.ModelError, match="no equations in its joint coordinates"):
        system.equations_of_motion()
    for at_rest in (system.equilibria, system.linearize):  # one line, not a width's fault
        with pytest.raises(lagrangian.ModelError, match="no rest in its joint coordinates"):
            at_rest()
    with pytest.raises(lagrangian.ModelError, match="unknown name 'kneee'"):  # the stop's names
        system.simulate(0.1, stop_when="kneee > 1")
    bad = tmp_path / "bad.urdf"
    bad.write_text(FLOATING_URDF.replace('name="knee" type="revolute"', 'name="knee" type="floating"'))
    with pytest.raises(lagrangian.ModelError, match="joint 'knee'.limit: a floating joint has no "
                       "limits"):  # a floating knee is a free flyer below the root, unlimited
        lagrangian.load(bad)


def test_command_prints_the_layout_and_refuses_a_bad_quaternion(cli, tmp_path):
    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    result = cli("dynamics", str(path), "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert (document["nq"], document["nv"]) == (10, 9)
    assert document["coordinates"][3:10] == ["base_qx", "base_qy", "base_qz", "base_qw", "hip",
                                             "knee", "slide"]
    assert document["velocities"][:6] == ["base_vx", "base_vy", "base_vz", "base_wx", "base_wy",
                                          "base_wz"]
    assert document["q"][:7] == [0, 0, 0, 0, 0, 0, 1] and len(document["mass_matrix"]) == 9
    bad = cli("dynamics", str(path), "--q", "0,0,0,0,0,0,0.5,0,0,0")
    assert bad.code == 2 and bad.err.startswith("error: --q: the base quaternion")
    result = cli("kinematics", str(path), "--frame", "foot", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert (document["nq"], document["nv"], len(document["jacobian"][0])) == (10, 9, 9)
    # base_vx (m/s along the trunk's own x) moves the foot along the trunk's x in the world
    trunk = lagrangian.load(path).dynamics().placement(document["q"], "trunk")
    np.testing.assert_allclose(np.array(document["jacobian"])[:3, 0], trunk[:3, 0], atol=1e-12)


@pytest.mark.slow
def test_every_floating_robot_of_example_robot_data_matches_pinocchio():
    """Every robot of example-robot-data that both load with a free flyer and the same
    coordinates (no continuous joint: Pinocchio writes those as cos/sin pairs), dynamics and
    frames to 1e-12."""
    import pinocchio as pin

    files = sorted(_robots().glob("*/urdf/*.urdf")) + sorted(_robots().glob("*/robots/*.urdf"))
    compared = []
    for robot in ("solo_description/robots/solo12.urdf", "talos_data/robots/talos_reduced.urdf"):
        path = _robots() / robot  # and two in generated C
        model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
        _compare_dynamics(model, lagrangian.load(path, floating_base=True).dynamics(backend="c"))
    for path in files:
        try:
            model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
            ours = lagrangian.load(path, floating_base=True).dynamics(backend="numpy")
        except Exception:  # noqa: BLE001 - refused by either: the fixed-base tests judge that
            continue
        if (ours.nq, ours.nv) != (model.nq, model.nv):
            continue
        _compare_dynamics(model, ours, states=2)
        compared.append(path.name)
    print(f"{len(compared)} robots compared: {', '.join(compared)}")
    assert len(compared) >= 25


@pytest.mark.skipif(not (shutil.which("cc") or shutil.which("gcc")), reason="no C compiler")
def test_standalone_c_of_a_floating_base(tmp_path):
    """The standalone C (C99, libm) of the hopper takes q of HOPPER_NQ = 10 and v of
    HOPPER_N = 9 and gives the numpy recursions' numbers."""
    import ctypes
    import subprocess

    from lagrangian.output.files import write_c

    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    system = lagrangian.load(path)
    code = system.to_c()
    assert "#define HOPPER_N 9\n#define HOPPER_NQ 10" in code.header
    write_c(code, tmp_path / "gen")
    library = tmp_path / "hopper.so"
    subprocess.run([shutil.which("cc") or shutil.which("gcc"), "-std=c99", "-O2", "-Wall",
                    "-Werror", "-pedantic", "-shared", "-fPIC", str(tmp_path / "gen/hopper.c"),
                    "-o", str(library), "-lm"], check=True)
    c = ctypes.CDLL(str(library))
    params = (ctypes.c_double * 4).in_dll(c, "hopper_parameters")
    ours = system.dynamics(backend="numpy")
    rng = np.random.default_rng(8)
    q = ours.integrate(np.r_[0.1, 0.2, 0.3, 0, 0, 0, 1, 0.2, -0.4, 0.05], rng.uniform(-1, 1, 9))
    v, tau = rng.uniform(-1, 1, 9), rng.uniform(-1, 1, 9)
    Q, V, TAU = ((ctypes.c_double * len(x))(*x) for x in (q, v, tau))
    M, out = (ctypes.c_double * 81)(), (ctypes.c_double * 9)()
    c.hopper_mass_matrix(Q, params, M)
    _close(np.array(M).reshape(9, 9), ours.mass_matrix(q))
    c.hopper_bias_forces(Q, V, params, out)
    _close(np.array(out), ours.bias_forces(q, v))
    assert c.hopper_forward_dynamics(Q, V, TAU, params, out) == 0
    _close(np.array(out), ours.forward_dynamics(q, v, tau))
