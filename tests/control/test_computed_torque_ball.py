"""Computed torque on a robot with ball joints (MJCF: ball, hinge, ball): the error taken on the
manifold, e = q_d (-) q. Started at rest a turn e0 away from the target along a geodesic, the
error stays on that geodesic and follows the critically damped closed form e0 (1 + w t)
exp(-w t) (Kp = w^2, Kd = 2 w), for a small turn and a large one alike; from a start moving
off that line it still settles on the target."""

from __future__ import annotations

import json

import numpy as np
import pytest

import lagrangian
from mjcf_models import BALL_HINGE_BALL

CHAIN = BALL_HINGE_BALL
W = 5.0  # rad/s: Kp = W^2, Kd = 2 W


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    path = tmp_path_factory.mktemp("ball_ct") / "arm.xml"
    path.write_text(CHAIN)
    system = lagrangian.load(path)
    dynamics = system.dynamics()
    rest = np.r_[1.0, 0, 0, 0, 0.0, 1.0, 0, 0, 0]
    target = dynamics.integrate(rest, np.r_[0.3, -0.2, 0.5, 0.4, -0.1, 0.2, 0.3])
    return path, system, dynamics, target


@pytest.mark.parametrize("scale", [1e-2, 1.0])
def test_the_error_on_the_manifold_follows_the_critically_damped_closed_form(arm, scale):
    _, system, dynamics, target = arm
    law = lagrangian.computed_torque(system, target, W * W, 2 * W)
    assert law.manifold and law.coordinates == dynamics.velocity_names
    np.testing.assert_allclose(np.sort(law.error_eigenvalues.real), -W, atol=1e-6)
    start = dynamics.integrate(target, scale * np.array([1.0, -2.0, 0.5, 1.0, 2.0, -1.0, 1.0]))
    run = system.simulate(2.0, initial=dict(zip(dynamics.coordinates, start, strict=True)),
                          controller=law, rtol=1e-11, atol=1e-12, samples=201)
    t, q = np.asarray(run.t), np.asarray(run.q)
    error = dynamics.difference(q, target)
    expected = error[0] * ((1 + W * t) * np.exp(-W * t))[:, None]
    assert np.abs(error - expected).max() <= 1e-8 * np.abs(error[0]).max()
    for first in (0, 5):  # each ball's quaternion stays unit with no renormalization
        np.testing.assert_allclose(np.linalg.norm(q[:, first:first + 4], axis=1), 1.0, atol=1e-14)


def test_a_start_moving_off_the_geodesic_settles_on_the_target(arm):
    _, system, dynamics, target = arm
    law = lagrangian.computed_torque(system, target, W * W, 2 * W)
    start = dict(zip(dynamics.coordinates, dynamics.integrate(target, np.full(7, 0.5)),
                     strict=True))
    start.update(shoulder_wz=3.0, elbow_dot=-2.0, wrist_wx=4.0)
    run = system.simulate(6.0, initial=start, controller=law, rtol=1e-10, atol=1e-12)
    final = np.asarray(run.q)[-1]
    assert np.abs(dynamics.difference(final, target)).max() < 1e-8


def test_the_command_line_holds_a_ball_at_its_target(arm, cli):
    path, _, dynamics, _ = arm
    result = cli("simulate", str(path), "--t-end", "3", "--control", "computed-torque",
                 "--about", "shoulder_qw=0.8,shoulder_qx=0.6", "--about", "elbow=0.5", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    final = document["final_state"]
    reached = np.array([final[name] for name in dynamics.coordinates])
    target = np.r_[0.8, 0.6, 0, 0, 0.5, 1.0, 0, 0, 0]
    assert np.abs(dynamics.difference(reached, target)).max() < 1e-8  # (1 + 30) e^-30
    assert document["control"]["coordinates"] == list(dynamics.velocity_names)
    bad = cli("simulate", str(path), "--t-end", "1", "--control", "computed-torque",
              "--about", "shoulder_qw=0.8,shoulder_qx=0.7")
    assert bad.code == 2 and len(bad.err.strip().splitlines()) == 1 and "shoulder" in bad.err
    # LQR about the hanging rest by the elbow alone: the ball's turn about the vertical is a
    # zero mode that the elbow cannot move (tests/control/test_lqr_ball.py balances a ball)
    lqr = cli("simulate", str(path), "--t-end", "1", "--control", "lqr", "--inputs", "elbow")
    assert lqr.code == 2 and "not stabilizable" in lqr.err
