"""The derivatives of a tree's dynamics in compiled C (dynamics/engine/derivatives_c.py): against
Pinocchio's computeRNEADerivatives / computeABADerivatives, the complex step through our
numpy Newton-Euler (derivatives.py), and central differences of our own inverse and forward
dynamics, on a branched tree with a mimic joint, a tilted prismatic axis and a massless link;
batches, NaN rows and bad input."""

from __future__ import annotations

import numpy as np
import pytest
from test_dynamics_pinocchio import ARM
from test_recursive_dynamics import TREE

import lagrangian
from lagrangian.compile import compiled
from robot_data import robots as _robots

needs_c = pytest.mark.skipif(not compiled.available(), reason="no C compiler")


@pytest.fixture(scope="module")
def turret(tmp_path_factory):
    path = tmp_path_factory.mktemp("tree") / "turret.urdf"
    path.write_text(TREE)
    return lagrangian.load(path, lock={"grip": 0.01})


def _states(n, count, seed):
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.5, 1.5, (3, count, n))


@needs_c
def test_compiled_derivatives_are_the_complex_steps_on_a_branched_tree_with_a_mimic(turret):
    fast, slow = turret.dynamics(), turret.dynamics(backend="numpy")
    assert fast._derivatives_kernel() is not None and slow._derivatives_kernel() is None
    q, v, a = _states(fast.n, 6, 1)
    for ours, theirs in zip(fast.inverse_dynamics_derivatives(q, v, a),
                            slow.inverse_dynamics_derivatives(q, v, a), strict=True):
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-11)
    for ours, theirs in zip(fast.forward_dynamics_derivatives(q, v, a),
                            slow.forward_dynamics_derivatives(q, v, a), strict=True):
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-9)


@needs_c
def test_compiled_derivatives_agree_with_central_differences_of_our_dynamics(turret):
    """An actuator parameter tau_<joint> set (a load: it moves q_ddot, not d tau) and gravity
    changed: d tau/dq, d tau/dq_dot of inverse dynamics, d q_ddot/dq, d q_ddot/dq_dot,
    d q_ddot/d tau of forward dynamics, each column by central differences (error ~ h^2)."""
    plain = turret.dynamics()
    load = plain.tree.actuators[0]
    dynamics = turret.dynamics(parameters={load: 0.7, plain.tree.gravity_parameter: 3.0})
    assert dynamics._derivatives_kernel() is not None
    n = dynamics.n
    q, v, a = _states(n, 1, 2)[:, 0]
    dq, dv = dynamics.inverse_dynamics_derivatives(q, v, a)
    fq, fv, ftau = dynamics.forward_dynamics_derivatives(q, v, a)
    h = 1e-6
    for k in range(n):
        e = h * np.eye(n)[k]
        for ours, f, args in ((dq, dynamics.inverse_dynamics, lambda s: (q + s, v, a)),
                              (dv, dynamics.inverse_dynamics, lambda s: (q, v + s, a)),
                              (fq, dynamics.forward_dynamics, lambda s: (q + s, v, a)),
                              (fv, dynamics.forward_dynamics, lambda s: (q, v + s, a)),
                              (ftau, dynamics.forward_dynamics, lambda s: (q, v, a + s))):
            central = (f(*args(e)) - f(*args(-e))) / (2 * h)
            np.testing.assert_allclose(ours[:, k], central, rtol=0, atol=2e-6)


