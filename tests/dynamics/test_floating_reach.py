"""A floating base's C(q, v), J_dot v, centroidal momentum matrix, wrenches at frames and
actuator models against Pinocchio's buildModelFromUrdf(path, JointModelFreeFlyer())
(computeCoriolisMatrix, getFrameClassicalAcceleration with a = 0, ccrba, rnea and aba with
f_ext, model.armature), and C's two defining properties without Pinocchio: C v = bias - g and
M_dot - 2C skew-symmetric along q (+) v dt. Skipped where Pinocchio or example-robot-data is
missing."""

from __future__ import annotations

import json

import numpy as np
import pytest
from tests.dynamics.test_floating_base import (
    FLOATING_URDF,
    _close,
    _close_forward,
    _layout,
    _pinocchio_frame,
    _robots,
)

import lagrangian

pytest.importorskip("yourdfpy")
REFERENCES = ("world", "local", "local_world_aligned")


def _load(robot: str):
    """Pinocchio's model and our numpy dynamics of an example-robot-data robot, floating."""
    import pinocchio as pin

    path = _robots() / robot
    if not path.is_file():
        pytest.skip(f"{robot} is not in this example-robot-data")
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    return model, lagrangian.load(path, floating_base=True).dynamics(backend="numpy")


def _states(model, count: int, seed: int = 3):
    import pinocchio as pin

    rng = np.random.default_rng(seed)
    q = np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
                  for _ in range(count)])
    return q, rng.uniform(-1, 1, (count, model.nv))


def _mass_rate(ours, q, v, h: float = 1e-3) -> np.ndarray:
    """dM/dt along q (+) v t at t = 0, by the five-point stencil (error h^4)."""
    at = [ours.mass_matrix(ours.integrate(q, v, s * h)) for s in (-2, -1, 1, 2)]
    return (at[0] - 8 * at[1] + 8 * at[2] - at[3]) / (12 * h)


@pytest.mark.parametrize("robot", [
    "solo_description/robots/solo12.urdf",
    "talos_data/robots/talos_reduced.urdf",
    "anymal_b_simple_description/robots/anymal.urdf",
])
def test_coriolis_matrix_of_a_floating_base(robot):
    """C(q, v) in the velocity space (the base's twist first) equals computeCoriolisMatrix to
    1e-12; C v = bias - g; M_dot - 2C is skew-symmetric (M_dot by differences along the
    manifold: to 1e-7 of M_dot's size, the stencil's truncation)."""
    import pinocchio as pin

    model, ours = _load(robot)
    data = model.createData()
    iq, iv = _layout(model, ours)
    q, v = _states(model, 3)
    C = ours.coriolis_matrix(q[:, iq], v[:, iv])
    assert C.shape == (3, model.nv, model.nv)
    for k in range(3):
        _close(C[k], pin.computeCoriolisMatrix(model, data, q[k], v[k])[np.ix_(iv, iv)])
    velocity_terms = ours.bias_forces(q[:, iq], v[:, iv]) - ours.gravity(q[:, iq])
    _close(np.einsum("nij,nj->ni", C, v[:, iv]), velocity_terms)
    rate = _mass_rate(ours, q[0, iq], v[0, iv])
    skew = rate - 2 * C[0]
    np.testing.assert_allclose(skew + skew.T, 0, atol=1e-7 * np.abs(rate).max())


def test_the_tree_coriolis_matrix_is_the_christoffel_one_on_a_fixed_base():
    """Two derivations agree: on a fixed base the spatial factorization (coriolis_tree.py) is
    the matrix of M's Christoffel symbols (joint_space.py, from the bias forces)."""
    from lagrangian.dynamics.algorithms.coriolis_tree import coriolis_matrix

    path = _robots() / "solo_description/robots/solo12.urdf"
    fixed = lagrangian.load(path).dynamics(backend="numpy")
    rng = np.random.default_rng(5)
    q, v = rng.uniform(-1, 1, (2, 4, 12))
    _close(coriolis_matrix(fixed.kinematics, q, v), fixed.coriolis_matrix(q, v))


def test_a_fixed_base_c_compiled_is_the_christoffel_one():
    """The compiled factorization (reach_coriolis.c) on a fixed base equals M's Christoffel C
    from the bias forces (numpy), also with a link's mass set by a parameter, and C q_dot is
    the bias less gravity."""
    path = _robots() / "solo_description/robots/solo12.urdf"
    rng = np.random.default_rng(6)
    q, v = rng.uniform(-1, 1, (2, 5, 12))
    for parameters in (None, {"FL_UPPER_LEG.mass": 2.5}):
        system = lagrangian.load(path)
        fast = system.dynamics(parameters=parameters)
        slow = system.dynamics(parameters=parameters, backend="numpy")
        C = fast.coriolis_matrix(q, v)
        assert fast._reach and fast._reach.fixed_coriolis  # the compiled path, checked
        _close(C, slow.coriolis_matrix(q, v))
        _close(np.einsum("nij,nj->ni", C, v), slow.bias_forces(q, v) - slow.gravity(q))
    heavier = fast.mass_matrix(q[0])
    assert not np.allclose(heavier, lagrangian.load(path).dynamics().mass_matrix(q[0]))


