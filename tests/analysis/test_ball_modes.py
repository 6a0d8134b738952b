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