@needs_c
@pytest.mark.slow  # a module of its own to compile (tens of seconds on a shared machine)
def test_compiled_derivatives_of_a_spatial_arm_are_pinocchios(tmp_path):
    pin = pytest.importorskip("pinocchio")
    pytest.importorskip("yourdfpy")
    path = tmp_path / "spatial.urdf"
    path.write_text(ARM)
    ours = lagrangian.load(path).dynamics()
    assert ours._derivatives_kernel() is not None
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    q, v, a = _states(model.nv, 5, 3)
    dq, dv = ours.inverse_dynamics_derivatives(q, v, a)
    fq, fv, ftau = ours.forward_dynamics_derivatives(q, v, a)
    for k in range(5):
        pq, pv, _ = pin.computeRNEADerivatives(model, data, q[k], v[k], a[k])
        np.testing.assert_allclose(dq[k], pq, rtol=0, atol=1e-10)
        np.testing.assert_allclose(dv[k], pv, rtol=0, atol=1e-10)
        pin.computeABADerivatives(model, data, q[k], v[k], a[k])
        np.testing.assert_allclose(fq[k], data.ddq_dq, rtol=0, atol=1e-10)
        np.testing.assert_allclose(fv[k], data.ddq_dv, rtol=0, atol=1e-10)
        Minv = np.triu(data.Minv) + np.triu(data.Minv, 1).T
        np.testing.assert_allclose(ftau[k], Minv, rtol=0, atol=1e-10)


@needs_c
def test_compiled_batches_broadcast_and_report_nan_rows(turret):
    dynamics = turret.dynamics()
    n = dynamics.n
    q, v, a = _states(n, 4, 5)
    one = [dynamics.inverse_dynamics_derivatives(q[k], v[k], a[k]) for k in range(4)]
    together = dynamics.inverse_dynamics_derivatives(q, v, a)
    for k in range(4):  # several states on vector lanes: equal to rounding
        np.testing.assert_allclose(together[0][k], one[k][0], rtol=0, atol=1e-12)
        np.testing.assert_allclose(together[1][k], one[k][1], rtol=0, atol=1e-12)
    # one q for a batch of rates; a (2, 2) batch keeps its shape
    shared = dynamics.inverse_dynamics_derivatives(q[0], v, a)
    np.testing.assert_allclose(shared[0][1], dynamics.inverse_dynamics_derivatives(
        q[0], v[1], a[1])[0], rtol=0, atol=1e-12)
    assert dynamics.forward_dynamics_derivatives(q.reshape(2, 2, n), v.reshape(2, 2, n),
                                                 a.reshape(2, 2, n))[2].shape == (2, 2, n, n)
    bad = q.copy()
    bad[2, 0] = np.nan
    with pytest.warns(lagrangian.DynamicsWarning, match="1 of 4 states"):
        dq, dv = dynamics.inverse_dynamics_derivatives(bad, v, a)
    assert np.isnan(dq[2]).all() and np.isnan(dv[2]).all()
    np.testing.assert_allclose(dq[[0, 1, 3]], together[0][[0, 1, 3]], rtol=0, atol=1e-12)
    with pytest.warns(lagrangian.DynamicsWarning, match="1 of 4 states"):
        fq, _, ftau = dynamics.forward_dynamics_derivatives(bad, v, a)
    assert np.isnan(fq[2]).all() and np.isfinite(ftau[[0, 1, 3]]).all()


@needs_c
def test_compiled_derivatives_refuse_bad_shapes_in_one_line(turret):
    dynamics = turret.dynamics()
    n = dynamics.n
    with pytest.raises(lagrangian.InputError, match=f"expected {n} values") as caught:
        dynamics.inverse_dynamics_derivatives(np.zeros(n + 1), np.zeros(n), np.zeros(n))
    assert caught.value.field == "q" and "\n" not in str(caught.value)
    with pytest.raises(lagrangian.InputError, match=f"expected {n} values") as caught:
        dynamics.forward_dynamics_derivatives(np.zeros(n), np.zeros(n), [0.0])
    assert caught.value.field == "tau"


