"""Equilibria and modes of a robot with a ball joint, in the model's Euler angles (what derive
shows: R = Rx Ry Rz) over the tree's recursions (M_theta = E^T M E, g_theta = E^T g): a body
hanging from a ball joint swings about its two horizontal principal axes at the compound
pendulum's closed form omega^2 = m g d / (I + m d^2), turns freely about the vertical (a
zero-frequency mode), and every rest found has its centre of mass on the vertical through the
pivot, stable below and unstable above."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from mjcf_models import BALL_HINGE_BALL

M, D, G = 2.0, 0.4, 9.81
I_CENTRE = (0.05, 0.08, 0.03)  # about the centre of mass, body axes (kg m^2)
BOB = f"""<mujoco model="ball_bob"><option gravity="0 0 -{G}"/><worldbody>
<body name="bob" pos="0 0 1"><joint name="pivot" type="ball"/>
<inertial pos="0 0 -{D}" mass="{M}" diaginertia="{I_CENTRE[0]} {I_CENTRE[1]} {I_CENTRE[2]}"/>
</body></worldbody></mujoco>"""


@pytest.fixture(scope="module")
def bob(tmp_path_factory):
    path = tmp_path_factory.mktemp("ball_modes") / "bob.xml"
    path.write_text(BOB)
    return lagrangian.load(path)


def test_a_hanging_body_on_a_ball_swings_as_a_compound_pendulum(bob):
    modes = bob.modes(about={"pivot__x": 0.0, "pivot__y": 0.0, "pivot__z": 0.0})
    omega = np.sort(np.asarray(modes.natural_frequencies))
    expected = np.sort([0.0] + [np.sqrt(M * G * D / (inertia + M * D**2))
                                for inertia in I_CENTRE[:2]])
    np.testing.assert_allclose(omega, expected, atol=1e-6)


def test_every_rest_found_has_its_centre_of_mass_on_the_vertical(bob):
    dynamics = bob.dynamics()
    from lagrangian.dynamics.tree.model_charts import ModelCharts

    charts = ModelCharts(bob.model, dynamics.velocity_names)
    found = bob.equilibria()
    assert len(found) >= 2
    for rest in found:
        theta = np.array([rest.coordinates[f"pivot__{a}"] for a in "xyz"])
        centre = dynamics.center_of_mass(charts.configuration(theta)) - np.array([0, 0, 1.0])
        assert np.hypot(centre[0], centre[1]) < 1e-7, rest
        assert abs(abs(centre[2]) - D) < 1e-7
        assert rest.stable == (centre[2] < 0), rest


def test_a_rest_found_on_a_family_is_taken_back_as_one(tmp_path):
    """A rest that equilibria() lists is accepted by linearize as given: on the ball-and-hinge
    arm's family of rests (the ball turning about the vertical through its pivot) Newton's
    polish slides along the family, and the rest was refused as 'not an equilibrium' for a
    residual of 1e-9. About it the turn is a zero mode, which the elbow alone cannot move: LQR
    says so in one line."""
    path = tmp_path / "chain.xml"
    hand = BALL_HINGE_BALL[BALL_HINGE_BALL.index('        <body name="hand"'):
                           BALL_HINGE_BALL.index('      </body>\n    </body>')]
    path.write_text(BALL_HINGE_BALL.replace(hand, ""))  # a ball, then a hinge
    chain = lagrangian.load(path)
    rest = chain.equilibria()[0]
    linear = chain.linearize(rest.coordinates, inputs=["elbow"])
    assert all(abs(linear.equilibrium[name] - value) < 1e-12
               for name, value in rest.coordinates.items())
    with pytest.raises(lagrangian.InputError, match="not stabilizable"):
        lagrangian.lqr(linear, 1.0, 1.0)
