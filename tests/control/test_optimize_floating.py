"""optimize on a floating base: a free-falling two-joint leg (a 5 kg trunk, nothing holding it)
moves its joints rest to rest by its joint torques alone. Whatever the joints do, its centre
of mass falls as g t^2 / 2 and its angular momentum about the centre of mass stays 0 (it starts
at rest): checked on the collocated states by our own dynamics (centre_of_mass, A_g), and the
torques replayed by simulate follow the trajectory."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import InputError
from mjcf_models import leg

LEG = leg()
GOAL = {"hip": 1.0, "knee": -0.8, "hip_dot": 0.0, "knee_dot": 0.0}


@pytest.fixture(scope="module")
def leg(tmp_path_factory):
    path = tmp_path_factory.mktemp("floating") / "leg.xml"
    path.write_text(LEG)
    system = lagrangian.load(path, floating_base=True)
    result = lagrangian.optimize(system, ["hip", "knee"], 0.5, 20, method="hermite-simpson",
                                 goal=GOAL)
    return system, result


def test_the_falling_leg_reaches_its_goal_and_falls_as_a_free_body(leg):
    system, result = leg
    assert result.converged and result.defects["final_state"] < 1e-9
    assert list(result.states)[:7] == ["base_x", "base_y", "base_z", "base_qx", "base_qy",
                                       "base_qz", "base_qw"]
    dynamics = system.dynamics(backend="numpy")
    X = np.column_stack(list(result.states.values()))
    q, v = X[:, :9], X[:, 9:]
    com = np.array([dynamics.center_of_mass(row) for row in q])
    falling = com[0] + np.outer(result.t ** 2, [0.0, 0.0, -9.81 / 2])
    assert np.abs(com - falling).max() < 1e-5  # the scheme's error (replay ~3e-5)
    # the trunk turns (the joints swing against it) while the angular momentum stays 0
    momentum = np.array([dynamics.centroidal_momentum_matrix(a) @ b for a, b in zip(q, v,
                                                                                   strict=True)])
    mass = float(dynamics.mass_matrix(q[0])[0, 0])
    assert np.abs(momentum[:, :2]).max() < 1e-5
    assert np.allclose(momentum[:, 2], -mass * 9.81 * result.t, rtol=0, atol=1e-4)
    assert np.abs(momentum[:, 3:]).max() < 1e-5
    assert np.abs(q[-1, 3:6]).max() > 0.05  # the trunk has turned
    assert np.abs(np.linalg.norm(q[:, 3:7], axis=1) - 1).max() < 1e-6


def test_the_torques_replayed_by_simulate_follow_the_trajectory(leg):
    system, result = leg
    run = system.simulate(0.5, initial=result.initial_state(), controller=result.controller(),
                          samples=20, rtol=1e-10, atol=1e-10)
    assert run.completed
    for k, name in enumerate(run.coordinates):
        assert np.abs(run.q[:, k] - result.states[name]).max() <= result.defects["replay"]


def test_a_floating_start_or_goal_needs_a_unit_quaternion(leg):
    system, _ = leg
    with pytest.raises(InputError, match="base quaternion .* norm 2"):
        lagrangian.optimize(system, ["hip"], 0.5, 5, start={"base_qw": 2.0})
    with pytest.raises(InputError, match="base quaternion .* norm 0.5"):
        lagrangian.optimize(system, ["hip"], 0.5, 5, goal={"base_qx": 0, "base_qy": 0,
                                                          "base_qz": 0, "base_qw": 0.5})
