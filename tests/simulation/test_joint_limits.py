"""simulate respects a URDF's position limits (issue 27): a joint that reaches its limit ends
the run with status 'limit', naming the joint, at the state energy conservation predicts;
``limits=False`` / ``--ignore-limits`` runs through it; a run that stays inside keeps the
compiled loop."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import lagrangian

pytest.importorskip("yourdfpy")

G = 9.81
# A 1 kg point 1 m below a hinge about y: V = -m g cos(q), a simple pendulum (L = 1 m).
PENDULUM = """<?xml version="1.0"?>
<robot name="hinged">
  <link name="base"/>
  <link name="bob"><inertial><origin xyz="0 0 -1"/><mass value="1"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <joint name="hinge.1" type="revolute"><parent link="base"/><child link="bob"/>
    <axis xyz="0 1 0"/><limit lower="-0.3" upper="0.5" effort="1" velocity="1"/></joint>
</robot>
"""


@pytest.fixture
def pendulum(tmp_path):
    path = tmp_path / "hinged.urdf"
    path.write_text(PENDULUM)
    return path


def test_a_joint_reaching_its_limit_ends_the_run_there(pendulum):
    system = lagrangian.load(pendulum)
    run = system.simulate(3.0, initial={"hinge_1": 0.4})  # from rest: swings to -0.4
    assert run.status == "limit" and run.completed
    assert "joint 'hinge.1'" in run.message and "-0.3 rad" in run.message
    q, v = run.q[-1, 0], run.q_dot[-1, 0]
    assert q == pytest.approx(-0.3, abs=1e-9)
    # energy: 1/2 v^2 = g (cos(-0.3) - cos(0.4)), moving down through the limit
    assert v == pytest.approx(-math.sqrt(2 * G * (math.cos(0.3) - math.cos(0.4))), rel=1e-7)
    # the first swing takes less than half the small-angle period pi sqrt(L/g)
    assert 0 < run.t[-1] < math.pi * math.sqrt(1 / G)


def test_ignoring_the_limits_runs_through_them(pendulum, cli):
    run = lagrangian.load(pendulum).simulate(3.0, initial={"hinge_1": 0.4}, limits=False)
    assert run.status == "finished"
    assert run.q[:, 0].min() == pytest.approx(-0.4, abs=1e-4)  # the full swing, past -0.3
    result = cli("simulate", str(pendulum), "--t-end", "3", "--initial", "hinge_1=0.4",
                 "--ignore-limits", "--json")
    assert json.loads(result.out)["status"] == "finished"
    result = cli("simulate", str(pendulum), "--t-end", "3", "--initial", "hinge_1=0.4", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["status"] == "limit" and "hinge.1" in document["message"]
    assert document["final_state"]["hinge_1"] == pytest.approx(-0.3, abs=1e-9)


def test_a_run_inside_the_limits_is_untouched(pendulum):
    system = lagrangian.load(pendulum)
    inside = system.simulate(3.0, initial={"hinge_1": 0.2})
    free = system.simulate(3.0, initial={"hinge_1": 0.2}, limits=False)
    assert inside.status == "finished"
    np.testing.assert_array_equal(inside.q, free.q)  # the same loop, the same numbers
    assert inside.summary()["backend"] == free.summary()["backend"]


def test_a_stop_condition_before_the_limit_still_stops(pendulum):
    run = lagrangian.load(pendulum).simulate(3.0, initial={"hinge_1": 0.4},
                                             stop_when="hinge_1 < 0")
    assert run.status == "stopped" and run.q[-1, 0] == pytest.approx(0, abs=1e-9)


def test_velocity_and_effort_limits_exceeded_are_reported(pendulum, cli):
    # the URDF's velocity limit 1 rad/s; from 0.4 rad at rest the bob passes the bottom at
    # sqrt(2 g (1 - cos 0.4)) = 1.24 rad/s, a quarter of a small-angle period in
    run = lagrangian.load(pendulum).simulate(3.0, initial={"hinge_1": 0.4}, limits=False)
    (record,) = run.summary()["limits_exceeded"]
    assert record["joint"] == "hinge.1" and record["quantity"] == "velocity"
    assert record["limit"] == 1.0 and record["unit"] == "rad/s"
    assert record["value"] == pytest.approx(math.sqrt(2 * G * (1 - math.cos(0.4))), rel=1e-4)
    assert record["t"] == pytest.approx(0.5 * math.pi * math.sqrt(1 / G), rel=0.02)
    # an actuator torque above the effort limit (1 N m), and the text summary
    result = cli("simulate", str(pendulum), "--t-end", "0.2", "--set", "tau_hinge_1=2")
    assert result.code == 0, result.err
    assert "effort limit exceeded: joint 'hinge.1' (hinge_1) 2 N m > 1 N m" in result.out
    # a slow swing exceeds nothing
    calm = lagrangian.load(pendulum).simulate(3.0, initial={"hinge_1": 0.1})
    assert calm.summary()["limits_exceeded"] == []


@pytest.mark.parametrize("floating", [False, True])
def test_a_start_beyond_a_limit_is_refused_naming_the_joint(pendulum, cli, floating):
    """The limit event fires on a crossing only: a run started past a limit went on without a
    word (the Panda 0.2 rad past joint 4's ended 'finished' at 3.87 rad against -0.07)."""
    from lagrangian.errors import InputError

    robot = lagrangian.load(pendulum, floating_base=floating)
    with pytest.raises(InputError, match=r"joint 'hinge.1' \(hinge_1\) starts at 0\.7, above "
                                         r"its position limit 0\.5 \(range -0\.3 to 0\.5\)"):
        robot.simulate(0.1, initial={"hinge_1": 0.7})
    if not floating:  # floating, the point mass on a massless base has a singular M
        assert robot.simulate(0.05, initial={"hinge_1": 0.7}, limits=False).status == "finished"
        code, out, err = cli("simulate", str(pendulum), "--t-end", "0.1", "--initial",
                             "hinge_1=0.7")
        assert code == 2 and err.strip().splitlines()[-1].startswith(
            "error: --initial: joint 'hinge.1' (hinge_1) starts at 0.7, above its position")
