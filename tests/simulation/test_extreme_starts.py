"""Extreme but finite starts (issue 39): refused, or answered, within a bounded number of
right-hand-side calls (counted, never timed), on a URDF robot's step loop and on a model file's
compiled loop; and a fast but resolvable motion still integrates, conserving its energy."""

from __future__ import annotations

import re

import numpy as np
import pytest

import lagrangian
from lagrangian.compile.functions import NumericSystem
from lagrangian.errors import InputError
from lagrangian.kinds import RunStatus
from lagrangian.simulation.guards import COLLAPSE_STEPS, MAX_REJECTED, MAX_STEPS
from lagrangian.simulation.integration_loops import integrate_steps
from lagrangian.simulation.options import METHODS, StepControl

# a window of accepted steps of DOP853's 12 stages, with no more rejected steps than accepted
WINDOW_CALLS = 2 * 12 * COLLAPSE_STEPS


@pytest.fixture(scope="module")
def arm():
    return lagrangian.load("two_link_arm")  # a URDF robot: the tree's step loop in Python


@pytest.fixture(scope="module")
def double_pendulum():
    return lagrangian.load("double_pendulum")  # a model file: the compiled loop where it builds


@pytest.fixture
def rhs_calls(monkeypatch):
    """Every right-hand side evaluated in Python, counted (the times it was called at)."""
    calls: list[float] = []
    original = NumericSystem.rhs

    def counted(self, t, y):
        calls.append(t)
        return original(self, t, y)

    monkeypatch.setattr(NumericSystem, "rhs", counted)
    return calls


def _stopped_at(message: str) -> float:
    return float(re.search(r"stopped at t = (\S+) s", message).group(1))


@pytest.mark.parametrize("rate", [1e308, 1e200, 1e154])
def test_a_rate_that_overflows_the_arm_is_refused_naming_it(arm, rhs_calls, rate):
    # the centrifugal terms go as shoulder_dot^2: past 1.3e154 rad/s they overflow at once
    with pytest.raises(InputError) as refused:
        # limits=False: its velocity limit would refuse the start first (the guard's the test)
        arm.simulate(1.0, initial={"shoulder_dot": rate}, limits=False)
    assert refused.value.field == "initial.shoulder_dot"
    assert str(refused.value) == (f"initial.shoulder_dot: {rate:.6g} makes the motion overflow "
                                  "(the accelerations are not finite at t = 0 s)")
    assert len(rhs_calls) <= 1 + 2  # the start, and the start with that rate set to 0


def test_a_model_file_rate_that_overflows_is_refused_before_its_compiled_loop(
        double_pendulum, rhs_calls):
    with pytest.raises(InputError) as refused:
        double_pendulum.simulate(1.0, initial={"theta1_dot": 1e308})
    assert str(refused.value) == ("initial.theta1_dot: 1e+308 makes the motion overflow (the "
                                  "accelerations are not finite at t = 0 s)")
    assert len(rhs_calls) <= 1 + 2


def test_the_panda_named_by_its_short_name_refuses_an_overflowing_rate(rhs_calls):
    try:
        panda = lagrangian.load("panda")
    except lagrangian.ModelError:
        pytest.skip("example-robot-data's Panda is not installed")
    with pytest.raises(InputError) as refused:
        panda.simulate(1.0, initial={"panda_joint2_dot": 1e154}, limits=False)
    assert refused.value.field == "initial.panda_joint2_dot"
    assert len(rhs_calls) <= 1 + 1  # only joint 2 turns: the only rate to set to 0


def test_a_spin_too_fast_to_resolve_fails_within_one_window(arm, rhs_calls):
    """omega = 1e50 rad/s: the error control keeps the steps on the motion's time scale 1/omega
    (the elbow's centrifugal swing), far below the float spacing of t at 1 s: a collapse."""
    run = arm.simulate(1.0, initial={"shoulder_dot": 1e50}, limits=False)
    assert run.status == RunStatus.FAILED
    assert run.message.startswith(f"the step size collapsed: {COLLAPSE_STEPS} steps took t")
    mean_step = _stopped_at(run.message) / COLLAPSE_STEPS
    assert mean_step * 1e50 < 10.0 and mean_step < np.spacing(1.0)
    assert len(rhs_calls) == run.nfev + 1 <= WINDOW_CALLS  # + 1: the start's own check


def test_a_model_file_spin_too_fast_fails_within_one_window_of_the_compiled_loop(
        double_pendulum):
    run = double_pendulum.simulate(1.0, initial={"theta1_dot": 1e50})
    assert run.status == RunStatus.FAILED and "the step size collapsed" in run.message
    assert _stopped_at(run.message) / COLLAPSE_STEPS * 1e50 < 10.0  # steps of order 1/omega
    assert run.nfev <= WINDOW_CALLS


