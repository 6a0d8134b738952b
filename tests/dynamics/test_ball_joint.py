"""The ball (spherical) joint, MuJoCo's: hand-written MJCF robots against MuJoCo itself (M by
mj_fullM, the bias and ID by mj_inverse, FD by mj_forward's qacc) on the compiled engine and the
numpy reference; a spherical pendulum's T + V and angular momentum about the vertical through
its pivot kept along its free motion (gravity has no moment about that axis); T and V in closed
form; batches bit for bit their single calls; q (+) v against mj_integratePos; a quaternion off
unit norm refused in one line naming the joint."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from mjcf_models import BALL_HINGE_BALL, FREE_HINGE_BALL

mujoco = pytest.importorskip("mujoco")
pytest.importorskip("yourdfpy")

TOLERANCE = 1e-9
BACKENDS = ("compiled", "numpy")

# the bob hangs 0.6 m below its pivot (0.1 m above the body's origin), off axis, with a full
# inertia tensor about its centre of mass (kg m^2)
PENDULUM = """<mujoco model="spherical_pendulum">
  <worldbody>
    <body name="bob" pos="0 0 1">
      <joint name="ball" type="ball" pos="0 0 0.1"/>
      <inertial pos="0.05 0.02 -0.5" mass="1.3" fullinertia="0.04 0.03 0.02 0.001 -0.002 0.003"/>
    </body>
  </worldbody>
</mujoco>"""
MASS, PIVOT, CENTRE = 1.3, np.array([0.0, 0.0, 1.1]), np.array([0.05, 0.02, -0.6])
I_CENTRE = np.array([[0.04, 0.001, -0.002], [0.001, 0.03, 0.003], [-0.002, 0.003, 0.02]])

# a ball, then a hinge, then a ball, each body turned and offset, under tilted gravity
CHAIN = BALL_HINGE_BALL


# several joints in one body (a hinge then a ball; a ball then a slide), a ball from a
# childclass default, a welded child, inertias from geoms
BODIES = """<mujoco model="joints_in_one_body">
  <default><default class="balls"><joint type="ball"/></default></default>
  <worldbody>
    <body name="a" pos="0 0.1 1" euler="10 20 30">
      <joint name="h0" axis="1 0 0" pos="0 0 0.05"/>
      <joint name="b0" type="ball" pos="0.02 0 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.04"/>
      <body name="weld" pos="0.1 0 -0.2"><geom type="sphere" size="0.05"/></body>
      <body name="b" pos="0 0 -0.4" childclass="balls">
        <joint name="b1" pos="0 0.01 0"/>
        <joint name="s1" type="slide" axis="0 1 1"/>
        <geom type="box" size="0.03 0.04 0.1" pos="0 0 -0.1"/>
      </body>
    </body>
  </worldbody>
