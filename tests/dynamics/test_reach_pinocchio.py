"""Issue 23 for fixed-base URDF robots, against Pinocchio (skipped where it is not installed):
J_dot q_dot of every frame in the three reference frames (getFrameClassicalAcceleration with
a = 0), the centroidal momentum matrix (ccrba), wrenches at frames in inverse and forward
dynamics (rnea and aba with f_ext), and the actuator models (armature against crba and aba with
model.armature; damping and friction against the formula, computed independently)."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian

pin = pytest.importorskip("pinocchio")
pytest.importorskip("yourdfpy")

from tests.dynamics.test_dynamics_pinocchio import ARM  # noqa: E402  (revolute, prismatic, fixed)

REFERENCES = {"world": pin.ReferenceFrame.WORLD, "local": pin.ReferenceFrame.LOCAL,
              "local_world_aligned": pin.ReferenceFrame.LOCAL_WORLD_ALIGNED}
# the first joint damped and with Coulomb friction
DAMPED = ARM.replace('velocity="1"/></joint>',
                     'velocity="1"/><dynamics damping="0.3" friction="0.2"/></joint>', 1)


@pytest.fixture(scope="module")
def system(tmp_path_factory):
    path = tmp_path_factory.mktemp("reach") / "spatial.urdf"
    path.write_text(DAMPED)
    return lagrangian.load(path)


@pytest.fixture(scope="module")
def model():
    return pin.buildModelFromXML(DAMPED)


def _frame_id(model, name):
    for kind in (pin.FrameType.BODY, pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT):
        if model.existFrame(name, kind):
            return model.getFrameId(name, kind)
    raise AssertionError(f"Pinocchio has no frame {name}")


def _states(count=5, seed=13):
    rng = np.random.default_rng(seed)
    return tuple(rng.uniform(-1, 1, (count, 3)) for _ in range(4))


@pytest.mark.parametrize("backend", ["numpy", "auto"])  # numpy; compiled C (numpy without one)
def test_jacobian_dot_times_v_of_every_frame_agrees_with_pinocchio(system, model, backend):
    arm = system.dynamics(backend=backend)
    data = model.createData()
    q, v, _, _ = _states()
    for name in arm.frames:
        frame_id = _frame_id(model, name)
        for ref, pin_ref in REFERENCES.items():
            ours = arm.jacobian_dot_times_v(q, v, name, ref)
            assert ours.shape == (len(q), 6)
            for k in range(len(q)):
                pin.forwardKinematics(model, data, q[k], v[k], np.zeros(3))
                pin.updateFramePlacements(model, data)
                expected = pin.getFrameClassicalAcceleration(model, data, frame_id, pin_ref)
                np.testing.assert_allclose(ours[k], expected.vector, atol=1e-12,
                                           err_msg=f"{name} {ref}")
    one = arm.jacobian_dot_times_v(q[0], v[0], "tool")  # one state: (6,)
    np.testing.assert_allclose(one, arm.jacobian_dot_times_v(q, v, "tool")[0], atol=1e-15)


def test_jacobian_dot_is_the_derivative_of_the_jacobian(system):
    """d/dt (J(q) q_dot) along q(t) = q + t q_dot at q_ddot = 0 by central differences: the
    law, without Pinocchio."""
    arm = system.dynamics(backend="numpy")
    q, v, _, _ = _states(1, seed=4)
    h = 1e-6
    ahead = arm.jacobian(q[0] + h * v[0], "tool") @ v[0]
    behind = arm.jacobian(q[0] - h * v[0], "tool") @ v[0]
    np.testing.assert_allclose(arm.jacobian_dot_times_v(q[0], v[0], "tool"),
                               (ahead - behind) / (2 * h), atol=1e-8)


@pytest.mark.parametrize("backend", ["numpy", "auto"])
def test_centroidal_momentum_matrix_agrees_with_ccrba(system, model, backend):
    arm = system.dynamics(backend=backend)
    data = model.createData()
    q, v, _, _ = _states()
    Ag = arm.centroidal_momentum_matrix(q)
    assert Ag.shape == (len(q), 6, 3)
    for k in range(len(q)):
        pin.ccrba(model, data, q[k], v[k])
        np.testing.assert_allclose(Ag[k], data.Ag, atol=1e-12)
        np.testing.assert_allclose(Ag[k] @ v[k], data.hg.vector, atol=1e-12)
    # the linear rows are the total mass times the centre of mass Jacobian
    np.testing.assert_allclose(Ag[:, :3], arm.kinematics.mass() * arm.center_of_mass_jacobian(q),
                               atol=1e-12)


def _pinocchio_wrenches(model, data, q, wrenches):
    """The world-aligned wrenches at frames as Pinocchio's f_ext: per joint, in its own axes,
    about its origin."""
    pin.forwardKinematics(model, data, q)
    pin.updateFramePlacements(model, data)
    f_ext = [pin.Force.Zero() for _ in range(model.njoints)]
    for name, w in wrenches.items():
        frame_id = _frame_id(model, name)
        joint = model.frames[frame_id].parentJoint
        R, o = data.oMi[joint].rotation, data.oMi[joint].translation
        p = data.oMf[frame_id].translation
        f_ext[joint] += pin.Force(R.T @ w[:3], R.T @ (w[3:] + np.cross(p - o, w[:3])))
    return f_ext


@pytest.mark.parametrize("backend", ["numpy", "auto"])
def test_wrenches_at_frames_agree_with_rnea_and_aba(system, model, backend):
    arm = system.dynamics(backend=backend)
    data = model.createData()
    q, v, a, tau = _states()
    rng = np.random.default_rng(2)
    wrenches = {"tool": rng.uniform(-5, 5, 6), "b": rng.uniform(-5, 5, 6),
                "j3": rng.uniform(-5, 5, 6), "base": rng.uniform(-5, 5, 6)}
    inverse = arm.inverse_dynamics(q, v, a, f_ext=wrenches)
    forward = arm.forward_dynamics(q, v, tau, f_ext=wrenches)
    for k in range(len(q)):
        f_ext = _pinocchio_wrenches(model, data, q[k], wrenches)
        np.testing.assert_allclose(inverse[k], pin.rnea(model, data, q[k], v[k], a[k], f_ext),
                                   atol=1e-12)
        np.testing.assert_allclose(forward[k], pin.aba(model, data, q[k], v[k], tau[k], f_ext),
                                   atol=1e-12)
    # a batch of wrenches, one per state
    batch = {"tool": rng.uniform(-5, 5, (len(q), 6))}
    each = [arm.inverse_dynamics(q[k], v[k], a[k], f_ext={"tool": batch["tool"][k]})
            for k in range(len(q))]
    np.testing.assert_allclose(arm.inverse_dynamics(q, v, a, f_ext=batch), each, atol=1e-12)


def test_bad_wrenches_are_refused_in_one_line(system):
    arm = system.dynamics()
    zero = np.zeros(3)
    with pytest.raises(lagrangian.InputError, match="no frame named 'tol'; did you mean 'tool'") \
            as caught:
        arm.inverse_dynamics(zero, zero, zero, f_ext={"tol": np.zeros(6)})
    assert caught.value.field == "f_ext"
    with pytest.raises(lagrangian.InputError, match="6 numbers") as caught:
        arm.forward_dynamics(zero, zero, zero, f_ext={"tool": [1.0, 2.0]})
    assert caught.value.field == "f_ext.tool"
    with pytest.raises(lagrangian.InputError, match="mapping"):
        arm.inverse_dynamics(zero, zero, zero, f_ext=[1, 2, 3, 4, 5, 6])


@pytest.mark.parametrize("backend", ["numpy", "auto"])
def test_actuators_armature_damping_and_friction(system, model, backend):
    armature = {"j1": 0.1, "j3": 0.05}
    rigid = system.dynamics(backend=backend)
    assert rigid.bias_forces(np.zeros(3), np.ones(3)).shape == (3,)  # off by default
    f = system.dynamics(backend=backend, actuators=True, armature=armature)
    assert f.actuators["j1"] == {"damping": 0.3, "friction": 0.2, "armature": 0.1}
    model = model.copy()
    model.armature = np.array([0.1, 0.0, 0.05])
    data = model.createData()
    q, v, a, tau = _states()
    d, c, arm = np.array([0.3, 0, 0]), np.array([0.2, 0, 0]), np.array([0.1, 0, 0.05])
    mass = f.mass_matrix(q)
    forward, inverse = f.forward_dynamics(q, v, tau), f.inverse_dynamics(q, v, a)
    for k in range(len(q)):
        m = pin.crba(model, data, q[k]).copy()
        m = np.triu(m) + np.triu(m, 1).T
        np.testing.assert_allclose(mass[k], m, atol=1e-12)
        # Pinocchio's aba with the armature, the losses moved into tau
        losses = d * v[k] + c * np.sign(v[k])
        np.testing.assert_allclose(forward[k], pin.aba(model, data, q[k], v[k], tau[k] - losses),
                                   atol=1e-12)
        # independently: (M + diag(armature))^-1 (tau - b - d q_dot - f sign q_dot)
        M = rigid.mass_matrix(q[k]) + np.diag(arm)
        b = rigid.bias_forces(q[k], v[k])
        np.testing.assert_allclose(forward[k], np.linalg.solve(M, tau[k] - b - losses),
                                   atol=1e-12)
        np.testing.assert_allclose(inverse[k], M @ a[k] + b + losses, atol=1e-12)
    # only the armature: no damping
    only = system.dynamics(backend=backend, armature={"j2": 0.2})
    assert only.actuators["j1"]["damping"] == 0.0
    np.testing.assert_allclose(only.mass_matrix(q[0]) - rigid.mass_matrix(q[0]),
                               np.diag([0, 0.2, 0]), atol=1e-15)
    # frames come through
    np.testing.assert_allclose(f.jacobian(q[0], "tool"), rigid.jacobian(q[0], "tool"))


def test_bad_armature_is_refused_in_one_line(system):
    with pytest.raises(lagrangian.InputError, match="no joint named 'j4'") as caught:
        system.dynamics(armature={"j4": 0.1})
    assert caught.value.field == "armature"
    with pytest.raises(lagrangian.InputError, match=">= 0") as caught:
        system.dynamics(armature={"j1": -1.0})
    assert caught.value.field == "armature.j1"


def test_negative_damping_in_a_urdf_is_refused_naming_the_joint(tmp_path):
    path = tmp_path / "bad.urdf"
    path.write_text(DAMPED.replace('damping="0.3"', 'damping="-0.3"'))
    with pytest.raises(lagrangian.ModelError, match="joint 'j1'.dynamics.damping"):
        lagrangian.load(path)


def test_actuated_dynamics_offers_no_rigid_simulation(system):
    """A simulation over the rigid body's functions would leave the actuators out: not offered."""
    f = system.dynamics(actuators=True)
    assert f.tree is system.dynamics().tree
    assert not hasattr(f, "numeric_system")
    # energy: the rotor's 1/2 I_a q_dot^2 on top of the links'
    rotor = system.dynamics(armature={"j2": 0.2})
    v = np.array([0.3, -1.0, 0.5])
    assert rotor.kinetic_energy(np.zeros(3), v) == pytest.approx(
        system.dynamics().kinetic_energy(np.zeros(3), v) + 0.5 * 0.2 * 1.0, rel=1e-14)


