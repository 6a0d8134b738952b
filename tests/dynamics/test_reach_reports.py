"""The functions of a state beyond the dynamics (placement, Jacobian, centre of mass and its
Jacobian, J_dot v, A_g, C(q, v), inverse and forward dynamics with wrenches) report a state that
is not finite as the dynamics functions do (test_batch_reports.py): NaN in its whole row, one
DynamicsWarning per call counting such states, every other row that state's call alone. On a
branching tree a NaN in one leg used to leave the other leg's numbers finite (its foot's
Jacobian does not depend on it), and the compiled and numpy paths differed in which rows they
left NaN and how many warnings they gave."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import lagrangian

pytest.importorskip("yourdfpy")

# A trunk with two legs of a revolute hip and a prismatic knee each, a foot frame on each.
TWO_LEGS = """<?xml version="1.0"?>
<robot name="biped">
  <link name="trunk"><inertial><origin xyz="0.01 0 0.05"/><mass value="4.0"/>
    <inertia ixx="0.05" ixy="0.001" ixz="0" iyy="0.06" iyz="0" izz="0.04"/></inertial></link>
  <link name="l_thigh"><inertial><origin xyz="0 0 -0.15"/><mass value="0.8"/>
    <inertia ixx="0.006" ixy="0" ixz="0.0004" iyy="0.006" iyz="0" izz="0.001"/></inertial></link>
  <link name="l_shank"><inertial><origin xyz="0.01 0 -0.1"/><mass value="0.4"/>
    <inertia ixx="0.002" ixy="0.0001" ixz="0" iyy="0.002" iyz="0" izz="0.0004"/></inertial></link>
  <link name="r_thigh"><inertial><origin xyz="0 0 -0.15"/><mass value="0.8"/>
    <inertia ixx="0.006" ixy="0" ixz="0.0004" iyy="0.006" iyz="0" izz="0.001"/></inertial></link>
  <link name="r_shank"><inertial><origin xyz="0.01 0 -0.1"/><mass value="0.4"/>
    <inertia ixx="0.002" ixy="0.0001" ixz="0" iyy="0.002" iyz="0" izz="0.0004"/></inertial></link>
  <link name="l_foot"/>
  <link name="r_foot"/>
  <joint name="l_hip" type="revolute"><parent link="trunk"/><child link="l_thigh"/>
    <origin xyz="0 0.1 -0.05"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="l_knee" type="prismatic"><parent link="l_thigh"/><child link="l_shank"/>
    <origin xyz="0 0 -0.3" rpy="0.1 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-0.1" upper="0.1" effort="1" velocity="1"/></joint>
  <joint name="r_hip" type="revolute"><parent link="trunk"/><child link="r_thigh"/>
    <origin xyz="0 -0.1 -0.05"/><axis xyz="0.6 0.8 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="r_knee" type="prismatic"><parent link="r_thigh"/><child link="r_shank"/>
    <origin xyz="0 0 -0.3"/><axis xyz="0 0 1"/>
    <limit lower="-0.1" upper="0.1" effort="1" velocity="1"/></joint>
  <joint name="l_ankle" type="fixed"><parent link="l_shank"/><child link="l_foot"/>
    <origin xyz="0 0 -0.2"/></joint>
  <joint name="r_ankle" type="fixed"><parent link="r_shank"/><child link="r_foot"/>
    <origin xyz="0 0 -0.2"/></joint>
