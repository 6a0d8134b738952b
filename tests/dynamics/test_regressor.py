"""The torque regressor tau = Y pi: Pinocchio's computeJointTorqueRegressor and parameter order on
the Panda, a minimal identifiable set of Pinocchio's rank, the Panda's base parameters recovered
from noisy torques to the noise level; a model file's regressor in named parameters against its
closed form; bad input refused in one line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import InputError

LOCK = {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}


@pytest.fixture(scope="module")
def panda():
    pin = pytest.importorskip("pinocchio")
    pytest.importorskip("yourdfpy")
    for parent in Path(pin.__file__).resolve().parents:
        path = parent / "share/example-robot-data/robots/panda_description/urdf/panda.urdf"
        if path.is_file():
            model = pin.buildModelFromUrdf(str(path))
            model = pin.buildReducedModel(model, [model.getJointId(j) for j in LOCK],
                                          pin.neutral(model))
            return lagrangian.load(path, lock=LOCK).dynamics(), model, pin
    pytest.skip("example-robot-data is not installed")


def test_panda_regressor_is_pinocchios(panda):
    ours, model, pin = panda
    data = model.createData()
    rng = np.random.default_rng(0)
    q, v, a = rng.uniform(-2, 2, (3, 6, 7))
    Y = ours.regressor(q, v, a)
    assert Y.shape == (6, 7, 70)
    for k in range(6):
        theirs = pin.computeJointTorqueRegressor(model, data, q[k], v[k], a[k])
        np.testing.assert_allclose(Y[k], theirs, rtol=0, atol=1e-10 * np.abs(theirs).max())
        np.testing.assert_allclose(Y[k] @ ours.inertial_parameters(),
                                   pin.rnea(model, data, q[k], v[k], a[k]), atol=1e-10)
    pi = np.concatenate([model.inertias[i].toDynamicParameters()
                         for i in range(1, model.njoints)])
    np.testing.assert_allclose(ours.inertial_parameters(), pi, atol=1e-14)
    assert ours.parameter_names()[:4] == ("m@panda_joint1", "mc_x@panda_joint1",
                                          "mc_y@panda_joint1", "mc_z@panda_joint1")


def test_panda_base_parameters_have_pinocchios_rank_and_reproduce_the_torques(panda):
    ours, model, pin = panda
    data = model.createData()
    rng = np.random.default_rng(1)
    stacked = np.vstack([pin.computeJointTorqueRegressor(model, data, *rng.uniform(-3, 3, (3, 7)))
                         for _ in range(150)])
    singular = np.linalg.svd(stacked, compute_uv=False)
    base = ours.base_parameters()
    assert len(base) == int(np.sum(singular > 1e-9 * singular[0])) == 43
    q, v, a = rng.uniform(-2, 2, (3, 20, 7))
    Y = ours.regressor(q, v, a)
    np.testing.assert_allclose(base.regressor(Y) @ base.values(ours.inertial_parameters()),
                               Y @ ours.inertial_parameters(), atol=1e-9)


def test_panda_identification_recovers_the_base_parameters_to_the_noise_level(panda):
    """Torques with Gaussian noise (0.05 N m) at 400 random states: least squares gives each base
    parameter within 4 of its standard errors, and the torque residual is the noise."""
    ours, _, _ = panda
    base = ours.base_parameters()
    rng = np.random.default_rng(2)
    sigma, count = 0.05, 400
    q = rng.uniform(-2.5, 2.5, (count, 7))
    v, a = rng.uniform(-2, 2, (count, 7)), rng.uniform(-5, 5, (count, 7))
    measured = ours.inverse_dynamics(q, v, a) + rng.normal(0, sigma, (count, 7))
    Yb = base.regressor(ours.regressor(q, v, a)).reshape(-1, len(base))
    estimate = np.linalg.lstsq(Yb, measured.ravel(), rcond=None)[0]
    truth = base.values(ours.inertial_parameters())
    standard_error = sigma * np.sqrt(np.diag(np.linalg.inv(Yb.T @ Yb)))
    assert np.all(np.abs(estimate - truth) < 4 * standard_error)
    residual = np.sqrt(np.mean((Yb @ estimate - measured.ravel()) ** 2))
    assert residual == pytest.approx(sigma, rel=0.1)


def test_model_file_regressor_is_the_pendulums_closed_form():
    """tau = m (L^2 theta_ddot + g L sin theta): Y = L^2 theta_ddot + g L sin theta for [m]."""
    dynamics = lagrangian.load("pendulum").dynamics()
    q, v, a = np.array([[0.3], [1.1]]), np.array([[0.5], [-2.0]]), np.array([[1.2], [0.4]])
    Y = dynamics.regressor(q, v, a, parameters=["m"])
    L, g = 0.5, 9.81
    np.testing.assert_allclose(Y[:, 0, 0], L**2 * a[:, 0] + g * L * np.sin(q[:, 0]), rtol=1e-13)
    double = lagrangian.load("double_pendulum").dynamics()
    rng = np.random.default_rng(3)
    q, v, a = rng.normal(size=(3, 5, 2))
    Y = double.regressor(q, v, a, parameters=["m1", "m2"])
    np.testing.assert_allclose(Y @ double.inertial_parameters(["m1", "m2"]),
                               double.inverse_dynamics(q, v, a), atol=1e-12)
    assert len(double.base_parameters(["m1", "m2"])) == 2


def test_bad_regressor_requests_are_one_line_errors():
    dynamics = lagrangian.load("pendulum").dynamics()
    with pytest.raises(InputError, match="linear in the parameters L") as caught:
        dynamics.regressor([0.1], [0.0], [0.0], parameters=["L"])
    assert caught.value.field == "parameters" and "\n" not in str(caught.value)
    with pytest.raises(InputError, match="'mass' is not a parameter"):
        dynamics.regressor([0.1], [0.0], [0.0], parameters=["mass"])
    with pytest.raises(InputError, match="name the parameters"):
        dynamics.regressor([0.1], [0.0], [0.0])
    with pytest.raises(InputError, match="tolerance"):
        dynamics.base_parameters(["m"], tolerance=2.0)


def test_regressor_command_agrees_with_the_dynamics_command(cli):
    """Y pi from `regressor` is the inverse dynamics `dynamics --a` prints, for the named
    masses of a model file and for a URDF arm's 10 parameters per body."""
    import json

    for model, extra in (("double_pendulum", ["--parameters", "m1,m2"]), ("two_link_arm", [])):
        state = ["--q", "0.3,-0.7", "--v", "1.5,0.2", "--a", "0.4,-2"]
        result = cli("regressor", model, *state, *extra, "--base", "--json")
        assert result.code == 0, result.err
        document = json.loads(result.out)
        Y, pi = np.array(document["regressor"]), np.array(document["values"])
        inverse = json.loads(cli("dynamics", model, *state, "--json").out)["inverse_dynamics"]
        np.testing.assert_allclose(Y @ pi, inverse, atol=1e-12)
        base = document["base"]
        combination = np.array(base["combination"])
        kept = [document["parameters"].index(name) for name in base["names"]]
        np.testing.assert_allclose(Y[:, kept] @ (combination @ pi), inverse, atol=1e-10)


@pytest.mark.parametrize("flags, message", [
    (["pendulum", "--parameters", "L"], "error: --parameters: T, V and the forces must be linear"),
    (["pendulum"], "error: --parameters: name the parameters"),
    (["pendulum", "--parameters", "m", "--base", "--tolerance", "3"],
     "error: --tolerance: the tolerance must lie between 0 and 1"),
    (["pendulum", "--parameters", "m", "--q", "1,2"], "error: --q: expected 1 comma-separated"),
])
def test_regressor_command_refuses_bad_input_in_one_line(cli, flags, message):
    result = cli("regressor", *flags)
    assert result.code == 2
    assert result.err.strip().startswith(message), result.err
    assert len(result.err.strip().splitlines()) == 1