def test_the_compiled_path_names_bad_input_and_broadcasts_like_numpy(system):
    arm, slow = system.dynamics(), system.dynamics(backend="numpy")
    q, v, a, _ = _states()
    with pytest.raises(lagrangian.InputError, match="no frame named 'tol'") as caught:
        arm.jacobian_dot_times_v(q[0], v[0], "tol")
    assert caught.value.field == "frame"
    with pytest.raises(lagrangian.InputError, match="unknown reference"):
        arm.jacobian_dot_times_v(q[0], v[0], "tool", "global")
    # the names looked up in C (reach_bindings.c) fall back to numpy's one-line refusals
    for bad in ("tol", ["tool"], 3):
        for call in (lambda f: arm.placement(q[0], f), lambda f: arm.jacobian(q[0], f)):
            with pytest.raises(lagrangian.InputError) as caught:
                call(bad)
            assert caught.value.field == "frame"
    for bad in ("global", None, 2, ["world"]):
        with pytest.raises(lagrangian.InputError, match="unknown reference"):
            arm.jacobian(q[0], "tool", bad)
    # a reference spelt by a string made at run time (not the interned literal) still counts
    built = "".join(["local_", "world_aligned"])
    np.testing.assert_array_equal(arm.jacobian(q, "tool", built),
                                  arm.jacobian(q, "tool", "local_world_aligned"))
    with pytest.raises(lagrangian.InputError, match="expected 3 values") as caught:
        arm.centroidal_momentum_matrix(np.zeros(4))
    assert caught.value.field == "q"
    with pytest.raises(lagrangian.InputError, match="expected 3 values") as caught:
        arm.jacobian_dot_times_v(q[0], np.zeros(2), "tool")
    assert caught.value.field == "v"
    # one configuration, many rates; one wrench for many states
    np.testing.assert_allclose(arm.jacobian_dot_times_v(q[0], v, "tool"),
                               slow.jacobian_dot_times_v(q[0], v, "tool"), atol=1e-13)
    w = {"tool": np.arange(6.0)}
    np.testing.assert_allclose(arm.inverse_dynamics(q, v, a, f_ext=w),
                               slow.inverse_dynamics(q, v, a, f_ext=w), atol=1e-12)
    np.testing.assert_allclose(arm.inverse_dynamics(q[0], v[0], a, f_ext=w),
                               slow.inverse_dynamics(q[0], v[0], a, f_ext=w), atol=1e-12)
    assert arm.inverse_dynamics(q[0], v[0], a[0], f_ext={}).shape == (3,)