def test_frame_accelerations_and_centroidal_momentum_of_solo():
    """J_dot v of every frame of Solo12 in the three references (getFrameClassicalAcceleration
    with a = 0) and A_g (ccrba) on its floating base, to 1e-12."""
    import pinocchio as pin

    model, ours = _load("solo_description/robots/solo12.urdf")
    data = model.createData()
    iq, iv = _layout(model, ours)
    q, v = _states(model, 2)
    drift = {(name, ref): ours.jacobian_dot_times_v(q[:, iq], v[:, iv], name, ref)
             for name in ours.frames for ref in REFERENCES}
    momentum = ours.centroidal_momentum_matrix(q[:, iq])
    for k in range(2):
        pin.forwardKinematics(model, data, q[k], v[k], np.zeros(model.nv))
        pin.updateFramePlacements(model, data)
        for (name, ref), ours_k in drift.items():
            frame = _pinocchio_frame(model, name)
            reference = getattr(pin.ReferenceFrame, ref.upper())
            _close(ours_k[k], pin.getFrameClassicalAcceleration(model, data, frame,
                                                                reference).vector)
        _close(momentum[k], pin.ccrba(model, data, q[k], v[k])[:, iv])


def test_centroidal_momentum_of_talos():
    """A humanoid's A_g against ccrba, and the base's drift: its origin's acceleration at
    a = 0 is w x v in world axes (the twist is constant in the base's own axes)."""
    import pinocchio as pin

    model, ours = _load("talos_data/robots/talos_reduced.urdf")
    data = model.createData()
    iq, iv = _layout(model, ours)
    q, v = _states(model, 2)
    momentum = ours.centroidal_momentum_matrix(q[:, iq])
    for k in range(2):
        _close(momentum[k], pin.ccrba(model, data, q[k], v[k])[:, iv])
    base = ours.placement(q[:, iq], "root_joint")[:, :3, :3]
    expected = base @ np.cross(v[:, 3:6], v[:, :3])[..., None]
    _close(ours.jacobian_dot_times_v(q[:, iq], v[:, iv], "root_joint")[:, :3], expected[..., 0])


def _pinocchio_wrenches(model, data, q, wrenches):
    """Our wrenches (world axes, at each frame's origin) as Pinocchio's f_ext: per joint, in
    its own axes about its origin."""
    import pinocchio as pin

    pin.framesForwardKinematics(model, data, q)
    out = [pin.Force.Zero() for _ in range(model.njoints)]
    for name, w in wrenches.items():
        frame = _pinocchio_frame(model, name)
        joint = model.frames[frame].parentJoint
        origin, placement = data.oMf[frame].translation, data.oMi[joint]
        moment = w[3:] + np.cross(origin - placement.translation, w[:3])
        out[joint] += pin.Force(placement.rotation.T @ w[:3], placement.rotation.T @ moment)
    return out


@pytest.mark.parametrize("backend", ["numpy", "auto"])  # auto: the unrolled C module's dynamics
def test_wrenches_at_frames_on_a_floating_base(tmp_path, backend):
    """Inverse and forward dynamics with wrenches on a foot, a joint frame and the base itself
    equal rnea and aba with f_ext; the base's six numbers take the wrench about its origin."""
    import pinocchio as pin

    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    model = pin.buildModelFromXML(FLOATING_URDF)
    data = model.createData()
    ours = lagrangian.load(path).dynamics(backend=backend)
    iq, iv = _layout(model, ours)
    q, v = _states(model, 3)
    rng = np.random.default_rng(9)
    a, tau = rng.uniform(-1, 1, (2, 3, model.nv))
    wrenches = {"foot": rng.uniform(-5, 5, 6), "knee": rng.uniform(-5, 5, 6),
                "trunk": rng.uniform(-5, 5, 6)}
    inverse = ours.inverse_dynamics(q[:, iq], v[:, iv], a[:, iv], f_ext=wrenches)
    forward = ours.forward_dynamics(q[:, iq], v[:, iv], tau[:, iv], f_ext=wrenches)
    mass, bias = ours.mass_matrix(q[:, iq]), ours.bias_forces(q[:, iq], v[:, iv])
    for k in range(3):
        f_ext = _pinocchio_wrenches(model, data, q[k], wrenches)
        _close(inverse[k], pin.rnea(model, data, q[k], v[k], a[k], f_ext)[iv])
        expected = pin.aba(model, data, q[k], v[k], tau[k], f_ext)[iv]
        pushed = tau[k, iv] + ours.inverse_dynamics(q[k, iq], v[k, iv], np.zeros(model.nv)) \
            - ours.inverse_dynamics(q[k, iq], v[k, iv], np.zeros(model.nv), f_ext=wrenches)
        _close_forward(forward[k], expected, mass[k], bias[k], pushed)
    # a pure force through the base's origin, along world z: the base's force in its own axes
    origin = ours.placement(q[0, iq], "trunk")
    only = ours.inverse_dynamics(q[0, iq], v[0, iv], a[0, iv], f_ext={"trunk": [0, 0, 2, 0, 0, 0]})
    plain = ours.inverse_dynamics(q[0, iq], v[0, iv], a[0, iv])
    _close(plain[:6] - only[:6], np.r_[origin[:3, :3].T @ [0, 0, 2.0], np.zeros(3)])
    _close(plain[6:], only[6:])  # the trunk is above every joint: no joint feels it


