"""The command line's everyday consistency (issue 12): the same flag means the same thing on
every command, names in any case, comma-joined assignments, --version, quiet projections."""

from __future__ import annotations

import json
import math

import pytest

import lagrangian
from lagrangian.simulation.options import StepControl


def test_derive_accepts_json_like_every_other_command(cli):
    by_flag, by_format = cli("derive", "double_pendulum", "--json"), \
        cli("derive", "double_pendulum", "--format", "json")
    assert by_flag.code == by_format.code == 0
    assert json.loads(by_flag.out) == json.loads(by_format.out)
    clash = cli("derive", "pendulum", "--json", "--format", "latex")
    assert clash.code == 2 and clash.out == ""
    assert clash.err.strip() == ("error: --format: --json and --format latex ask for two formats; "
                                 "give one")


@pytest.mark.parametrize("spelling", ["rk45", "Rk45", "RK45"])
def test_integrator_names_in_any_case(cli, spelling):
    assert StepControl(spelling).method == "RK45"
    run = cli("simulate", "pendulum", "--t-end", "1", "--method", spelling, "--json")
    assert run.code == 0
    summary = json.loads(run.out)
    assert summary["method"] == "RK45"
    # the same pendulum by another integrator: the runs agree (rtol 1e-9)
    reference = json.loads(cli("simulate", "pendulum", "--t-end", "1", "--json").out)
    assert summary["final_state"]["theta"] == pytest.approx(
        reference["final_state"]["theta"], rel=1e-6)


def test_set_suggests_a_name_that_differs_only_in_case(cli):
    result = cli("derive", "pendulum", "--set", "l=1")
    assert result.code == 2
    assert result.err.strip() == ("error: --set: 'l' is not a parameter of this model; "
                                  "did you mean 'L'?")


def test_a_name_with_no_close_match_lists_the_valid_ones(cli):
    result = cli("forces", "double_pendulum", "--at", "zzz=1")
    assert result.code == 2
    assert result.err.strip() == (
        "error: --at: 'zzz' is not a coordinate, velocity or t of this model; expected one of: "
        "theta1, theta2, theta1_dot, theta2_dot, t")


def test_assignments_may_be_joined_by_commas(cli):
    """theta0 = 0.3 rad released from rest: the comma form is the repeated form."""
    joined = cli("simulate", "pendulum", "--t-end", "0.5", "--initial", "theta=0.3,theta_dot=0",
                 "--set", "L=2,m=3", "--json")
    repeated = cli("simulate", "pendulum", "--t-end", "0.5", "--initial", "theta=0.3",
                   "--initial", "theta_dot=0", "--set", "L=2", "--set", "m=3", "--json")
    assert joined.code == repeated.code == 0
    one, other = json.loads(joined.out), json.loads(repeated.out)
    assert one["final_state"] == other["final_state"]
    # energy m g L (1 - cos theta0) is kept: the start was theta = 0.3 at rest, as given
    theta, rate = one["final_state"]["theta"], one["final_state"]["theta_dot"]
    energy = 0.5 * 3 * 4 * rate**2 + 3 * 9.81 * 2 * (1 - math.cos(theta))
    assert energy == pytest.approx(3 * 9.81 * 2 * (1 - math.cos(0.3)), rel=1e-7)
    # a comma inside a value is not taken for a second assignment
    bad = cli("forces", "pendulum", "--at", "theta=0.1,2")
    assert bad.code == 2 and bad.err.startswith("error: --at theta:")


def test_version(cli):
    result = cli("--version")
    assert result.code == 0 and result.out.strip() == f"lagrangian {lagrangian.__version__}"


def test_four_bar_starts_quietly_and_a_wrong_start_still_warns(cli):
    """The example's own start is consistent to a dozen digits (5e-10, below the solver's
    tolerance): no warning. A start moved off the linkage is projected back, with a warning."""
    quiet = cli("simulate", "four_bar", "--t-end", "0.05", "--samples", "11")
    assert quiet.code == 0 and "warning" not in quiet.err  # (a machine with no C compiler
    # adds its one-line note there)
    moved = cli("simulate", "four_bar", "--t-end", "0.05", "--samples", "11", "--initial",
                "theta2=0.8")
    assert moved.code == 0
    assert moved.err.startswith("warning: the initial state violates the constraints; "
                                "projected onto them: theta1 1 -> ")