def test_a_robot_without_moving_mass_has_no_centroidal_momentum(tmp_path):
    path = tmp_path / "light.urdf"
    path.write_text('<robot name="r"><link name="a"/><link name="b"/><joint name="j" '
                    'type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
                    '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')
    kinematics = lagrangian.load(path).model.kinematic_tree
    from lagrangian.dynamics.algorithms.frames import TreeKinematics

    with pytest.raises(lagrangian.InputError, match="no mass"):
        TreeKinematics(kinematics).centroidal_momentum_matrix(np.zeros(1))


def test_a_joint_of_more_than_one_coordinate_is_refused_not_miscounted(system):
    """The walks give each joint its own columns (one, or a free flyer's six): a tree with a
    joint they do not know (a fixed one here, which a tree merges away) is refused in one line,
    never summed wrong; the compiled module takes no joint it has no columns for."""
    from dataclasses import replace

    from lagrangian.dynamics.algorithms.coriolis_tree import coriolis_matrix
    from lagrangian.dynamics.algorithms.frames import TreeKinematics

    tree = system.model.kinematic_tree
    odd = replace(tree, joints=(replace(tree.joints[0], kind="fixed"), *tree.joints[1:]))
    kinematics = TreeKinematics.__new__(TreeKinematics)
    kinematics.tree, kinematics.n, kinematics.coordinates = odd, 3, tree.coordinates
    for call in (lambda: kinematics.jacobian_dot_times_v(np.zeros(3), np.zeros(3), "tool"),
                 lambda: kinematics.centroidal_momentum_matrix(np.zeros(3)),
                 lambda: coriolis_matrix(kinematics, np.zeros(3), np.zeros(3))):
        with pytest.raises(lagrangian.InputError, match="fixed joint: not yet"):
            call()
    from lagrangian.dynamics.algorithms.wrenches import wrench_forces

    with pytest.raises(lagrangian.InputError, match="fixed joint: not yet"):
        wrench_forces(kinematics, np.zeros(3), {"tool": np.zeros(6)})
    from lagrangian.dynamics.engine.reach_c import reach_module

    # nor the compiled module (a ball's three and a free flyer's six below the root it takes:
    # test_ball_joint.py, test_urdf_floating_mid_tree.py)
    assert reach_module(odd) is None