</mujoco>"""


# the chain on a free flyer instead of its shoulder: a floating base with a ball wrist
FLOATING = FREE_HINGE_BALL


def _load(tmp_path_factory, text, name, **options):
    path = tmp_path_factory.mktemp("ball") / f"{name}.xml"
    path.write_text(text)
    system = lagrangian.load(path, **options)
    return (system, {"compiled": system.dynamics(), "numpy": system.dynamics(backend="numpy")},
            mujoco.MjModel.from_xml_path(str(path)))


@pytest.fixture(scope="module")
def pendulum(tmp_path_factory):
    return _load(tmp_path_factory, PENDULUM, "pendulum")


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    return _load(tmp_path_factory, CHAIN, "chain")


def _states(model, count, seed):
    """MuJoCo states at random: unit ball quaternions, rates and accelerations in [-2, 2]."""
    rng = np.random.default_rng(seed)
    qpos = rng.uniform(-1.0, 1.0, (count, model.nq))
    for j in range(model.njnt):
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_BALL:
            a = model.jnt_qposadr[j]
            qpos[:, a:a + 4] /= np.linalg.norm(qpos[:, a:a + 4], axis=-1, keepdims=True)
    return qpos, rng.uniform(-2.0, 2.0, (count, model.nv)), rng.uniform(-2.0, 2.0, (count, model.nv))


def _mujoco(model, qpos, qvel, qacc):
    """M, the bias, tau = ID(qacc) and FD(tau / 2) by MuJoCo."""
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:], data.qacc[:] = qpos, qvel, qacc
    mujoco.mj_inverse(model, data)
    tau = data.qfrc_inverse.copy()
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    bias = data.qfrc_bias.copy()
    data.qfrc_applied[:] = 0.5 * tau
    mujoco.mj_forward(model, data)
    return M, bias, tau, data.qacc.copy()


def _agree(ours, theirs, what):
    error = float(np.abs(np.asarray(ours) - theirs).max())
    assert error <= TOLERANCE * (1.0 + float(np.abs(theirs).max())), f"{what}: off by {error:.2e}"


@pytest.fixture(scope="module")
def bodies(tmp_path_factory):
    return _load(tmp_path_factory, BODIES, "bodies")


@pytest.fixture(scope="module")
def floating(tmp_path_factory):
    return _load(tmp_path_factory, FLOATING, "floating", floating_base=True)


@pytest.mark.parametrize("robot", ["pendulum", "chain", "bodies"])
@pytest.mark.parametrize("backend", BACKENDS)
def test_M_ID_and_FD_agree_with_mujoco(request, robot, backend):
    system, dynamics, model = request.getfixturevalue(robot)
    d = dynamics[backend]
    assert (d.nq, d.nv) == (model.nq, model.nv)
    assert ("numpy" in d.backend) == (backend == "numpy")
    if backend == "compiled":  # FD by the articulated-body algorithm (the ball's 3 x 3 D)
        assert d.description[5] == 0.0
    for qpos, qvel, qacc in zip(*_states(model, 6, seed=3), strict=True):
        M, bias, tau, fd = _mujoco(model, qpos, qvel, qacc)
        where = f"{robot}, {backend}"
        _agree(d.mass_matrix(qpos), M, f"{where}: M")
        _agree(d.bias_forces(qpos, qvel), bias, f"{where}: bias")
        _agree(d.inverse_dynamics(qpos, qvel, qacc), tau, f"{where}: ID")
        _agree(d.forward_dynamics(qpos, qvel, 0.5 * tau), fd, f"{where}: FD")
        _agree(d.kinetic_energy(qpos, qvel), 0.5 * qvel @ M @ qvel, f"{where}: T")


def _rotation(quaternion_wxyz):
    w, x, y, z = quaternion_wxyz / np.linalg.norm(quaternion_wxyz)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


# the bob's inertia about the pivot, body axes (parallel axes)
J_PIVOT = I_CENTRE + MASS * (CENTRE @ CENTRE * np.eye(3) - np.outer(CENTRE, CENTRE))


@pytest.mark.parametrize("backend", BACKENDS)
def test_the_pendulum_energies_in_closed_form(pendulum, backend):
    """T = w . J_O w / 2 (J_O about the pivot), V = m g (height of the centre of mass)."""
    d = pendulum[1][backend]
    qpos, qvel, _ = _states(pendulum[2], 5, seed=5)
    for q, w in zip(qpos, qvel, strict=True):
        _agree(d.kinetic_energy(q, w), 0.5 * w @ J_PIVOT @ w, f"{backend}: T")
        height = (PIVOT + _rotation(q) @ CENTRE)[2]
        _agree(d.potential_energy(q), MASS * 9.81 * height, f"{backend}: V")


def _invariants(q, w):
    """T + V and L_z = e_z . R J_O w (the angular momentum about the vertical through the
    pivot), from the closed forms above."""
    R = _rotation(q)
    energy = 0.5 * w @ J_PIVOT @ w + MASS * 9.81 * (PIVOT + R @ CENTRE)[2]
    return energy, (R @ (J_PIVOT @ w))[2]


@pytest.mark.parametrize("backend", BACKENDS)
def test_the_spherical_pendulum_keeps_its_energy_and_vertical_angular_momentum(pendulum,
                                                                                backend):
    """Free motion for 2 s (q_dot = q (0, w) / 2, w_dot = FD): T + V and L_z constant."""
    from scipy.integrate import solve_ivp

    d = pendulum[1][backend]

    def rhs(_, y):
        q, w = y[:4] / np.linalg.norm(y[:4]), y[4:]
        qw, qx, qy, qz = q
        rate = 0.5 * np.array([-qx * w[0] - qy * w[1] - qz * w[2],
                               qw * w[0] + qy * w[2] - qz * w[1],
                               qw * w[1] - qx * w[2] + qz * w[0],
                               qw * w[2] + qx * w[1] - qy * w[0]])
        return np.concatenate([rate, d.forward_dynamics(q, w, np.zeros(3))])

    q0 = np.array([0.9, 0.3, -0.2, 0.1])
    y0 = np.concatenate([q0 / np.linalg.norm(q0), [1.5, -0.7, 2.0]])
    run = solve_ivp(rhs, (0.0, 2.0), y0, method="DOP853", rtol=1e-12, atol=1e-12,
                    t_eval=np.linspace(0, 2, 21))
    assert run.success
    start = _invariants(y0[:4], y0[4:])
    moved = np.linalg.norm(run.y[:4, -1] - y0[:4])
    assert moved > 0.1  # it swung
    for y in run.y.T:
        energy, momentum = _invariants(y[:4], y[4:])
        assert energy == pytest.approx(start[0], abs=1e-8)
        assert momentum == pytest.approx(start[1], abs=1e-8)


def test_a_batch_is_its_single_calls_bit_for_bit(chain):
    """The engine's vector lanes on a tree with ball joints: each row its state's single call;
    a NaN state's row NaN, counted in one warning."""
    _, dynamics, model = chain
    d = dynamics["compiled"]
    Q, V, A = _states(model, 9, seed=11)
    Q[4, -1] = np.nan
    functions = [(d.mass_matrix, (Q,)), (d.bias_forces, (Q, V)), (d.gravity, (Q,)),
                 (d.inverse_dynamics, (Q, V, A)), (d.forward_dynamics, (Q, V, A)),
                 (d.kinetic_energy, (Q, V)), (d.potential_energy, (Q,))]
    for function, args in functions:
        with pytest.warns(lagrangian.DynamicsWarning):
            batch = function(*args)
        assert np.isnan(batch[4]).all(), function.__name__
        for i in (0, 3, 8):
            assert np.array_equal(batch[i], function(*(x[i] for x in args))), function.__name__


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_quaternion_off_unit_norm_is_refused_in_one_line(chain, backend):
    _, dynamics, model = chain
    d = dynamics[backend]
    Q, V, _ = _states(model, 3, seed=2)
    Q[1, 5:9] *= 1.01  # the wrist's
    for call in (lambda: d.mass_matrix(Q), lambda: d.forward_dynamics(Q, V, V),
                 lambda: d.kinetic_energy(Q[1], V[1]), lambda: d.placement(Q, "hand")):
        with pytest.raises(lagrangian.LagrangianError) as error:
            call()
        message = str(error.value)
        assert "ball joint 'wrist'" in message and "1.01" in message, message
        assert "\n" not in message
    near = Q[0].copy()
    near[0:4] *= 1 + 1e-7  # within the tolerance: used normalized
    unit = Q[0]
    assert np.allclose(d.mass_matrix(near), d.mass_matrix(unit), rtol=0, atol=1e-12)


