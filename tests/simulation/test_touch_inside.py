"""A condition that turns true and back within one integrator step is seen (the step's dense
output looked at between its ends): a stop condition at a crest, and a falling rod's end that
would otherwise pass through the floor between two steps."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from lagrangian.simulation.integration_loops import integrate_steps
from lagrangian.simulation.options import StepControl


def test_a_crest_inside_one_step_stops_the_run_where_the_closed_form_says():
    """x = sin t exceeds 0.995 only for t in (asin 0.995, pi - asin 0.995), 0.2 s, inside one
    1.1 s step of a loose DOP853: the run stops at asin 0.995."""
    run = integrate_steps(lambda t, y: np.array([y[1], -y[0]]), 0.0, np.array([0.0, 1.0]), 3.0,
                          np.linspace(0.0, 3.0, 4), StepControl("DOP853", 1e-6, 1e-6),
                          lambda q, v, t: float(q[0] - 0.995))
    assert run.status == "stopped"
    assert run.t[-1] == pytest.approx(np.arcsin(0.995), abs=1e-5)  # the interpolant's 1e-6


def test_an_elastic_rods_ends_never_pass_through_the_floor():
    """At e = 1 (no slip) the rod's free end struck the floor inside a step and came back out
    unseen (0.18 m through it by t = 0.6 s); every strike is now taken."""
    rod = lagrangian.load("falling_rod").with_parameters(e=1.0)
    L = rod.parameters["L"]
    run = rod.simulate(10.0, samples=5001)
    y, theta = run.q[:, 1], run.q[:, 2]
    for end in (y - L / 2 * np.sin(theta), y + L / 2 * np.sin(theta)):
        assert end.min() > -1e-9
    assert {r.name for r in run.impacts} == {"end_a", "end_b"}