def test_the_compact_kernel_link_inertials_and_a_floating_base(system, tmp_path):
    """The same numbers on the compact kernel; a link's inertial given as a parameter is the
    edited URDF's; a floating base's functions take nv numbers, its actuators are the joints'."""
    q, v, a, _ = _states()
    unrolled, compact = system.dynamics(), system.dynamics(kernel="compact")
    np.testing.assert_allclose(compact.centroidal_momentum_matrix(q),
                               unrolled.centroidal_momentum_matrix(q), atol=1e-13)
    np.testing.assert_allclose(compact.jacobian_dot_times_v(q, v, "tool"),
                               unrolled.jacobian_dot_times_v(q, v, "tool"), atol=1e-13)
    w = {"tool": np.arange(6.0)}
    np.testing.assert_allclose(compact.inverse_dynamics(q, v, a, f_ext=w),
                               unrolled.inverse_dynamics(q, v, a, f_ext=w), atol=1e-12)
    heavier = system.dynamics(parameters={"c.mass": 1.5})
    path = tmp_path / "heavier.urdf"
    path.write_text(DAMPED.replace('<mass value="0.5"/>', '<mass value="1.5"/>'))
    edited = lagrangian.load(path).dynamics()
    np.testing.assert_allclose(heavier.centroidal_momentum_matrix(q),
                               edited.centroidal_momentum_matrix(q), atol=1e-12)
    path = tmp_path / "spatial.urdf"
    path.write_text(DAMPED)
    floating = lagrangian.load(path, floating_base=True).dynamics(actuators=True)
    nq, nv = len(floating.coordinates), floating.n
    q0 = np.r_[np.zeros(6), 1.0, np.zeros(nq - 7)]
    # a floating base's functions are checked against Pinocchio in test_floating_reach.py:
    # here, the widths and the actuators
    assert floating.centroidal_momentum_matrix(q0).shape == (6, nv)
    assert floating.jacobian_dot_times_v(q0, np.zeros(nv), "tool").shape == (6,)
    assert floating.inverse_dynamics(q0, np.zeros(nv), np.zeros(nv),
                                     f_ext={"tool": np.zeros(6)}).shape == (nv,)
    assert list(floating.actuators) == list(floating.velocity_names[6:])
    assert floating.actuators["j1"] == {"damping": 0.3, "friction": 0.2, "armature": 0.0}
