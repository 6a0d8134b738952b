"""docs/bridges.md's ball-joint simulate block runs, and its run is the physics: a spherical
pendulum (2 kg, 0.5 m below the pivot, 0.01 kg m^2 about its centre) keeps T + V and its
angular momentum about the vertical through the pivot, each quaternion unit."""

from __future__ import annotations

import re

import numpy as np

from docs_blocks import block

J_PIVOT = np.diag([0.01 + 2 * 0.5**2, 0.01 + 2 * 0.5**2, 0.01])  # kg m^2, parallel axes


def _rotation(q):
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def test_the_ball_simulate_block_keeps_the_pendulums_invariants(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (code,) = re.findall(r"```python\n(.*?)```", block("bridges-ball-simulate", "bridges.md"),
                         re.S)
    namespace: dict = {}
    exec(code, namespace)  # noqa: S102 - our own documentation
    run = namespace["run"]
    assert run.status == "finished" and len(run.t) == 301
    np.testing.assert_allclose(np.linalg.norm(run.q, axis=1), 1.0, rtol=0, atol=1e-14)
    R = np.array([_rotation(q) for q in run.q])
    height = 1.0 + R[:, 2, 2] * -0.5  # the centre, 0.5 m along the bob's -z from the pivot
    energy = 0.5 * np.einsum("ki,ij,kj->k", run.q_dot, J_PIVOT, run.q_dot) + 2 * 9.81 * height
    momentum = np.einsum("kij,jl,kl->ki", R, J_PIVOT, run.q_dot)[:, 2]
    np.testing.assert_allclose(energy, energy[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(momentum, momentum[0], rtol=0, atol=1e-9)
    assert np.ptp(R[:, 2, 2]) > 0.01  # it nutates: not a steady cone