def test_actuator_models_on_a_floating_base():
    """Armature on the joints only agrees with crba, rnea and aba with model.armature; damping
    and Coulomb friction act on the joints' rates, never on the base's twist."""
    import pinocchio as pin

    model, _ = _load("solo_description/robots/solo12.urdf")
    system = lagrangian.load(_robots() / "solo_description/robots/solo12.urdf",
                             floating_base=True)
    joints = [c.name for c in system.model.coordinates]
    rotors = {name: 0.01 * (k + 1) for k, name in enumerate(joints)}
    ours = system.dynamics(backend="numpy", armature=rotors)
    rigid = system.dynamics(backend="numpy")
    iq, iv = _layout(model, ours)
    for name, value in rotors.items():
        model.armature[model.idx_vs[model.getJointId(name)]] = value
    data = model.createData()
    q, v = _states(model, 2)
    a, tau = np.random.default_rng(4).uniform(-1, 1, (2, 2, model.nv))
    for k in range(2):
        mass = pin.crba(model, data, q[k])
        _close(ours.mass_matrix(q[k, iq]), (np.triu(mass) + np.triu(mass, 1).T)[np.ix_(iv, iv)])
        _close(ours.inverse_dynamics(q[k, iq], v[k, iv], a[k, iv]),
               pin.rnea(model, data, q[k], v[k], a[k])[iv])
        _close(ours.forward_dynamics(q[k, iq], v[k, iv], tau[k, iv]),
               pin.aba(model, data, q[k], v[k], tau[k])[iv])
    assert list(ours.actuators) == joints  # the base has no actuator
    damped = type(ours)(rigid, np.r_[np.zeros(6), np.full(12, 0.2)],
                        np.r_[np.zeros(6), np.full(12, 0.1)], np.zeros(18))
    losses = damped.bias_forces(q[0, iq], v[0, iv]) - rigid.bias_forces(q[0, iq], v[0, iv])
    _close(losses, np.r_[np.zeros(6), 0.2 * v[0, iv][6:] + 0.1 * np.sign(v[0, iv][6:])])


def test_bad_input_is_refused_in_one_line(tmp_path):
    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    robot = lagrangian.load(path).dynamics(backend="numpy")
    q, v = np.r_[0, 0, 0, 0, 0, 0, 1.0, 0, 0, 0], np.zeros(9)
    for call in (lambda: robot.coriolis_matrix(np.r_[q[:6], 0.5, q[7:]], v),
                 lambda: robot.jacobian_dot_times_v(np.r_[q[:6], 0.5, q[7:]], v, "foot"),
                 lambda: robot.centroidal_momentum_matrix(np.r_[q[:6], 0.5, q[7:]])):
        with pytest.raises(lagrangian.InputError, match="base quaternion .* norm 0.5") as info:
            call()
        assert info.value.field == "q"
    with pytest.raises(lagrangian.InputError, match="expected 9 values") as info:
        robot.coriolis_matrix(q, np.zeros(10))
    assert info.value.field == "v"
    with pytest.raises(lagrangian.InputError, match="expected 9 values") as info:
        robot.jacobian_dot_times_v(q, np.zeros(10), "foot")
    assert info.value.field == "v"
    with pytest.raises(lagrangian.InputError, match="no frame named 'feet'") as info:
        robot.jacobian_dot_times_v(q, v, "feet")
    assert info.value.field == "frame"
    with pytest.raises(lagrangian.InputError, match="6 numbers") as info:
        robot.inverse_dynamics(q, v, v, f_ext={"foot": np.zeros(5)})
    assert info.value.field == "f_ext.foot"


