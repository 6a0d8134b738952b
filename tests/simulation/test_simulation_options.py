"""Simulation options as small immutable types: StepControl, SaveAt, a parsed StopCondition."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.simulation.result import SimulationResult
from lagrangian.simulation.simulate import SaveAt, StepControl, parse_stop_condition, simulate

G = 9.81


@pytest.fixture(scope="module")
def pendulum():
    return lagrangian.load("pendulum")


@pytest.mark.parametrize(("options", "field", "message"), [
    ({"method": "Euler"}, "method", "unknown method 'Euler'; choose one of DOP853"),
    ({"rtol": 0.0}, "rtol", "rtol must be a positive number"),
    ({"atol": float("nan")}, "atol", "atol must be a positive number"),
    ({"rtol": math.inf}, "rtol", "rtol must be a positive number"),
    ({"max_step": -1.0}, "max_step", "max_step must be a positive number"),
])
def test_step_control_refuses_bad_values_naming_the_field(options, field, message):
    with pytest.raises(ModelError) as info:
        StepControl(**options)
    assert info.value.field == field and message in info.value.message


def test_save_at_needs_two_samples_and_options_are_immutable():
    for samples in (1, 0, 2.5, True):
        with pytest.raises(ModelError, match="samples must be at least 2") as info:
            SaveAt(samples)  # type: ignore[arg-type]
        assert info.value.field == "samples"
    with pytest.raises(dataclasses.FrozenInstanceError):
        StepControl().rtol = 1.0  # type: ignore[misc]


def test_save_at_gives_evenly_spaced_samples_with_both_ends(pendulum):
    result = simulate(pendulum.equations_of_motion(), 0.5, save_at=SaveAt(11))
    np.testing.assert_allclose(result.t, np.linspace(0, 0.5, 11), rtol=0, atol=1e-15)


def test_max_step_bounds_every_step_and_keeps_the_physics(pendulum):
    """With steps of at most 1 ms over 0.2 s the run takes at least 200 steps; the small swing
    still follows theta0 cos(omega t), omega = sqrt(g / L)."""
    theta0 = 1e-3
    result = simulate(pendulum.equations_of_motion(), 0.2, initial={"theta": theta0},
                      step_control=StepControl("DOP853", 1e-10, 1e-12, max_step=1e-3))
    assert result.backend == "scipy"  # the compiled loop has no step bound
    assert result.steps >= 200
    omega = math.sqrt(G / 0.5)
    np.testing.assert_allclose(result.q[:, 0], theta0 * np.cos(omega * result.t),
                               atol=theta0 * 1e-5)


def test_a_parsed_stop_condition_is_used_as_given(pendulum):
    """Released at rest from 0.1 rad, the pendulum reaches theta = 0 a quarter period later."""
    stop = parse_stop_condition("theta < 0", pendulum.model)
    run = pendulum.simulate(5.0, initial={"theta": 0.1}, stop_when=stop, rtol=1e-12, atol=1e-12)
    assert run.status == "stopped" and run.stop_when == "theta < 0"
    # T = T0 (1 + theta0^2 / 16 + ...): 0.1 rad lengthens the period by 0.06 %
    quarter = math.pi / 2 * math.sqrt(0.5 / G) * (1 + 0.1**2 / 16)
    assert run.t[-1] == pytest.approx(quarter, rel=1e-5)


def test_simulation_is_the_one_result_type(pendulum):
    run = pendulum.simulate(0.1, samples=3)
    assert isinstance(run, lagrangian.Simulation) and isinstance(run, SimulationResult)
    assert run.step_control == StepControl() and run.method == "DOP853"
    assert run.last_state.t == run.t[-1] and run.last_state.q == (run.q[-1, 0],)
    assert run.summary()["final_state"] == run.final_state
    assert repr(run).startswith(f"Simulation({pendulum.name!r}: finished")