@needs_c
def test_dynamics_command_gives_the_compiled_derivatives(tmp_path, cli):
    """`dynamics ARM.urdf --derivatives --json` (the compiled path) is Pinocchio's."""
    import json

    pin = pytest.importorskip("pinocchio")
    pytest.importorskip("yourdfpy")
    path = tmp_path / "spatial.urdf"
    path.write_text(ARM)
    q, v, a = [0.3, -0.7, 0.2], [0.5, 1.0, -0.4], [1.0, -2.0, 0.5]
    result = cli("dynamics", str(path), "--q", ",".join(map(str, q)), "--v",
                 ",".join(map(str, v)), "--a", ",".join(map(str, a)), "--derivatives", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()  # kept: Pinocchio's results are views of it
    pq, pv, _ = pin.computeRNEADerivatives(model, data, np.array(q), np.array(v), np.array(a))
    np.testing.assert_allclose(document["dtau_dq"], pq, rtol=0, atol=1e-10)
    np.testing.assert_allclose(document["dtau_dv"], pv, rtol=0, atol=1e-10)


@needs_c
def test_compiled_regressor_is_the_numpy_one_and_gives_tau(turret):
    """Y pi is inverse dynamics (the actuator parameters aside); Y equals the numpy regressor
    (derivatives.py's path) on the branched tree with its mimic joint; a NaN row is reported."""
    fast, slow = turret.dynamics(), turret.dynamics(backend="numpy")
    q, v, a = _states(fast.n, 6, 7)
    Y = fast.regressor(q, v, a)
    np.testing.assert_allclose(Y, slow.regressor(q, v, a), rtol=0, atol=1e-12)
    np.testing.assert_allclose(Y @ fast.inertial_parameters(), fast.inverse_dynamics(q, v, a),
                               rtol=0, atol=1e-11)
    np.testing.assert_allclose(fast.regressor(q[0], v[0], a[0]), Y[0], rtol=0, atol=1e-12)
    bad = v.copy()
    bad[1, 0] = np.inf
    with pytest.warns(lagrangian.DynamicsWarning, match="1 of 6 states"):
        Y = fast.regressor(q, bad, a)
    assert np.isnan(Y[1]).all() and np.isfinite(Y[[0, 2, 3, 4, 5]]).all()


@needs_c
@pytest.mark.slow  # a module of its own to compile (tens of seconds on a shared machine)
def test_floating_base_derivatives_are_pinocchios():
    """Solo12 on a free flyer (nq 19, nv 18): d/dq along the base's own axes, q (+) dq, as
    Pinocchio's; to 1e-10 of each matrix's largest entry (M^-1 of the light legs is large)."""
    pin = pytest.importorskip("pinocchio")
    pytest.importorskip("yourdfpy")
    path = _robots(pin) / "solo_description/robots/solo12.urdf"
    ours = lagrangian.load(path, floating_base=True).dynamics()
    assert ours._derivatives_kernel() is not None
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    assert ours.coordinates[7:] == tuple(model.names[i] for i in range(2, model.njoints))
    data = model.createData()
    rng = np.random.default_rng(8)
    count = 5
    quaternion = rng.normal(size=(count, 4))
    q = np.concatenate([rng.normal(size=(count, 3)),
                        quaternion / np.linalg.norm(quaternion, axis=-1, keepdims=True),
                        rng.uniform(-1, 1, (count, model.nq - 7))], axis=-1)
    v, a = rng.normal(size=(2, count, model.nv))
    dq, dv = ours.inverse_dynamics_derivatives(q, v, a)
    fq, fv, ftau = ours.forward_dynamics_derivatives(q, v, a)

    def close(mine, theirs):
        np.testing.assert_allclose(mine, theirs, rtol=0,
                                   atol=1e-10 * max(1.0, np.abs(theirs).max()))

    for k in range(count):
        pq, pv, _ = pin.computeRNEADerivatives(model, data, q[k], v[k], a[k])
        close(dq[k], pq)
        close(dv[k], pv)
        pin.computeABADerivatives(model, data, q[k], v[k], a[k])
        close(fq[k], data.ddq_dq)
        close(fv[k], data.ddq_dv)
        close(ftau[k], np.triu(data.Minv) + np.triu(data.Minv, 1).T)




@needs_c
def test_floating_base_derivatives_agree_with_central_differences_on_the_manifold(tmp_path):
    """The hopper of test_floating_base.py: each column of d tau/dq and d q_ddot/dq by central
    differences along q (+) h e_k (free_flyer.integrate), of d tau/dq_dot and d q_ddot/dq_dot
    along v; a bad quaternion is refused in one line."""
    from test_floating_base import FLOATING_URDF

    from lagrangian.dynamics.tree.free_flyer import integrate

    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    robot = lagrangian.load(path).dynamics()
    assert robot._derivatives_kernel() is not None
    rng = np.random.default_rng(9)
    quaternion = rng.normal(size=4)
    q = np.concatenate([rng.normal(size=3), quaternion / np.linalg.norm(quaternion),
                        rng.uniform(-1, 1, robot.nq - 7)])
    v, a = rng.normal(size=(2, robot.nv))
    dq, dv = robot.inverse_dynamics_derivatives(q, v, a)
    fq, fv, _ = robot.forward_dynamics_derivatives(q, v, a)
    h = 1e-6
    for k in range(robot.nv):
        e = h * np.eye(robot.nv)[k]
        plus, minus = integrate(q[None], e[None])[0], integrate(q[None], -e[None])[0]
        for ours, f, args in ((dq, robot.inverse_dynamics, lambda s, x: (x, v, a)),
                              (fq, robot.forward_dynamics, lambda s, x: (x, v, a)),
                              (dv, robot.inverse_dynamics, lambda s, x: (q, v + s, a)),
                              (fv, robot.forward_dynamics, lambda s, x: (q, v + s, a))):
            central = (f(*args(e, plus)) - f(*args(-e, minus))) / (2 * h)
            np.testing.assert_allclose(ours[:, k], central, rtol=0, atol=2e-6)
    bad = np.r_[q[:6], 2.0, q[7:]]
    batch = np.stack([q, q, q])
    batch[1, 3:7] *= 1 + 1e-5  # off by ten times the tolerance, in the batch's second state
    for function in (robot.inverse_dynamics_derivatives, robot.forward_dynamics_derivatives,
                     robot.regressor):
        with pytest.raises(lagrangian.InputError, match="norm 2") as caught:
            function(bad, v, a)
        assert caught.value.field == "q" and "\n" not in str(caught.value)
        with pytest.raises(lagrangian.InputError, match="norm 1.00001 in state 1"):
            function(batch, v, a)


@needs_c
def test_a_link_inertial_set_at_run_time_reuses_the_module(turret):
    """`<link>.mass` and `.com_x` given to dynamics(): the same compiled module (the inertials
    are run-time numbers), the complex step's derivatives at those inertials."""
    plain = turret.dynamics()
    heavier = {"left.mass": 2.5, "left.com_x": 0.3}
    fast, slow = turret.dynamics(parameters=heavier), turret.dynamics(parameters=heavier,
                                                                      backend="numpy")
    assert fast._derivatives_kernel()[2].func is plain._derivatives_kernel()[2].func
    q, v, a = _states(fast.n, 3, 10)
    for ours, theirs in zip(fast.inverse_dynamics_derivatives(q, v, a),
                            slow.inverse_dynamics_derivatives(q, v, a), strict=True):
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-11)
    assert not np.allclose(fast.inverse_dynamics_derivatives(q, v, a)[0],
                           plain.inverse_dynamics_derivatives(q, v, a)[0])


