"""Time dependence is decided by value: a bead on a spinning hoop written in the inertial frame
(a 3D particle at (R sin(theta) cos(Omega t), R sin(theta) sin(Omega t), -R cos(theta))) has the
rotating-frame bead's equilibria, stability and frequencies."""

from __future__ import annotations

import math

import pytest

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.model.reader import parse_model
from variable_models import BEAD_ON_SPINNING_HOOP

# The same bead with t left in T by form only: 1 + sin(2 W t) - 2 sin(W t) cos(W t) = 1.
BY_FORM = """
[coordinates]
theta = { unit = "rad", initial = 0.5, range = [-3.141592653589793, 3.141592653589793] }
[parameters]
m = 0.1
R = 0.5
g = 9.81
Omega = 6.0
[energy]
T = "m*R^2*(theta_dot^2 + Omega^2*sin(theta)^2*(1 + sin(2*Omega*t) - 2*sin(Omega*t)*cos(Omega*t)))/2"
V = "-m*g*R*cos(theta)"
"""


@pytest.mark.parametrize("text", [BEAD_ON_SPINNING_HOOP, BY_FORM], ids=["inertial-3d", "t-by-form"])
def test_same_equilibria_stability_and_frequencies_as_the_rotating_frame(text):
    system = lagrangian.System(parse_model(text))
    reference = lagrangian.load("bead_on_hoop")
    tilt = math.acos(9.81 / (6.0**2 * 0.5))
    found = [(e.coordinates["theta"], e.stable) for e in system.equilibria()]
    assert [th for th, _ in found] == pytest.approx([-tilt, 0.0, tilt, math.pi], abs=1e-9)
    assert [s for _, s in found] == [True, False, True, False]
    ours = [mode.frequency for mode in system.modes({"theta": tilt}).modes]
    theirs = [mode.frequency for mode in reference.modes({"theta": tilt}).modes]
    assert ours == pytest.approx(theirs, rel=1e-12)
    # small oscillations about the tilted equilibrium: omega^2 = Omega^2 sin^2(theta0)
    assert ours[0] == pytest.approx(6.0 * math.sin(tilt), rel=1e-9)


def test_a_truly_time_dependent_model_is_still_refused():
    with pytest.raises(ModelError, match="the equations at rest depend on time t explicitly"):
        lagrangian.load("support_pendulum").equilibria()
