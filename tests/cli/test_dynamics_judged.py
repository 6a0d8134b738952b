"""The dynamics at one state are judged by the library (api/state_dynamics.py), the command only
prints them (issue 38): closed forms of the pendulum, a state without dynamics named once and
shown as NaN, an overflow refused."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import lagrangian
from lagrangian.api.state_dynamics import state_dynamics
from lagrangian.errors import DerivationError

# A bead on a rod turning about its end, its radius x the coordinate: T = m x^2 x_dot^2 / 2,
# so M = m x^2 vanishes at x = 0, where there is no forward dynamics.
RADIAL = """name = "Radial bead"
[coordinates]
x = { unit = "m", initial = 0.0, rate = 0.5 }
[parameters]
m = { value = 2.0, unit = "kg" }
[energy]
T = "1/2*m*x^2*x_dot^2"
V = "0"
"""


@pytest.fixture(scope="module")
def pendulum():
    return lagrangian.load("pendulum")  # m = 1 kg, L = 0.5 m, g = 9.81 m/s^2


def test_the_pendulum_at_a_state_is_its_closed_form(pendulum):
    """M = m L^2, g(q) = m g L sin(theta), q_ddot = (tau - m g L sin(theta)) / (m L^2),
    T = m L^2 theta_dot^2 / 2, V = -m g L cos(theta)."""
    m, L, g, theta, rate, tau = 1.0, 0.5, 9.81, 0.3, 0.5, 0.2
    found = state_dynamics(pendulum.dynamics(), [theta], [rate], tau=[tau])
    values = found.values
    assert list(values) == ["q", "v", "mass_matrix", "bias_forces", "gravity", "tau",
                            "forward_dynamics", "kinetic_energy", "potential_energy"]
    assert values["mass_matrix"][0][0] == pytest.approx(m * L**2, rel=1e-14)
    assert values["gravity"][0] == pytest.approx(m * g * L * math.sin(theta), rel=1e-14)
    assert values["forward_dynamics"][0] == pytest.approx(
        (tau - m * g * L * math.sin(theta)) / (m * L**2), rel=1e-13)
    assert float(values["kinetic_energy"]) == pytest.approx(m * L**2 * rate**2 / 2, rel=1e-14)
    assert float(values["potential_energy"]) == pytest.approx(-m * g * L * math.cos(theta),
                                                              rel=1e-14)
    assert found.undefined == () and found.warnings == () and found.constraints == ()
    inverse = state_dynamics(pendulum.dynamics(), [theta], [rate], a=[1.5]).values
    assert inverse["inverse_dynamics"][0] == pytest.approx(
        m * L**2 * 1.5 + m * g * L * math.sin(theta), rel=1e-14)


def test_an_overflow_is_refused_by_the_library(pendulum):
    huge = pendulum.with_parameters(m=1e299, L=1e299)  # m L^2 = 1e897
    with pytest.raises(DerivationError, match="mass matrix is not finite"):
        state_dynamics(huge.dynamics(), [0.3], [0.0])


def test_a_state_without_dynamics_is_nan_and_said_once(tmp_path, cli):
    path = tmp_path / "radial.toml"
    path.write_text(RADIAL)
    found = state_dynamics(lagrangian.load(path).dynamics(), [0.0], [0.5], tau=[1.0])
    assert found.undefined == ("forward_dynamics",)
    assert np.isnan(found.values["forward_dynamics"]).all()
    assert found.values["mass_matrix"][0][0] == 0.0  # m x^2 at x = 0
    assert len(found.warnings) == 1 and "no forward dynamics at this state" in found.warnings[0]
    # the command prints what the library found: the line once, null in JSON, exit 0
    result = cli("dynamics", str(path), "--tau", "1", "--json")
    assert result.code == 0
    assert json.loads(result.out)["forward_dynamics"] == [None]
    assert result.err.count("no forward dynamics at this state") == 1
