"""The torque regressor of a floating base (nv rows, the first six the wrench on the base in its
axes): Pinocchio's computeJointTorqueRegressor on its free-flyer model for Solo12, ANYmal and
Talos, Y pi equal to our own inverse dynamics, a base parameter set of the numerical rank of
stacked Y (more than the same robot's fixed base), the command's --floating-base, bad input in
one line."""

from __future__ import annotations

import json

import numpy as np
import pytest
from tests.dynamics.test_floating_base import FLOATING_URDF

import lagrangian
from robot_data import robots as _robots

pytest.importorskip("yourdfpy")




def _columns(model, ours):
    """Pinocchio's rows (v) and columns (10 per joint after the universe) in our order: our
    bodies by joint name (Pinocchio visits sibling joints by name)."""
    ids = [model.getJointId(j.name) for j in ours.tree.joints[1:]]
    iq = np.array(list(range(7)) + [model.idx_qs[i] for i in ids])
    iv = np.array(list(range(6)) + [model.idx_vs[i] for i in ids])
    columns = np.concatenate([np.arange(10)] + [np.arange(10 * (i - 1), 10 * i) for i in ids])
    return iq, iv, columns


@pytest.mark.parametrize("robot", ["solo_description/robots/solo12.urdf",
                                   "anymal_b_simple_description/robots/anymal.urdf",
                                   "talos_data/robots/talos_reduced.urdf"])
@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_floating_regressor_is_pinocchios(robot, backend):
    import pinocchio as pin

    path = _robots() / robot
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = model.createData()
    ours = lagrangian.load(path, floating_base=True).dynamics(backend=backend)
    if backend == "c" and ours._derivatives_kernel() is None:
        pytest.skip("no C compiler")
    iq, iv, columns = _columns(model, ours)
    rng = np.random.default_rng(0)
    states = 3
    q = np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
                  for _ in range(states)])
    v, a = rng.uniform(-2, 2, (2, states, model.nv))
    Y = ours.regressor(q[:, iq], v[:, iv], a[:, iv])
    assert Y.shape == (states, model.nv, 10 * (model.njoints - 1))
    pi = ours.inertial_parameters()
    theirs_pi = np.concatenate([model.inertias[i].toDynamicParameters()
                                for i in range(1, model.njoints)])
    np.testing.assert_allclose(pi, theirs_pi[columns], rtol=0, atol=1e-14 * np.abs(pi).max())
    inverse = ours.inverse_dynamics(q[:, iq], v[:, iv], a[:, iv])
    for k in range(states):
        theirs = pin.computeJointTorqueRegressor(model, data, q[k], v[k], a[k])
        scale = max(1.0, np.abs(theirs).max())
        np.testing.assert_allclose(Y[k], theirs[np.ix_(iv, columns)], rtol=0, atol=1e-12 * scale)
        tau = pin.rnea(model, data, q[k], v[k], a[k])[iv]
        np.testing.assert_allclose(Y[k] @ pi, tau, rtol=0,
                                   atol=1e-12 * max(1.0, np.abs(tau).max()))
        np.testing.assert_allclose(Y[k] @ pi, inverse[k], rtol=0,
                                   atol=1e-12 * max(1.0, np.abs(tau).max()))
    assert ours.parameter_names()[0] == f"m@{ours.tree.joints[0].name}"


def test_floating_base_parameters_have_the_rank_of_stacked_Y():
    """A floating base identifies more than the same robot bolted down: Solo12's base set has
    the numerical rank of Y stacked over random states (94 of 130; 68 on a fixed base)."""
    path = _robots() / "solo_description/robots/solo12.urdf"
    ours = lagrangian.load(path, floating_base=True).dynamics(backend="numpy")
    base = ours.base_parameters()
    rng = np.random.default_rng(4)
    count = 60
    q = np.concatenate([rng.uniform(-1, 1, (count, 3)), rng.normal(size=(count, 4)),
                        rng.uniform(-3, 3, (count, 12))], axis=1)
    q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=1, keepdims=True)
    v, a = rng.uniform(-3, 3, (2, count, 18))
    Y = ours.regressor(q, v, a)
    singular = np.linalg.svd(Y.reshape(-1, Y.shape[-1]), compute_uv=False)
    assert len(base) == int(np.sum(singular > 1e-9 * singular[0])) == 94
    assert len(lagrangian.load(path).dynamics(backend="numpy").base_parameters()) == 68
    pi = ours.inertial_parameters()
    np.testing.assert_allclose(base.regressor(Y) @ base.values(pi), Y @ pi, rtol=0, atol=1e-10)


