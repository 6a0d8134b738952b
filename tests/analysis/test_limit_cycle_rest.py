"""The bouncing ball's cycles: neutral when elastic (a family of them), none when e < 1 (the
impacts accumulate), each said so in words (issue 41)."""

from __future__ import annotations

import math

import pytest

import lagrangian
from lagrangian.errors import InputError
from lagrangian.output.impacts import cycle_text


@pytest.fixture(scope="module")
def ball():
    return lagrangian.load("bouncing_ball")


def test_an_elastic_ball_has_a_neutral_cycle_of_period_2v_over_g(ball):
    cycle = ball.with_parameters(e=1.0).limit_cycle()
    g = {p.name: p.value for p in ball.model.parameters}["g"]
    v = math.sqrt(2 * g * 1.0)  # dropped from y = 1 m: it leaves the floor at sqrt(2 g h)
    assert math.isclose(cycle.state["y_dot"], v, rel_tol=1e-9)
    assert math.isclose(cycle.period, 2 * v / g, rel_tol=1e-9)
    (multiplier,) = cycle.multipliers  # a higher bounce is another cycle: |mu| = 1
    assert abs(multiplier - 1) < 1e-6
    assert not cycle.stable and cycle.stability == "neutral"
    assert cycle.to_dict()["stability"] == "neutral"
    assert "a neutrally stable limit cycle" in cycle_text(cycle, "Bouncing ball")


def test_a_ball_with_e_below_1_has_no_cycle_its_returns_shrink_by_e(ball):
    with pytest.raises(InputError, match="impacts accumulate") as caught:
        ball.with_parameters(e=0.8).limit_cycle()
    g = {p.name: p.value for p in ball.model.parameters}["g"]
    v = math.sqrt(2 * g * 1.0)
    # the flights after the first two impacts: 2 v e / g and 2 v e^2 / g
    assert f"{2 * v * 0.8 / g:.4g} -> {2 * v * 0.8**2 / g:.4g} s" in str(caught.value)
    assert "\n" not in str(caught.value)


def test_a_flow_whose_step_collapses_ends_the_search_in_one_line():
    # g = 1e154: the wheel's time scale sqrt(L/g) is 1e-77 s, so DOP853 stepped 1e-78 s at a
    # time toward the search's 20 s and never returned (minutes at full CPU); now the guards
    # of the other loops end it after one window of 1000 steps, numpy's warnings held back
    import warnings

    wheel = lagrangian.load("rimless_wheel").with_parameters(g=1e154)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(InputError, match="the step size collapsed: 1000 steps") as caught:
            wheel.limit_cycle()
    assert "\n" not in str(caught.value)