def test_integrate_and_difference_agree_with_mujoco(chain):
    """q (+) v dt against mj_integratePos, and difference its inverse."""
    _, dynamics, model = chain
    d = dynamics["compiled"]
    Q, V, _ = _states(model, 4, seed=9)
    for q, v in zip(Q, V, strict=True):
        expected = q.copy()
        mujoco.mj_integratePos(model, expected, v, 0.3)
        moved = d.integrate(q, v, 0.3)
        for start in (0, 5):  # a quaternion and its negative are one rotation
            if moved[start:start + 4] @ expected[start:start + 4] < 0:
                moved[start:start + 4] *= -1
        np.testing.assert_allclose(moved, expected, rtol=0, atol=1e-12)
        np.testing.assert_allclose(d.difference(q, d.integrate(q, v, 0.3)), 0.3 * v,
                                   rtol=0, atol=1e-12)


def test_frames_agree_with_mujoco(chain):
    """Each body's frame (at its joint's anchor: xanchor, the body's axes xmat) and its
    Jacobian there (mj_jac: angular rows world axes) on the numpy frames."""
    _, dynamics, model = chain
    d = dynamics["compiled"]
    data = mujoco.MjData(model)
    for q in _states(model, 3, seed=4)[0]:
        data.qpos[:] = q
        mujoco.mj_forward(model, data)
        for body, joint in (("upper", "shoulder"), ("lower", "elbow"), ("hand", "wrist")):
            k = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
            anchor = data.xanchor[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)]
            H = d.placement(q, body)
            np.testing.assert_allclose(H[:3, 3], anchor, rtol=0, atol=1e-12)
            np.testing.assert_allclose(H[:3, :3], data.xmat[k].reshape(3, 3), rtol=0, atol=1e-12)
            jp, jr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
            mujoco.mj_jac(model, data, jp, jr, anchor, k)
            J = d.jacobian(q, body)
            np.testing.assert_allclose(J[:3], jp, rtol=0, atol=1e-12)
            np.testing.assert_allclose(J[3:], jr, rtol=0, atol=1e-12)