def test_commands_on_a_floating_base(cli):
    """kinematics --floating-base --v --centroidal and dynamics --floating-base --coriolis
    --wrench --actuators print the library's numbers; bad input is one line, exit 2."""
    path = _robots() / "solo_description/robots/solo12.urdf"
    ours = lagrangian.load(path, floating_base=True).dynamics(backend="numpy")
    q = [0.1, 0.2, 0.3, 0.0, 0.6, 0.0, 0.8] + [0.3] * 12
    v = [0.1, 0.0, -0.2, 0.3, 0.0, 0.5] + [0.2] * 12
    text = ",".join(map(str, q)), ",".join(map(str, v))
    result = cli("kinematics", str(path), "--floating-base", "--frame", "FL_FOOT", "--q", text[0],
                 "--v", text[1], "--centroidal", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    _close(document["jacobian_dot_times_v"],
           ours.jacobian_dot_times_v(q, v, "FL_FOOT", "local_world_aligned"))
    _close(document["centroidal_momentum_matrix"], ours.centroidal_momentum_matrix(q))
    result = cli("dynamics", str(path), "--floating-base", "--q", text[0], "--v", text[1],
                 "--coriolis", "--a", ",".join(["0"] * 18), "--wrench", "FL_FOOT=0,0,10,0,0,0",
                 "--actuators", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    _close(document["coriolis_matrix"], ours.coriolis_matrix(q, v))
    _close(document["inverse_dynamics"], ours.inverse_dynamics(
        q, v, np.zeros(18), f_ext={"FL_FOOT": [0, 0, 10, 0, 0, 0]}))
    assert list(document["actuators"])[:2] == ["FL_HAA", "FL_HFE"]
    for args, start in (
            (("kinematics", "--frame", "FOOT"), "error: --frame: no frame named 'FOOT'"),
            (("dynamics", "--coriolis", "--q", "0,0,0,0,0,0,2" + ",0" * 12),
             "error: --q: the base quaternion"),
            (("dynamics", "--a", ",".join(["0"] * 18), "--wrench", "FL_FOOT=0,0,1"),
             "error: --wrench FL_FOOT: expected 6")):
        bad = cli(args[0], str(path), "--floating-base", *args[1:])
        assert bad.code == 2 and bad.err.startswith(start), bad.err
        assert len(bad.err.strip().splitlines()) == 1


@pytest.mark.parametrize("backend", ["numpy", "auto"])  # auto: reach_kernel.c where it compiles
def test_the_hopper_in_both_backends(tmp_path, backend):
    """The compiled kernel (free flyer as body 0) and numpy give Pinocchio's C(q, v), J_dot v of
    every frame and A_g for a URDF floating joint with an origin of its own, over a batch; a
    bad quaternion is refused in one line on either path."""
    import pinocchio as pin

    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    model = pin.buildModelFromXML(FLOATING_URDF)
    data = model.createData()
    ours = lagrangian.load(path).dynamics(backend=backend)
    iq, iv = _layout(model, ours)
    q, v = _states(model, 5)
    C = ours.coriolis_matrix(q[:, iq], v[:, iv])
    A = ours.centroidal_momentum_matrix(q[:, iq])
    drift = {(name, ref): ours.jacobian_dot_times_v(q[:, iq], v[:, iv], name, ref)
             for name in ours.frames for ref in REFERENCES}
    for k in range(5):
        _close(C[k], pin.computeCoriolisMatrix(model, data, q[k], v[k])[np.ix_(iv, iv)])
        _close(A[k], pin.ccrba(model, data, q[k], v[k])[:, iv])
        pin.forwardKinematics(model, data, q[k], v[k], np.zeros(model.nv))
        pin.updateFramePlacements(model, data)
        for (name, ref), ours_k in drift.items():
            reference = getattr(pin.ReferenceFrame, ref.upper())
            _close(ours_k[k], pin.getFrameClassicalAcceleration(
                model, data, _pinocchio_frame(model, name), reference).vector)
    if getattr(ours, "backend", None) == "recursive":  # compiled: so is the reach kernel
        from lagrangian.dynamics.engine.reach_c import ReachKernel

        assert isinstance(ours._reach, ReachKernel) and ours._reach.coriolis is not None
    near = q[0, iq].copy()
    near[3:7] *= 1 + 1e-7  # within QUATERNION_TOLERANCE: read as the unit quaternion
    _close(ours.coriolis_matrix(near, v[0, iv]), C[0])
    _close(ours.centroidal_momentum_matrix(near), A[0])
    bad = q[0, iq].copy()
    bad[3:7] *= 2.0
    for call in (lambda: ours.coriolis_matrix(bad, v[0, iv]),
                 lambda: ours.centroidal_momentum_matrix(bad),
                 lambda: ours.jacobian_dot_times_v(bad, v[0, iv], "foot"),
                 lambda: ours.inverse_dynamics(bad, v[0, iv], v[0, iv], f_ext={"foot": [0] * 6})):
        with pytest.raises(lagrangian.InputError, match="norm 2"):
            call()
