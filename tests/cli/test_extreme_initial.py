"""`simulate --initial NAME=1e308` and other extreme but finite starts (issue 39): one line and
exit 2 for a rate that overflows the accelerations at once, one line and exit 1 for a run
whose step size collapses; each within a bounded number of right-hand-side calls (counted)."""

from __future__ import annotations

import json

import pytest

import lagrangian
from lagrangian.compile.functions import NumericSystem
from lagrangian.simulation.guards import COLLAPSE_STEPS

WINDOW_CALLS = 2 * 12 * COLLAPSE_STEPS  # DOP853's 12 stages, no more rejected than accepted


@pytest.fixture
def rhs_calls(monkeypatch):
    """Every right-hand side evaluated in Python, counted."""
    calls: list[float] = []
    original = NumericSystem.rhs

    def counted(self, t, y):
        calls.append(t)
        return original(self, t, y)

    monkeypatch.setattr(NumericSystem, "rhs", counted)
    return calls


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


@pytest.mark.parametrize(("model", "name", "value"), [
    ("two_link_arm", "shoulder_dot", "1e308"),  # a URDF robot: the tree's step loop
    ("two_link_arm", "shoulder_dot", "1e200"),
    ("two_link_arm", "shoulder_dot", "1e154"),
    ("double_pendulum", "theta1_dot", "1e308"),  # a model file: its compiled loop
])
def test_a_rate_that_overflows_the_motion_is_refused_in_one_line(cli, rhs_calls, model, name,
                                                                 value):
    # a URDF's velocity limits would refuse the start first (test_start_rate_limits.py)
    ignore = ("--ignore-limits",) if model == "two_link_arm" else ()
    code, out, err = cli("simulate", model, "--t-end", "1", "--initial", f"{name}={value}",
                         *ignore)
    assert code == 2 and out == ""
    assert one_line(err) == (f"error: --initial {name}: {float(value):.6g} makes the motion "
                             "overflow (the accelerations are not finite at t = 0 s)")
    assert len(rhs_calls) <= 1 + 2  # the start, and the start with that rate set to 0


def test_the_panda_by_its_short_name_is_refused_in_one_line(cli, rhs_calls):
    try:
        lagrangian.load("panda")
    except lagrangian.ModelError:
        pytest.skip("example-robot-data's Panda is not installed")
    rhs_calls.clear()
    code, out, err = cli("simulate", "panda", "--t-end", "1", "--initial",
                         "panda_joint4=-1.5,panda_joint2_dot=1e200", "--ignore-limits")
    assert code == 2 and out == ""
    assert one_line(err) == ("error: --initial panda_joint2_dot: 1e+200 makes the motion "
                             "overflow (the accelerations are not finite at t = 0 s)")
    assert len(rhs_calls) <= 1 + 1


@pytest.mark.parametrize(("model", "args"), [
    ("two_link_arm", ("--initial", "shoulder_dot=1e50", "--ignore-limits")),
    ("double_pendulum", ("--initial", "theta1_dot=1e50")),
])
def test_a_step_size_collapse_ends_the_run_in_one_line(cli, rhs_calls, model, args):
    code, out, err = cli("simulate", model, "--t-end", "1", *args, "--json")
    assert code == 1
    assert one_line(err).startswith(f"error: integration failed: the step size collapsed: "
                                    f"{COLLAPSE_STEPS} steps took t only from 0 to ")
    summary = json.loads(out)
    assert summary["status"] == "failed" and summary["nfev"] <= WINDOW_CALLS
    assert len(rhs_calls) <= WINDOW_CALLS  # the arm's in Python, the pendulum's in C