@needs_c
@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
def test_a_branching_trees_factor_along_the_tree_gives_the_forward_derivatives(tmp_path,
                                                                              floating):
    """Two legs on a trunk (fixed, or on a free flyer): forward dynamics' M is factored along
    the tree (M = L^T D L, no fill-in) and the products skip the legs' zero blocks. Fixed: the
    complex step through numpy Newton-Euler (an independent derivation); floating: M^-1 times
    M is the identity, and each column by central differences on the manifold."""
    pytest.importorskip("yourdfpy")
    from test_reach_reports import TWO_LEGS

    from lagrangian.dynamics.engine.derivatives_c import factored_along_the_tree
    from lagrangian.dynamics.tree.free_flyer import integrate

    path = tmp_path / "biped.urdf"
    path.write_text(TWO_LEGS)
    robot = lagrangian.load(path, floating_base=floating).dynamics()
    assert robot._derivatives_kernel() is not None
    parents = factored_along_the_tree(robot.tree)
    assert parents is not None and parents.count(5 if floating else -1) == 2  # two legs
    rng = np.random.default_rng(12)
    count = 11  # a group of eight lanes and three states one by one
    q = rng.uniform(-1.0, 1.0, (count, robot.nq))
    if floating:
        q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
    v, tau = rng.uniform(-1.0, 1.0, (2, count, robot.nv))
    fq, fv, ftau = robot.forward_dynamics_derivatives(q, v, tau)
    identity = np.einsum("kij,kjl->kil", robot.mass_matrix(q), ftau)
    np.testing.assert_allclose(identity, np.broadcast_to(np.eye(robot.nv), identity.shape),
                               atol=1e-11)
    if not floating:
        slow = lagrangian.load(path).dynamics(backend="numpy")
        for ours, theirs in zip((fq, fv, ftau), slow.forward_dynamics_derivatives(q, v, tau),
                                strict=True):
            np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-9)
        return
    h = 1e-6
    for k in range(robot.nv):
        e = h * np.eye(robot.nv)[k]
        for state in (0, 9):
            plus, minus = integrate(q[state][None], e[None])[0], integrate(q[state][None],
                                                                           -e[None])[0]
            central = (robot.forward_dynamics(plus, v[state], tau[state])
                       - robot.forward_dynamics(minus, v[state], tau[state])) / (2 * h)
            np.testing.assert_allclose(fq[state][:, k], central, rtol=0, atol=2e-6)
            central = (robot.forward_dynamics(q[state], v[state] + e, tau[state])
                       - robot.forward_dynamics(q[state], v[state] - e, tau[state])) / (2 * h)
            np.testing.assert_allclose(fv[state][:, k], central, rtol=0, atol=2e-6)


