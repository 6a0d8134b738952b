"""A floating-base robot's CasADi functions (the free flyer at the root of the tree, Pinocchio's
layout): M, the bias forces and the forward dynamics of Solo12 against our compiled engine, the
state's rate against simulate's, and an MJCF robot's against MuJoCo through the layouts' change
of variables (model/mjcf_state.py)."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pytest

import lagrangian
from lagrangian.dynamics.tree.free_flyer import BASE_CONFIGURATION, BASE_VELOCITY
from lagrangian.model.mjcf_state import mujoco_layout
from lagrangian.model.urdf import example_urdf
from lagrangian.simulation.floating import configuration_rate
from mjcf_models import leg

LEG = leg()


def random_state(nq: int, nv: int, rng):
    quaternion = rng.normal(size=4)
    q = np.r_[rng.normal(size=3), quaternion / np.linalg.norm(quaternion),
              rng.uniform(-1, 1, nq - 7)]
    return q, rng.normal(size=nv)


@pytest.fixture(scope="module")
def solo():
    if example_urdf("solo12") is None:
        pytest.skip("example-robot-data is not installed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        system = lagrangian.load("solo12", floating_base=True)
    return system, system.to_casadi(inputs=["FL_KFE", "tau_HR_HFE"])


def test_solo12_on_a_floating_base_equals_our_engine(solo):
    system, functions = solo
    dynamics = system.dynamics()  # the compiled engine
    assert (dynamics.nq, dynamics.nv) == (19, 18)
    # the names simulate(initial=...) takes: the base's numbers, the joints and their rates
    assert functions.configuration == tuple(dynamics.coordinates)
    assert functions.velocities == tuple(dynamics.velocity_names[:6]) + tuple(
        f"{name}_dot" for name in dynamics.velocity_names[6:])
    assert functions.configuration[:7] == BASE_CONFIGURATION
    assert functions.velocities[:6] == BASE_VELOCITY
    coordinates = [c.name for c in system.model.coordinates]
    rng = np.random.default_rng(1)
    for _ in range(3):
        q, v = random_state(19, 18, rng)
        u = rng.normal(size=2)
        tau = np.zeros(18)
        tau[6 + coordinates.index("FL_KFE")] = u[0]
        tau[6 + coordinates.index("HR_HFE")] = u[1]
        assert np.allclose(np.asarray(functions.mass_matrix(q)), dynamics.mass_matrix(q),
                           rtol=0, atol=1e-9)
        assert np.allclose(np.asarray(functions.forcing(q, v, u)).ravel(),
                           tau - dynamics.bias_forces(q, v), rtol=0, atol=1e-9)
        x_dot = np.asarray(functions.rhs(np.r_[q, v], u)).ravel()
        assert np.allclose(x_dot[19:], dynamics.forward_dynamics(q, v, tau), rtol=0,
                           atol=1e-9)
        assert np.allclose(x_dot[:19], configuration_rate(q, v), rtol=0, atol=1e-12)


def test_the_base_rotation_is_that_of_the_normalised_quaternion(solo):
    """R(q / |q|): a quaternion scaled by 2 gives the same M (collocation may leave |q| off 1
    by the scheme's error)."""
    _, functions = solo
    q, _ = random_state(19, 18, np.random.default_rng(2))
    scaled = q.copy()
    scaled[3:7] *= 2
    assert np.allclose(np.asarray(functions.mass_matrix(scaled)),
                       np.asarray(functions.mass_matrix(q)), rtol=0, atol=1e-12)


def test_an_mjcf_floating_leg_in_casadi_agrees_with_mujoco(tmp_path):
    """MuJoCo's M and bias carried to our layout, M = G^T M_mj G, b = G^T (M_mj G' v + b_mj)
    (tests/model/test_mjcf_state.py), and mj_forward's qacc converted to ours."""
    path = tmp_path / "leg.xml"
    path.write_text(LEG)
    system = lagrangian.load(path, floating_base=True)
    functions = system.to_casadi(inputs=["hip", "knee"])
    layout = mujoco_layout(system)
    model = mujoco.MjModel.from_xml_path(str(path))
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, v = random_state(9, 8, rng)
        u = rng.normal(size=2)
        qpos, qvel = layout.to_mujoco(q, v)
        data = mujoco.MjData(model)
        data.qpos[:], data.qvel[:] = qpos, qvel
        data.qfrc_applied[:] = layout.force_to_mujoco(q, np.r_[np.zeros(6), u])
        mujoco.mj_forward(model, data)
        M_mj = np.zeros((8, 8))
        mujoco.mj_fullM(model, data, M_mj)
        G = np.eye(8)
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, qpos[3:7])
        G[:3, :3] = R.reshape(3, 3)
        assert np.allclose(np.asarray(functions.mass_matrix(q)), G.T @ M_mj @ G, rtol=0,
                           atol=1e-9)
        _, _, a = layout.from_mujoco(qpos, qvel, data.qacc)
        x_dot = np.asarray(functions.rhs(np.r_[q, v], u)).ravel()
        assert np.allclose(x_dot[9:], a, rtol=0, atol=1e-9)
