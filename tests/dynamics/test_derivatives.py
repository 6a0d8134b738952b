"""Derivatives of inverse and forward dynamics: Pinocchio's computeRNEADerivatives and
computeABADerivatives on the Panda and a spatial arm with a prismatic joint, a model file's
against the pendulum's closed form and central differences of our own dynamics."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from robot_data import robots as _robots

LOCK = {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}


def _symmetric(matrix):
    return np.triu(matrix) + np.triu(matrix, 1).T




def _against_pinocchio(ours, model, pin, seed):
    data = model.createData()
    n = model.nq
    rng = np.random.default_rng(seed)
    q = rng.uniform(np.maximum(model.lowerPositionLimit, -2),
                    np.minimum(model.upperPositionLimit, 2), (5, n))
    v, a, tau = rng.uniform(-2, 2, (3, 5, n))
    dq, dv = ours.inverse_dynamics_derivatives(q, v, a)
    fq, fv, ftau = ours.forward_dynamics_derivatives(q, v, tau)
    for k in range(5):
        pq, pv, _ = pin.computeRNEADerivatives(model, data, q[k], v[k], a[k])
        np.testing.assert_allclose(dq[k], pq, rtol=0, atol=1e-10)
        np.testing.assert_allclose(dv[k], pv, rtol=0, atol=1e-10)
        pin.computeABADerivatives(model, data, q[k], v[k], tau[k])
        np.testing.assert_allclose(fq[k], data.ddq_dq, rtol=0, atol=1e-10)
        np.testing.assert_allclose(fv[k], data.ddq_dv, rtol=0, atol=1e-10)
        np.testing.assert_allclose(ftau[k], _symmetric(data.Minv), rtol=0, atol=1e-10)


def test_panda_derivatives_are_pinocchios():
    pin = pytest.importorskip("pinocchio")
    pytest.importorskip("yourdfpy")
    path = _robots(pin) / "panda_description/urdf/panda.urdf"
    model = pin.buildModelFromUrdf(str(path))
    model = pin.buildReducedModel(model, [model.getJointId(j) for j in LOCK], pin.neutral(model))
    _against_pinocchio(lagrangian.load(path, lock=LOCK).dynamics(), model, pin, 0)


def test_spatial_arm_derivatives_are_pinocchios(tmp_path):
    """Revolute and prismatic joints, rpy origins, a tilted axis, full inertia tensors."""
    pin = pytest.importorskip("pinocchio")
    pytest.importorskip("yourdfpy")
    from test_dynamics_pinocchio import ARM

    path = tmp_path / "spatial.urdf"
    path.write_text(ARM)
    _against_pinocchio(lagrangian.load(path).dynamics(backend="numpy"),
                       pin.buildModelFromUrdf(str(path)), pin, 1)


def test_pendulum_derivatives_are_the_closed_form():
    """tau = m L^2 a + m g L sin q: d tau/dq = m g L cos q, d tau/dq_dot = 0; forward:
    d q_ddot/dq = -g cos q / L, d q_ddot/d tau = 1/(m L^2)."""
    dynamics = lagrangian.load("pendulum").dynamics()
    m, L, g = 1.0, 0.5, 9.81
    q, v = np.array([[0.3], [2.0]]), np.array([[0.5], [-1.0]])
    dq, dv = dynamics.inverse_dynamics_derivatives(q, v, [[1.0], [0.0]])
    np.testing.assert_allclose(dq[:, 0, 0], m * g * L * np.cos(q[:, 0]), rtol=1e-13)
    np.testing.assert_allclose(dv, 0.0, atol=1e-15)
    fq, fv, ftau = dynamics.forward_dynamics_derivatives(q, v, [[0.2], [0.0]])
    np.testing.assert_allclose(fq[:, 0, 0], -g * np.cos(q[:, 0]) / L, rtol=1e-13)
    np.testing.assert_allclose(ftau[:, 0, 0], 1 / (m * L**2), rtol=1e-13)


def test_model_file_derivatives_agree_with_central_differences_of_our_dynamics():
    """The double pendulum (velocity terms, coupled M) and a damped oscillator."""
    for example in ("double_pendulum", "damped_oscillator"):
        dynamics = lagrangian.load(example).dynamics()
        n = dynamics.n
        rng = np.random.default_rng(4)
        q, v, a = rng.normal(size=(3, n))
        dq, dv = dynamics.inverse_dynamics_derivatives(q, v, a)
        fq, fv, _ = dynamics.forward_dynamics_derivatives(q, v, a)
        h = 1e-6
        for k in range(n):
            e = h * np.eye(n)[k]
            central = (dynamics.inverse_dynamics(q + e, v, a)
                       - dynamics.inverse_dynamics(q - e, v, a)) / (2 * h)
            np.testing.assert_allclose(dq[:, k], central, atol=1e-7)
            central = (dynamics.inverse_dynamics(q, v + e, a)
                       - dynamics.inverse_dynamics(q, v - e, a)) / (2 * h)
            np.testing.assert_allclose(dv[:, k], central, atol=1e-7)
            central = (dynamics.forward_dynamics(q + e, v, a)
                       - dynamics.forward_dynamics(q - e, v, a)) / (2 * h)
            np.testing.assert_allclose(fq[:, k], central, atol=1e-6)
            central = (dynamics.forward_dynamics(q, v + e, a)
                       - dynamics.forward_dynamics(q, v - e, a)) / (2 * h)
            np.testing.assert_allclose(fv[:, k], central, atol=1e-6)


def test_derivatives_refuse_bad_shapes_in_one_line():
    dynamics = lagrangian.load("double_pendulum").dynamics()
    with pytest.raises(lagrangian.InputError, match="expected 2 values") as caught:
        dynamics.inverse_dynamics_derivatives([0.1, 0.2, 0.3], [0, 0], [0, 0])
    assert caught.value.field == "q" and "\n" not in str(caught.value)
    with pytest.raises(lagrangian.InputError, match="expected 2 values"):
        dynamics.forward_dynamics_derivatives([0.1, 0.2], [0, 0], [0])


def test_dynamics_command_prints_the_derivatives(cli):
    """`dynamics --derivatives --json`: the pendulum's d tau/dq = m g L cos q and
    d q_ddot/d tau = 1/(m L^2); without --a or --tau, one line."""
    import json

    result = cli("dynamics", "pendulum", "--q", "0.4", "--v", "1", "--a", "2", "--derivatives",
                 "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["dtau_dq"][0][0] == pytest.approx(9.81 * 0.5 * np.cos(0.4), rel=1e-13)
    assert document["dtau_dv"] == [[0.0]]
    forward = json.loads(cli("dynamics", "pendulum", "--q", "0.4", "--tau", "1",
                             "--derivatives", "--json").out)
    assert forward["dqdd_dtau"][0][0] == pytest.approx(4.0, rel=1e-13)
    assert forward["dqdd_dq"][0][0] == pytest.approx(-9.81 / 0.5 * np.cos(0.4), rel=1e-13)
    bad = cli("dynamics", "pendulum", "--derivatives")
    assert bad.code == 2 and bad.err.strip() == (
        "error: --derivatives: needs --a (inverse dynamics) or --tau (forward dynamics) to "
        "differentiate")