# a free trunk with an arm on two ball joints (shoulder, wrist) about an elbow, and a leg: as
# MuJoCo's free joint (three world slides and a ball) and, loaded with floating_base, on the
# free flyer; the tree branches at the trunk (M factored along the tree)
BALL_ARM = """<mujoco><worldbody><body name="trunk"><freejoint name="root"/>
<geom type="box" size="0.2 0.1 0.05" mass="3"/>
<body name="arm" pos="0.2 0 0"><joint name="shoulder" type="ball"/>
<geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="0.7"/>
<body name="fore" pos="0.3 0 0"><joint name="elbow" axis="0 1 0"/>
<geom type="capsule" fromto="0 0 0 0.25 0 0" size="0.02" mass="0.4"/>
<body name="hand" pos="0.25 0 0"><joint name="wrist" type="ball"/>
<geom type="sphere" size="0.04" mass="0.2" pos="0.05 0.01 0"/></body></body></body>
<body name="leg" pos="-0.2 0 0"><joint name="hip" axis="1 0 0"/>
<geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03" mass="0.6"/></body>
</body></worldbody></mujoco>"""


@pytest.fixture(scope="module")
def ball_arm(tmp_path_factory):
    path = tmp_path_factory.mktemp("ball") / "arm.xml"
    path.write_text(BALL_ARM)
    return {floating: lagrangian.load(path, floating_base=floating) for floating in (False, True)}


def _unit_states(dynamics, count, seed):
    from lagrangian.dynamics.tree.spherical import quaternion_slices

    rng = np.random.default_rng(seed)
    q = rng.uniform(-1, 1, (count, len(dynamics.coordinates)))
    slices = [iq for _, _, iq, _ in quaternion_slices(dynamics.tree)]
    for iq in slices + ([3] if dynamics.tree.floating_base else []):
        q[:, iq:iq + 4] /= np.linalg.norm(q[:, iq:iq + 4], axis=1, keepdims=True)
    return q, *rng.uniform(-1, 1, (2, count, dynamics.n))