def test_a_spin_that_needs_too_many_steps_fails_at_once(double_pendulum):
    """omega = 1e10 rad/s to t = 1 s: steps of order 1/omega would number about 1e10, past
    the limit the compiled loop would reach only after MAX_STEPS of them (10 s)."""
    run = double_pendulum.simulate(1.0, initial={"theta1_dot": 1e10})
    assert run.status == RunStatus.FAILED and "past the limit of 10,000,000 steps" in run.message
    mean_step = _stopped_at(run.message) / COLLAPSE_STEPS
    assert mean_step * 1e10 < 10.0 and 1.0 / mean_step > MAX_STEPS
    assert run.nfev <= WINDOW_CALLS


def test_a_fast_but_resolvable_spin_integrates_and_conserves_energy(arm):
    """300 rad/s for 0.05 s (15 turns, no loads but gravity): not refused, and T + V is kept."""
    run = arm.simulate(0.05, initial={"shoulder_dot": 300.0}, limits=False, samples=11)
    assert run.status == RunStatus.FINISHED
    drift = np.max(np.abs(run.energy - run.energy[0])) / abs(run.energy[0])
    assert drift < 1e-7


def _oscillator(kind: str, calls: list):
    """x'' = -x, with derivatives NaN everywhere ("start") or only after t = 0 ("after")."""
    def f(t, y):
        calls.append(t)
        if kind == "start" or t > 0:
            return np.array([np.nan, 0.0])
        return np.array([y[1], -y[0]])

    return f


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("kind", ["start", "after"])
def test_a_loop_on_derivatives_that_are_never_finite_ends_in_bounded_calls(method, kind):
    # scipy's own loop never ended on these: NaN < min_step is false, so h shrank forever
    calls: list[float] = []
    run = integrate_steps(_oscillator(kind, calls), 0.0, np.array([1.0, 0.0]), 1.0,
                          np.linspace(0.0, 1.0, 11), StepControl(method=method))
    assert run.status == RunStatus.FAILED and run.t[-1] == 0.0
    assert len(calls) <= MAX_REJECTED * 12 + 2 * 12


HOPPER = """<?xml version="1.0"?>
<robot name="hopper">
  <link name="trunk"><inertial><mass value="3.0"/>
    <inertia ixx="0.05" ixy="0" ixz="0" iyy="0.07" iyz="0" izz="0.06"/></inertial></link>
  <link name="leg"><inertial><origin xyz="0 0 -0.15"/><mass value="0.8"/>
    <inertia ixx="0.006" ixy="0" ixz="0" iyy="0.006" iyz="0" izz="0.001"/></inertial></link>
  <joint name="hip" type="revolute"><parent link="trunk"/><child link="leg"/>
    <origin xyz="0.1 0 -0.05"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="100"/></joint>
</robot>
"""


@pytest.fixture(scope="module")
def hopper(tmp_path_factory):
    pytest.importorskip("yourdfpy")
    path = tmp_path_factory.mktemp("hopper") / "hopper.urdf"
    path.write_text(HOPPER)
    return lagrangian.load(path, floating_base=True)


@pytest.fixture
def dynamics_calls(hopper, monkeypatch):
    """The floating base's forward dynamics, counted (one per right-hand side)."""
    dynamics, calls = hopper.dynamics(), []
    original = dynamics.forward_dynamics

    def counted(q, v, tau):
        calls.append(1)
        return original(q, v, tau)

    monkeypatch.setattr(dynamics, "forward_dynamics", counted)
    return calls


@pytest.mark.parametrize("name", ["base_wx", "hip_dot"])
def test_a_floating_base_refuses_an_overflowing_rate(hopper, dynamics_calls, name):
    with pytest.raises(InputError) as refused:
        hopper.simulate(1.0, initial={name: 1e308}, limits=False)
    assert str(refused.value) == (f"initial.{name}: 1e+308 makes the motion overflow (the "
                                  "accelerations are not finite at t = 0 s)")
    assert len(dynamics_calls) <= 1 + 1


def test_a_floating_base_spinning_too_fast_fails_within_one_window(hopper, dynamics_calls):
    run = hopper.simulate(1.0, initial={"hip_dot": 1e50}, limits=False)
    assert run.status == RunStatus.FAILED and "the step size collapsed" in run.message
    assert len(dynamics_calls) == run.nfev + 1 <= WINDOW_CALLS  # + 1: the start's check