def test_regressor_command_takes_a_floating_base(cli, tmp_path):
    """A hopper whose URDF floats its trunk: Y pi is the inverse dynamics `dynamics` prints,
    and Newton's law holds for the whole robot at rest (the force on the base is m g)."""
    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    q = "0.1,0.2,0.3,0,0,0.6,0.8,0.4,-0.7,0.05"
    state = ["--q", q, "--v", "0.5,-0.2,0.1,0.3,-0.4,0.2,1,-1,0.5", "--a",
             "0.2,0.1,-0.3,1,0.5,-2,0.4,0.3,-0.1"]
    result = cli("regressor", str(path), *state, "--base", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert len(document["coordinates"]) == 10 and document["velocities"][:6] == [
        "base_vx", "base_vy", "base_vz", "base_wx", "base_wy", "base_wz"]
    Y, pi = np.array(document["regressor"]), np.array(document["values"])
    assert Y.shape == (9, 40) and len(document["base"]["names"]) < 40
    inverse = json.loads(cli("dynamics", str(path), *state, "--json").out)["inverse_dynamics"]
    np.testing.assert_allclose(Y @ pi, inverse, rtol=0, atol=1e-12 * np.abs(inverse).max())
    at_rest = json.loads(cli("regressor", str(path), "--q", "0,0,0,0,0,0,1,0,0,0",
                             "--json").out)
    tau = np.array(at_rest["tau"])
    # the base's force (in its own turned axes) holds up the robot's 4.35 kg
    assert np.linalg.norm(tau[:3]) == pytest.approx(4.35 * 9.81, rel=1e-12)
    assert "base_wz" in cli("regressor", str(path)).out


@pytest.mark.parametrize("flags, message", [
    (["--q", "0,0,0"], "error: --q: expected 10 comma-separated values"),
    (["--q", "0,0,0,0,0,0,0.5,0,0,0"], "error: --q: the base quaternion"),
    (["--v", "0,0,0"], "error: --v: expected 9 comma-separated values"),
])
def test_floating_regressor_command_refuses_bad_input_in_one_line(cli, flags, message, tmp_path):
    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    result = cli("regressor", str(path), *flags)
    assert result.code == 2
    assert result.err.strip().startswith(message), result.err
    assert len(result.err.strip().splitlines()) == 1


def test_a_large_batch_is_its_states_one_by_one(tmp_path):
    """300 states in one call (body by body) and a few at a time (all bodies at once) give the
    same Y, and Y pi is the inverse dynamics, a (2, 150) batch keeping its shape."""
    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    robot = lagrangian.load(path).dynamics(backend="numpy")
    rng = np.random.default_rng(6)
    q = np.concatenate([rng.uniform(-1, 1, (300, 3)), rng.normal(size=(300, 4)),
                        rng.uniform(-2, 2, (300, 3))], axis=1)
    q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=1, keepdims=True)
    v, a = rng.uniform(-2, 2, (2, 300, 9))
    Y = robot.regressor(q.reshape(2, 150, 10), v.reshape(2, 150, 9), a.reshape(2, 150, 9))
    assert Y.shape == (2, 150, 9, 40)
    Y = Y.reshape(300, 9, 40)
    np.testing.assert_allclose(Y[:5], robot.regressor(q[:5], v[:5], a[:5]), rtol=0, atol=1e-13)
    inverse = robot.inverse_dynamics(q, v, a)
    np.testing.assert_allclose(Y @ robot.inertial_parameters(), inverse, rtol=0,
                               atol=1e-12 * np.abs(inverse).max())
