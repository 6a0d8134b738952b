"""Simulation through impacts: the bouncing ball's impact times and heights against the
geometric series, the accumulation time t_inf in closed form where the run stops, settling,
the cap on impacts, and T + V balanced across the impacts."""

from __future__ import annotations

import math

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import InputError

G, E, H = 9.81, 0.8, 1.0


def closed_form_times(count: int, e: float = E, h: float = H) -> list[float]:
    """t_k = t_1 + sum_{j=1}^{k-1} 2 v_1 e^j / g, t_1 = sqrt(2 h / g), v_1 = g t_1."""
    t1 = math.sqrt(2 * h / G)
    v1 = G * t1
    return [t1 + sum(2 * v1 * e**j / G for j in range(1, k + 1)) for k in range(count)]


def accumulation_time(e: float = E, h: float = H) -> float:
    t1 = math.sqrt(2 * h / G)
    return t1 * (1 + e) / (1 - e)


@pytest.fixture(scope="module")
def ball():
    return lagrangian.load("bouncing_ball")


@pytest.fixture(scope="module")
def run(ball):
    return ball.simulate(5.0, samples=501)


def test_impact_times_follow_the_geometric_series(run):
    times = [record.time for record in run.impacts]
    expected = closed_form_times(12)
    assert times[:12] == pytest.approx(expected, abs=1e-9)
    assert all(record.name == "floor" for record in run.impacts)


def test_rebound_speeds_and_heights(run):
    v1 = math.sqrt(2 * G * H)
    for k, record in enumerate(run.impacts[:8]):
        assert record.before["y_dot"] == pytest.approx(-v1 * E**k, rel=1e-9)
        assert record.after["y_dot"] == pytest.approx(v1 * E ** (k + 1), rel=1e-9)
        assert abs(record.before["y"]) < 1e-12
        assert record.impulse[1] == pytest.approx((1 + E) * v1 * E**k, rel=1e-9)  # m = 1
        assert record.residual < 1e-12
    # between the first and second impact the ball rises to e^2 h
    between = (run.t > run.impacts[0].time) & (run.t < run.impacts[1].time)
    assert run.q[between, 0].max() == pytest.approx(E**2 * H, rel=1e-4)  # on the samples


def test_the_accumulation_is_detected_at_t_inf(run):
    assert run.status == "accumulated"
    assert "accumulate" in run.message and "floor" in run.message
    assert run.accumulation_time == pytest.approx(accumulation_time(), abs=1e-9)
    assert run.t[-1] <= run.accumulation_time + 1e-9
    assert len(run.impacts) < 200  # it stopped, not ground on


def test_energy_balances_across_the_impacts(run):
    assert not run.energy_conserved
    assert run.invariant_drift < 1e-9


def test_settle_rests_on_the_floor_to_the_end(ball):
    settled = ball.simulate(5.0, samples=101, settle=True)
    assert settled.status == "settled" and settled.t[-1] == pytest.approx(5.0)
    assert np.all(np.abs(settled.q[settled.t > 4.1]) < 1e-12)
    assert np.all(settled.q_dot[settled.t > 4.1] == 0)


def test_the_cap_on_impacts(ball):
    capped = ball.simulate(5.0, samples=101, max_impacts=3)
    assert capped.status == "impact_limit" and len(capped.impacts) == 3
    assert "3 impacts" in capped.message
    for bad in (-1, 0):  # 0: the first impact would pass the cap
        with pytest.raises(InputError, match="max_impacts must be a whole number >= 1"):
            ball.simulate(1.0, max_impacts=bad)


def test_a_stop_condition_is_refused_for_impacts(ball):
    with pytest.raises(InputError, match="stop condition"):
        ball.simulate(1.0, stop_when="y < 0.5")


def test_a_plain_simulate_call_goes_through_the_impacts(ball):
    """lagrangian.simulate (the stage's entry) routes a model with impacts too."""
    from lagrangian.simulation.simulate import simulate

    result = simulate(ball.equations_of_motion(), 1.5)
    assert [r.time for r in result.impacts] == pytest.approx(closed_form_times(2), abs=1e-9)


def test_a_plastic_impact_that_presses_into_the_floor_rests_there(ball):
    """e = 0: no velocity left along the normal and gravity pressing in: a contact from then
    on, not a ball sinking through the floor unseen."""
    plastic = ball.with_parameters(e=0.0)
    run = plastic.simulate(2.0, samples=21)
    assert run.status == "accumulated" and "pressed into it" in run.message
    assert run.accumulation_time == pytest.approx(math.sqrt(2 * H / G), abs=1e-12)
    assert run.q_dot[-1, 0] == pytest.approx(0.0, abs=1e-12)
    assert np.all(run.q[:, 0] > -1e-12)
    rested = plastic.simulate(2.0, samples=21, settle=True)
    assert rested.status == "settled" and rested.t[-1] == pytest.approx(2.0)


def test_a_relabelling_that_moves_the_model_is_refused():
    """The rimless wheel relabelled by one spoke angle instead of two: the hub is not where
    the impact left it about the new foot."""
    from lagrangian.model.examples import example_text
    from lagrangian.model.reader import parse_model

    text = example_text("rimless_wheel").replace('"theta - 2*alpha"', '"theta - alpha"')
    wrong = lagrangian.System(parse_model(text, source="wheel.toml"))
    with pytest.raises(InputError, match="after its relabelling the particle 'hub'"):
        wrong.simulate(2.0, samples=11)


def test_a_normal_that_disagrees_with_the_guard_is_refused():
    """The floor's normal given pointing down: the ball 'leaves' it as y falls through 0."""
    from lagrangian.model.examples import example_text
    from lagrangian.model.reader import parse_model

    text = example_text("bouncing_ball").replace("normal = [0, 1]", "normal = [0, -1]")
    with pytest.raises(InputError, match="leaves the surface") as caught:
        lagrangian.System(parse_model(text)).simulate(1.0, samples=11)
    assert "\n" not in str(caught.value)


def test_a_walkers_pivot_moves_on_by_each_step():
    """The compass gait's released stance foot: the pivot advances by the step, 2 l sin(alpha)
    along the slope, at each heel strike (the animation draws the walker there)."""
    run = lagrangian.load("compass_gait").simulate(1.6, samples=9)
    steps = [record for record in run.impacts]
    assert len(steps) == 2
    alpha = abs(steps[0].before["theta_st"])
    after = run.pivot_offsets[run.t > steps[1].time]
    assert after[:, 0] == pytest.approx(2 * 2 * 1.0 * math.sin(alpha), rel=1e-6)
    assert np.all(run.pivot_offsets[run.t < steps[0].time] == 0)
