"""Every URDF of example-robot-data that Pinocchio loads (fixed base, buildModelFromUrdf without
a free flyer), we load: M and the bias C q_dot + g agree with Pinocchio's crba and rnea at a
random state to 1e-12 (relative to the robot's largest entry), or the file is refused with one
line a robotics user can act on. Continuous joints are (cos, sin) pairs in Pinocchio, and it
reads a mimic joint as a joint of its own: both are mapped onto our coordinates (theta = k q +
offset), M = K^T M_pin K and b = K^T rnea(q_pin, K q_dot, 0). Skipped without the data."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import lagrangian

pin = pytest.importorskip("pinocchio")
pytest.importorskip("yourdfpy")

# Refusals we expect, with what the message must tell the user (the fix or the fault).
REFUSED = {
    "alex_psyonic_hands.urdf": r"joint 'Left_index_q2'\.mimic: mimics no joint 'index_q1'; did "
                               r"you mean 'Left_index_q1'",
    "quadrotor_base.urdf": r"no joint left to move",
    "iris_simple.urdf": r"no joint left to move",
    "romeo.urdf": r"URDF joints 'LHand', 'RHand' move no mass.*--lock LHand=0 --lock RHand=0",
    "romeo_laas_small.urdf": r"link 'LHipPitch_link'\.inertial: the inertia tensor is not "
                             r"positive semidefinite",
    "ur3.urdf": r"the <robot> holds no <link>: an empty robot",
}
# Loaded with a warning: an unphysical inertia on a link fixed to the root changes nothing.
WARNED = {"tiago.urdf", "tiago_dual.urdf", "tiago_no_hand.urdf"}


def _robot_files() -> list[Path]:
    for parent in Path(pin.__file__).resolve().parents:
        candidate = parent / "share/example-robot-data/robots"
        if candidate.is_dir():
            return sorted(candidate.glob("**/*.urdf"))
    return []


def _pinocchio_coordinates(model, ours, q, v):
    """Pinocchio's q and v for our q and q_dot, and K with v_pin = K q_dot."""
    joints = {j.name: j for j in ours.tree.joints}
    q_pin, v_pin = pin.neutral(model), np.zeros(model.nv)
    K = np.zeros((model.nv, ours.n))
    for index in range(1, model.njoints):
        name, joint = model.names[index], model.joints[index]
        ours_joint = joints[name]
        theta = ours_joint.multiplier * q[ours_joint.coordinate] + ours_joint.offset
        if joint.nq == 2:  # a continuous joint: (cos, sin)
            q_pin[joint.idx_q:joint.idx_q + 2] = np.cos(theta), np.sin(theta)
        else:
            q_pin[joint.idx_q] = theta
        K[joint.idx_v, ours_joint.coordinate] += ours_joint.multiplier
        v_pin[joint.idx_v] = ours_joint.multiplier * v[ours_joint.coordinate]
    return q_pin, v_pin, K


@pytest.mark.slow
def test_every_example_robot_loads_and_agrees_with_pinocchio_or_is_refused_in_one_line():
    files = _robot_files()
    if not files:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data)")
    assert len(files) >= 60
    agreed, refused = [], []
    for path in files:
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always", lagrangian.ModelWarning)
            try:
                ours = lagrangian.load(path).dynamics(backend="numpy")
            except lagrangian.LagrangianError as exc:
                message = str(exc)
                assert path.name in REFUSED, f"{path.name} refused: {message}"
                assert re.search(REFUSED[path.name], message), message
                assert "\n" not in message and "Error:" not in message, message
                refused.append(path.name)
                continue
        assert path.name not in REFUSED, f"{path.name} loads now: take it off REFUSED"
        notes = [str(w.message) for w in seen if issubclass(w.category, lagrangian.ModelWarning)]
        assert bool(notes) == (path.name in WARNED), (path.name, notes)
        assert all("fixed to the root" in note for note in notes)
        try:
            model = pin.buildModelFromUrdf(str(path))
        except (RuntimeError, ValueError):
            continue  # Pinocchio refuses it: nothing to agree with
        data = model.createData()
        rng = np.random.default_rng(len(path.name))
        q, v = rng.uniform(-1, 1, ours.n), rng.uniform(-1, 1, ours.n)
        q_pin, v_pin, K = _pinocchio_coordinates(model, ours, q, v)
        mass = pin.crba(model, data, q_pin).copy()
        mass = np.triu(mass) + np.triu(mass, 1).T
        expected_mass = K.T @ mass @ K
        expected_bias = K.T @ pin.rnea(model, data, q_pin, v_pin, np.zeros(model.nv))
        scale = max(1.0, float(np.abs(expected_mass).max()), float(np.abs(expected_bias).max()))
        np.testing.assert_allclose(ours.mass_matrix(q), expected_mass, rtol=0,
                                   atol=1e-12 * scale, err_msg=path.name)
        np.testing.assert_allclose(ours.bias_forces(q, v), expected_bias, rtol=0,
                                   atol=1e-12 * scale, err_msg=path.name)
        agreed.append(path.name)
    print(f"{len(agreed)} robots agree with Pinocchio, {len(refused)} refused: {refused}")
    assert set(refused) == set(REFUSED)
    assert len(agreed) >= 60
