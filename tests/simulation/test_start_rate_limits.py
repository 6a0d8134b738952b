"""A start faster than a joint's URDF velocity limit: refused in one line naming the joint,
its rate and its limit; with clamp, started at the limit's speed (the sign kept) and said in
the result; with the limits ignored, started as given and said too. The Panda's joint 4
(velocity limit 2.175 rad/s) and the built-in two-link arm."""

from __future__ import annotations

import pytest

import lagrangian
from lagrangian.errors import InputError


@pytest.fixture(scope="module")
def panda():
    try:
        return lagrangian.load("panda")
    except lagrangian.ModelError:
        pytest.skip("example-robot-data's Panda is not installed")


def test_a_start_past_a_velocity_limit_is_refused_naming_the_joint(panda):
    with pytest.raises(InputError) as refused:
        panda.simulate(0.05, initial={"panda_joint4_dot": -10.0})
    text = str(refused.value)
    assert "\n" not in text and "joint 'panda_joint4'" in text
    assert "-10 rad/s, beyond its velocity limit 2.175 rad/s" in text


def test_clamped_it_starts_at_the_limit_and_says_so(panda):
    run = panda.simulate(0.05, initial={"panda_joint4_dot": -10.0}, limits="clamp",
                         samples=11)
    assert run.q_dot[0, list(run.coordinates).index("panda_joint4")] == pytest.approx(-2.175)
    assert "clamped to the limit" in run.message and "panda_joint4" in run.message


def test_with_the_limits_ignored_it_starts_as_given_and_says_so(panda, cli):
    run = panda.simulate(0.05, initial={"panda_joint4_dot": -10.0}, limits=False, samples=11)
    assert run.q_dot[0, list(run.coordinates).index("panda_joint4")] == pytest.approx(-10.0)
    assert "started so, the limits ignored" in run.message
    result = cli("simulate", "two_link_arm", "--t-end", "0.1", "--initial", "shoulder_dot=1e3")
    assert result.code == 2 and len(result.err.strip().splitlines()) == 1
    assert "beyond its velocity limit" in result.err and "'shoulder'" in result.err
