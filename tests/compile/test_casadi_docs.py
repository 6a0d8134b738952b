"""docs/bridges.md's floating-base and time block runs, and what it prints is the physics:
Solo12's M[0, 0] is its whole mass, and the shaken pendulum's theta_ddot at t = 0 is the
closed form -(g/L) sin(theta) - x_s''(0) cos(theta) / L with x_s'' = -A Omega^2 cos(Omega t)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from docs_blocks import block
from lagrangian.model.urdf import example_urdf


def test_the_floating_and_time_block(capsys):
    if example_urdf("solo12") is None:
        pytest.skip("example-robot-data is not installed")
    (code,) = re.findall(r"```python\n(.*?)```", block("bridges-floating-casadi", "bridges.md"),
                         re.S)
    namespace: dict = {}
    exec(code, namespace)  # noqa: S102 - our own documentation
    solo = namespace["solo"]
    links = solo.model.kinematic_tree.links
    assert namespace["M"][0, 0] == pytest.approx(sum(link.mass for link in links), rel=1e-12)
    assert namespace["M"].shape == (18, 18)
    g, L, A, Omega, theta = 9.81, 0.5, 0.02, 5.0, 0.1
    x_ddot = np.asarray(namespace["shaken"].rhs([theta, 0], [0], 0.0)).ravel()
    assert x_ddot[1] == pytest.approx(-g / L * np.sin(theta) + A * Omega ** 2 * np.cos(theta) / L,
                                      rel=1e-12)
    assert "base_qw" in capsys.readouterr().out


def test_the_ball_joint_block(tmp_path, monkeypatch, capsys):
    """The spherical pendulum (m = 2 kg, L = 0.5 m, I = 0.01 kg m^2 about its centre) tilted by
    0.3 rad at rest: w_x' = -m g L sin(tilt) / (I + m L^2); a moment u about its own z turns it
    at w_z' = u / I; the quaternion still at rest."""
    monkeypatch.chdir(tmp_path)
    (code,) = re.findall(r"```python\n(.*?)```", block("bridges-ball-casadi", "bridges.md"),
                         re.S)
    namespace: dict = {}
    exec(code, namespace)  # noqa: S102 - our own documentation
    m, g, L, I, tilt = 2.0, 9.81, 0.5, 0.01, 0.3
    x_dot = namespace["x_dot"]
    assert x_dot[4] == pytest.approx(-m * g * L * np.sin(tilt) / (I + m * L ** 2), rel=1e-12)
    assert np.abs(np.r_[x_dot[:4], x_dot[5:]]).max() < 1e-12
    state = [np.cos(tilt / 2), np.sin(tilt / 2), 0, 0, 0, 0, 0]
    pushed = np.asarray(namespace["f"].rhs(state, [1.5])).ravel()
    assert pushed[6] == pytest.approx(1.5 / I, rel=1e-12)
    assert "pivot_wz" in capsys.readouterr().out
