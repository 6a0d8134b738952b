"""A robot's CasADi functions from its kinematic tree (the numpy reference's recursions over
casadi SX): M, the bias forces and the forward dynamics agree with our recursive dynamics (a
variant too: mimic fingers, a lock, a payload, tilted gravity, a floating base) and, for an
MJCF robot, with MuJoCo; and a URDF arm's trajectory optimised on them replays in simulate."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pytest

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.model.urdf import example_urdf

MJCF = """
<mujoco model="arm">
  <option gravity="0 0 -9.81"/>
  <worldbody>
    <body name="a" pos="0 0 0.5" euler="10 20 30">
      <joint name="j1" axis="0 0 1" pos="0.01 0.02 0.03"/>
      <inertial pos="0.1 0 0" mass="2" fullinertia="0.2 0.25 0.3 0.01 0.02 0.03"/>
      <body name="b" pos="0.2 0 0" quat="0.9 0.1 0.2 0.3">
        <joint name="s" type="slide" axis="1 0 0"/>
        <joint name="j2" axis="0 1 1" pos="0.1 0 0"/>
        <geom type="capsule" fromto="0 0 0 0.4 0.1 0" size="0.05"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.fixture(scope="module")
def arm():
    return lagrangian.load("two_link_arm")


def random_states(n, count=3, seed=2):
    rng = np.random.default_rng(seed)
    return [(rng.uniform(-1, 1, n), rng.uniform(-2, 2, n)) for _ in range(count)]


@pytest.mark.parametrize("name", ["two_link_arm", "ur5"])
def test_tree_functions_equal_our_recursive_dynamics(name, arm):
    path = lagrangian.model.urdf.example_urdf(name) if name != "two_link_arm" else name
    if path is None:
        pytest.skip(f"{name}: example-robot-data is not installed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        system = arm if name == "two_link_arm" else lagrangian.load(path)
    first = system.model.coordinates[0].name
    functions = system.to_casadi(inputs=[first])
    dynamics = system.dynamics(backend="numpy")
    n = len(system.coordinates)
    for q, v in random_states(n):
        M = dynamics.mass_matrix(q)
        assert np.allclose(np.asarray(functions.mass_matrix(q)), M, rtol=0, atol=1e-12)
        assert np.allclose(-np.asarray(functions.forcing(q, v, [0.0])).ravel(),
                           dynamics.bias_forces(q, v), rtol=0, atol=1e-11)
        tau = np.zeros(n)
        tau[0] = 1.5
        accelerations = np.asarray(functions.rhs(np.r_[q, v], [1.5])).ravel()[n:]
        assert np.allclose(accelerations, dynamics.forward_dynamics(q, v, tau), rtol=1e-10,
                           atol=1e-10)


def test_an_mjcf_robot_in_casadi_agrees_with_mujoco(tmp_path):
    path = tmp_path / "arm.xml"
    path.write_text(MJCF)
    functions = lagrangian.load(path).to_casadi(inputs=["j1", "s", "j2"])
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    for q, v in random_states(3):
        data.qpos[:], data.qvel[:] = q, v
        mujoco.mj_forward(model, data)
        M = np.zeros((3, 3))
        mujoco.mj_fullM(model, data, M)
        assert np.allclose(np.asarray(functions.mass_matrix(q)), M, rtol=0, atol=1e-9)
        assert np.allclose(-np.asarray(functions.forcing(q, v, [0, 0, 0])).ravel(),
                           data.qfrc_bias, rtol=0, atol=1e-9)
        assert np.allclose(np.asarray(functions.rhs(np.r_[q, v], [0, 0, 0])).ravel()[3:],
                           data.qacc, rtol=0, atol=1e-9)


def test_a_urdf_arm_optimised_and_replayed(arm):
    """Rest to rest in 1 s from the horizontal, the actuators' torques (tau_<joint>) within
    60 N m, the joints within their position limits (bounds of their own: the least effort
    folds the elbow to its limit, -3.1 rad, which eases the shoulder's load)."""
    result = lagrangian.optimize(arm, ["tau_shoulder", "tau_elbow"], 1.0, 25,
                                 method="hermite-simpson",
                                 start={"shoulder": 0, "elbow": 0, "shoulder_dot": 0,
                                        "elbow_dot": 0},
                                 goal={"shoulder": 0.5, "elbow": -0.3, "shoulder_dot": 0,
                                       "elbow_dot": 0},
                                 bounds={"tau_shoulder": (-60, 60), "tau_elbow": (-60, 60)})
    assert result.states["elbow"].min() >= -3.1 - 1e-6
    assert result.converged and result.defects["final_state"] < 1e-9
    run = arm.simulate(1.0, initial=result.initial_state(), controller=result.controller(),
                       samples=25, rtol=1e-10, atol=1e-10, limits=False)
    assert np.abs(run.q[:, 0] - result.states["shoulder"]).max() <= result.defects["replay"]
    with pytest.raises(ModelError, match="not a coordinate or actuator"):
        arm.to_casadi(inputs=["wrist"])


def test_a_robot_variant_equals_our_engine():
    """The Panda on a floating base, its fingers mimic, a wrist joint locked, a 1.5 kg payload
    and gravity tilted: the tree's numbers, so CasADi's M, bias and forward dynamics equal the
    compiled engine's (itself Pinocchio's: tests/dynamics)."""
    if example_urdf("panda") is None:
        pytest.skip("panda: example-robot-data is not installed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        system = lagrangian.load("panda", lock={"panda_joint7": 0.3}, floating_base=True,
                                 payload={"panda_hand": (1.5, (0.0, 0.02, 0.1))},
                                 gravity=(1.0, -2.0, -9.5))
    functions = system.to_casadi(inputs=["tau_panda_joint2"])
    dynamics = system.dynamics()
    nq, nv = dynamics.nq, dynamics.nv
    assert functions.configuration == tuple(dynamics.coordinates)
    rng = np.random.default_rng(5)
    for _ in range(2):
        q = np.r_[rng.normal(size=3), rng.normal(size=4), rng.uniform(-1, 1, nq - 7)]
        q[3:7] /= np.linalg.norm(q[3:7])
        v = rng.uniform(-1, 1, nv)
        tau = np.zeros(nv)
        tau[6 + list(dynamics.velocity_names[6:]).index("panda_joint2")] = 2.0
        assert np.allclose(np.asarray(functions.mass_matrix(q)), dynamics.mass_matrix(q),
                           rtol=0, atol=1e-9)
        assert np.allclose(-np.asarray(functions.forcing(q, v, [0.0])).ravel(),
                           dynamics.bias_forces(q, v), rtol=0, atol=1e-9)
        x_dot = np.asarray(functions.rhs(np.r_[q, v], [2.0])).ravel()
        assert np.allclose(x_dot[nq:], dynamics.forward_dynamics(q, v, tau), rtol=0, atol=1e-8)