def test_what_has_no_ball_joint_yet_refuses_it_by_name(chain):
    """The numeric system (q_dot = v) has none; kernel="unrolled" and the C export do
    (tests/dynamics/test_joint_kinds_export.py)."""
    _, dynamics, _ = chain
    with pytest.raises(lagrangian.LagrangianError, match="'shoulder' is a ball") as error:
        dynamics["compiled"].numeric_system()
    assert "\n" not in str(error.value)


@pytest.mark.parametrize("robot", ["chain", "bodies", "floating"])
def test_compiled_frames_agree_with_the_numpy_reference(request, robot):
    """The compiled reach module (joint.h's ball branch) on a tree with ball joints: every
    frame's placement and Jacobian in the three references, the centre of mass and its
    Jacobian, and (the ball as its body's three columns, each fixed in the body: S_dot = V x S)
    J_dot v, A_g, C(q, v) and the wrenches' one Newton-Euler pass against the numpy reference
    (frames.py, centroidal.py, coriolis_tree.py, wrenches.py), to 1e-12; a NaN state's row NaN."""
    _, dynamics, _ = request.getfixturevalue(robot)
    ours, reference = dynamics["compiled"], dynamics["numpy"]
    kernel = ours._reach_kernel()
    if not kernel:
        pytest.skip("no C compiler")
    rng = np.random.default_rng(5)
    Q = rng.uniform(-1.0, 1.0, (4, ours.nq))
    tree = ours.tree
    starts = [3] * tree.floating_base + [tree.base_nq + j.coordinate for j in tree.spherical]
    for a in starts:
        Q[:, a:a + 4] /= np.linalg.norm(Q[:, a:a + 4], axis=-1, keepdims=True)
    for frame in ours.frames:
        np.testing.assert_allclose(kernel.placement(Q, frame), reference.placement(Q, frame),
                                   rtol=0, atol=1e-12)
        for ref in ("world", "local", "local_world_aligned"):
            np.testing.assert_allclose(kernel.jacobian(Q, frame, ref),
                                       reference.jacobian(Q, frame, ref), rtol=0, atol=1e-12)
    np.testing.assert_allclose(kernel.center_of_mass(Q), reference.center_of_mass(Q),
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(kernel.center_of_mass_jacobian(Q),
                               reference.center_of_mass_jacobian(Q), rtol=0, atol=1e-12)
    V = rng.uniform(-1.0, 1.0, (4, ours.nv))
    for frame in ours.frames:  # compiled, not the numpy walks the front used to fall back on
        for ref in ("world", "local", "local_world_aligned"):
            np.testing.assert_allclose(kernel.drift(Q, V, frame, ref),
                                       reference.jacobian_dot_times_v(Q, V, frame, ref),
                                       rtol=0, atol=1e-12)
    np.testing.assert_allclose(kernel.centroidal(Q), reference.centroidal_momentum_matrix(Q),
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(kernel.coriolis(Q, V), reference.coriolis_matrix(Q, V),
                               rtol=0, atol=1e-12)
    one_pass = kernel.fused_inverse(ours)
    assert one_pass, "the wrenches' one pass checked equal and taken"
    wrench = {ours.frames[-1]: rng.uniform(-2.0, 2.0, (4, 6))}
    np.testing.assert_allclose(one_pass(Q, V, V, wrench),
                               reference.inverse_dynamics(Q, V, V, f_ext=wrench),
                               rtol=0, atol=1e-11)
    Q[2, -1] = np.nan
    J, bad = kernel.jacobian(Q, ours.frames[-1], "world")
    assert bad == 1 and np.isnan(J[2]).all() and not np.isnan(J[[0, 1, 3]]).any()
    V = rng.uniform(-1.0, 1.0, (2, ours.nv))
    for call in (lambda d: d.jacobian_dot_times_v(Q[:2], V, ours.frames[-1]),
                 lambda d: d.centroidal_momentum_matrix(Q[:2]),
                 lambda d: d.inverse_dynamics(Q[:2], V, V, f_ext={ours.frames[-1]: np.ones(6)})):
        # the rates, A_g and wrenches through a ball (the numpy walks, test_ball_rates.py's
        # MuJoCo oracle): the compiled front gives the reference's numbers
        np.testing.assert_allclose(call(ours), call(reference), rtol=0, atol=1e-10)