</robot>
"""
COUNT = 19  # two groups of eight lanes and three states one by one in the compiled batches
NAN_Q, INF_V, NAN_W, INF_A = 2, 9, 12, 17  # the states spoilt, one input each


def _robot(tmp_path, floating: bool, backend: str):
    path = tmp_path / "biped.urdf"
    path.write_text(TWO_LEGS)
    return lagrangian.load(path, floating_base=floating).dynamics(backend=backend)


def _inputs(robot):
    rng = np.random.default_rng(11)
    q = rng.uniform(-0.5, 0.5, (COUNT, len(robot.coordinates)))
    if robot.velocity_names is not None:
        q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
    v, a = rng.uniform(-1, 1, (2, COUNT, robot.n))
    w = rng.uniform(-5, 5, (COUNT, 6))
    q[NAN_Q, -1] = np.nan  # the right knee: nothing of the left foot depends on it
    v[INF_V, 0] = np.inf
    w[NAN_W, 2] = np.nan
    a[INF_A, -2] = -np.inf
    return {"q": q, "v": v, "a": a, "w": w}


FUNCTIONS = {  # name: (call, the inputs it takes, the axes of one state's output)
    "placement": (lambda r, x: r.placement(x["q"], "l_foot"), "q", 2),
    "jacobian": (lambda r, x: r.jacobian(x["q"], "l_foot", "world"), "q", 2),
    "center_of_mass": (lambda r, x: r.center_of_mass(x["q"]), "q", 1),
    "center_of_mass_jacobian": (lambda r, x: r.center_of_mass_jacobian(x["q"]), "q", 2),
    "jacobian_dot_times_v": (lambda r, x: r.jacobian_dot_times_v(x["q"], x["v"], "l_foot"),
                             "qv", 1),
    "centroidal_momentum_matrix": (lambda r, x: r.centroidal_momentum_matrix(x["q"]), "q", 2),
    "coriolis_matrix": (lambda r, x: r.coriolis_matrix(x["q"], x["v"]), "qv", 2),
    "inverse_dynamics f_ext": (
        lambda r, x: r.inverse_dynamics(x["q"], x["v"], x["a"], f_ext={"l_foot": x["w"]}),
        "qvaw", 1),
    "forward_dynamics f_ext": (
        lambda r, x: r.forward_dynamics(x["q"], x["v"], x["a"], f_ext={"l_foot": x["w"]}),
        "qvaw", 1),
}
DERIVATIVES = {  # three outputs concatenated, one row of n x 3n per state
    "inverse_dynamics_derivatives": (
        lambda r, x: np.concatenate(r.inverse_dynamics_derivatives(x["q"], x["v"], x["a"]), -1),
        "qva", 2),
    "forward_dynamics_derivatives": (
        lambda r, x: np.concatenate(r.forward_dynamics_derivatives(x["q"], x["v"], x["a"]), -1),
        "qva", 2),
    "regressor": (lambda r, x: r.regressor(x["q"], x["v"], x["a"]), "qva", 2),
}
FUNCTIONS.update(DERIVATIVES)
SPOILT = {"q": NAN_Q, "v": INF_V, "a": INF_A, "w": NAN_W}


@pytest.mark.parametrize("backend", ["c", "numpy"])
@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
@pytest.mark.parametrize("name", list(FUNCTIONS))
def test_a_state_not_finite_is_nan_in_its_whole_row_with_one_warning(tmp_path, backend,
                                                                      floating, name):
    robot = _robot(tmp_path, floating, backend)
    call, inputs, axes = FUNCTIONS[name]
    x = _inputs(robot)
    bad = {SPOILT[k] for k in inputs}
    with pytest.warns(lagrangian.DynamicsWarning) as record:
        out = call(robot, x)
    assert len(record) == 1, [str(r.message) for r in record]
    assert record[0].message.count == len(bad) and record[0].message.total == COUNT
    assert out.shape[0] == COUNT and out.ndim == 1 + axes
    for k in range(COUNT):
        if k in bad:
            assert np.isnan(out[k]).all(), k
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a good state alone warns of nothing
            alone = call(robot, {key: value[k] for key, value in x.items()})
        assert np.isfinite(alone).all()
        # the compiled batch's lanes may fuse a multiply-add where one state's code does not
        np.testing.assert_allclose(out[k], alone, rtol=0,
                                   atol=1e-13 * max(1.0, np.abs(alone).max()), err_msg=str(k))


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_the_good_batch_warns_of_nothing_and_shared_wrenches_count_once(tmp_path, backend):
    robot = _robot(tmp_path, True, backend)
    x = _inputs(robot)
    for k in ("q", "v", "a", "w"):
        x[k] = np.nan_to_num(x[k], nan=0.1, posinf=0.2, neginf=-0.2)
    x["q"][:, 3:7] /= np.linalg.norm(x["q"][:, 3:7], axis=-1, keepdims=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for name, (call, _, _) in FUNCTIONS.items():
            if backend == "c" or name not in DERIVATIVES:
                assert np.isfinite(call(robot, x)).all()
    # one wrench for the whole batch, not finite: every state is undefined
    with pytest.warns(lagrangian.DynamicsWarning) as record:
        tau = robot.inverse_dynamics(x["q"], x["v"], x["a"],
                                     f_ext={"l_foot": [0, 0, np.nan, 0, 0, 0]})
    assert len(record) == 1 and record[0].message.count == COUNT
    assert np.isnan(tau).all()


def test_forward_derivatives_of_a_state_with_a_singular_mass_matrix_are_nan_alone(tmp_path):
    """The numpy path (no compiler): one state's singular M made the whole batch's M^-1 fail."""
    from tests.dynamics.test_batch_reports import POINT_ARM

    path = tmp_path / "point_arm.urdf"
    path.write_text(POINT_ARM)
    arm = lagrangian.load(path).dynamics(backend="numpy")
    q = np.array([[0.3, 0.7], [0.0, 0.0], [1.1, -0.4]])  # row 1: elbow 0, M singular
    v, tau = np.full((3, 2), 0.5), np.ones((3, 2))
    with pytest.warns(lagrangian.DynamicsWarning, match="1 of 3 states") as record:
        by_q, by_v, inverse = arm.forward_dynamics_derivatives(q, v, tau)
    assert len(record) == 1
    assert all(np.isnan(x[1]).all() for x in (by_q, by_v, inverse))
    for k in (0, 2):
        np.testing.assert_allclose(inverse[k] @ arm.mass_matrix(q[k]), np.eye(2), atol=1e-12)
        alone = arm.forward_dynamics_derivatives(q[k], v[k], tau[k])
        for ours, one in zip((by_q, by_v, inverse), alone, strict=True):
            np.testing.assert_allclose(ours[k], one, rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("backend", ["c", "numpy"])
@pytest.mark.parametrize("count", [3, 100])  # a fixed base's batch over 64: ID, then J^T w
@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
def test_an_empty_wrench_table_reports_as_the_dynamics(tmp_path, backend, count, floating):
    robot = _robot(tmp_path, floating, backend)
    q, v = np.zeros((count, len(robot.coordinates))), np.zeros((count, robot.n))
    if floating:
        q[:, 6] = 1.0
    q[1, -1] = np.nan
    for function in (robot.inverse_dynamics, robot.forward_dynamics):
        with pytest.warns(lagrangian.DynamicsWarning) as record:
            out = function(q, v, v, f_ext={})
        assert len(record) == 1 and record[0].message.count == 1
        assert np.isnan(out[1]).all() and np.isfinite(np.delete(out, 1, axis=0)).all()
        np.testing.assert_allclose(out[0], function(q[0], v[0], v[0]), atol=1e-12)