@needs_c
@pytest.mark.parametrize("floating", [False, True])
def test_ball_joints_compiled_derivatives_are_the_complex_steps(ball_arm, floating):
    """A ball joint in the engine as its three columns (the turn of the body's axes x, y, z,
    each moving the subtree from the ball's parent's motion): d tau/dq along q (x) exp(dq) and
    d tau/dv equal the complex step through the numpy reference's Newton-Euler, and the forward
    derivatives -M^-1 d tau and M^-1, on both layouts, a batch on the lanes."""
    from lagrangian.dynamics.derivatives import tree_inverse_dynamics_derivatives
    from lagrangian.dynamics.recursive_numpy import NumpyBackend

    dynamics = ball_arm[floating].dynamics()
    assert dynamics._derivatives_kernel() is not None  # the engine's, not the complex step
    q, v, a = _unit_states(dynamics, 6, 3)
    exact = tree_inverse_dynamics_derivatives(
        NumpyBackend(dynamics.tree, dynamics.parameters, dynamics.n), q, v, a)
    for ours, theirs in zip(dynamics.inverse_dynamics_derivatives(q, v, a), exact, strict=True):
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-12 * np.abs(theirs).max())
    fq, fv, inverse = dynamics.forward_dynamics_derivatives(q, v, a)
    accelerations = dynamics.forward_dynamics(q, v, a)
    dq, dv = tree_inverse_dynamics_derivatives(
        NumpyBackend(dynamics.tree, dynamics.parameters, dynamics.n), q, v, accelerations)
    np.testing.assert_allclose(inverse @ dynamics.mass_matrix(q), np.broadcast_to(
        np.eye(dynamics.n), inverse.shape), rtol=0, atol=1e-10)
    np.testing.assert_allclose(fq, -inverse @ dq, rtol=0, atol=1e-10 * np.abs(fq).max())
    np.testing.assert_allclose(fv, -inverse @ dv, rtol=0, atol=1e-10 * np.abs(fv).max())


@needs_c
def test_ball_joints_compiled_derivatives_refuse_a_quaternion_off_unit_in_one_line(ball_arm):
    dynamics = ball_arm[False].dynamics()
    q, v, a = _unit_states(dynamics, 1, 4)
    q[0, 7:11] *= 0.5  # the shoulder's w x y z (after the free joint's 7)
    for call in (dynamics.inverse_dynamics_derivatives, dynamics.forward_dynamics_derivatives):
        with pytest.raises(lagrangian.InputError, match="'shoulder'.*norm 0.5") as caught:
            call(q[0], v[0], a[0])
        assert "\n" not in str(caught.value)
    q[0, 7] = np.nan  # a state not finite: its rows NaN, the warning counts it
    with pytest.warns(lagrangian.DynamicsWarning, match="1 of 1 states"):
        dq, _ = dynamics.inverse_dynamics_derivatives(q, v, a)
    assert np.isnan(dq).all()


@needs_c
@pytest.mark.parametrize("floating", [False, True])
def test_ball_joints_compiled_regressor_gives_tau(ball_arm, floating):
    """The compiled regressor over the tree's own bodies (a ball's first two records, massless,
    left out): Y pi = tau, and Y the numpy walks' own, ten columns a body."""
    dynamics = ball_arm[floating].dynamics()
    q, v, a = _unit_states(dynamics, 4, 6)
    fast = dynamics._derivatives_kernel()
    Y = fast.regressor(q, v, a, fast.P)
    np.testing.assert_allclose(Y @ dynamics.inertial_parameters(),
                               dynamics.inverse_dynamics(q, v, a), rtol=0, atol=1e-12)
    reference = ball_arm[floating].dynamics(backend="numpy").regressor(q, v, a)
    np.testing.assert_allclose(Y, reference, rtol=0, atol=1e-12)
    assert Y.shape[-1] == 10 * len(dynamics.tree.joints)
