"""A start beyond a URDF joint's position limit: refused by default, clamped to the limit with
limits="clamp" / --clamp-start, or run from where it is with limits=False / --ignore-limits,
each noted in the result's message; a joint that starts on its limit no longer hides the other
joints' crossings (the Panda's finger at its lower limit 0 did)."""

from __future__ import annotations

import json
import math

import pytest

import lagrangian

pytest.importorskip("yourdfpy")

# A 1 kg point 1 m below a hinge about y: a simple pendulum, V = -m g cos(q).
PENDULUM = """<?xml version="1.0"?>
<robot name="hinged">
  <link name="base"/>
  <link name="bob"><inertial><origin xyz="0 0 -1"/><mass value="1"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="bob"/>
    <axis xyz="0 1 0"/><limit lower="LOWER" upper="UPPER" effort="1" velocity="10"/></joint>
</robot>
"""


def _robot(tmp_path, lower, upper):
    path = tmp_path / f"hinged_{lower}_{upper}.urdf"
    path.write_text(PENDULUM.replace("LOWER", str(lower)).replace("UPPER", str(upper)))
    return path


@pytest.fixture(scope="module")
def swinging(tmp_path_factory):
    return _robot(tmp_path_factory.mktemp("limits"), -0.3, 0.5)


def test_a_clamped_start_swings_from_the_limit(swinging):
    robot = lagrangian.load(swinging)
    run = robot.simulate(1.5, initial={"hinge": -0.7}, limits="clamp", samples=301)
    # started at rest on the lower limit -0.3: gravity pulls it in, and by energy conservation
    # it swings to +0.3 (inside the upper 0.5) and back: the run finishes
    assert run.q[0, 0] == -0.3
    assert run.status == lagrangian.RunStatus.FINISHED
    assert run.q[:, 0].max() == pytest.approx(0.3, abs=1e-4)
    assert "starts at -0.7, below its position limit -0.3" in run.message
    assert run.message.endswith("rad: clamped to the limit")
    # from the upper limit it swings to -0.5, past the lower: it stops there, at the time
    # energy conservation predicts (the pendulum's quarter period to q = -0.3 from 0.5)
    run = robot.simulate(2.0, initial={"hinge": 0.9}, limits="clamp")
    assert run.status == lagrangian.RunStatus.LIMIT
    assert "reached its position limit -0.3 rad" in run.message
    assert run.q[-1, 0] == pytest.approx(-0.3, abs=1e-6)
    g, theta0 = 9.81, 0.5
    quadrature = 200_001  # t = int dq / sqrt(2 g (cos q - cos q0)) from 0.5 to -0.3
    t = _time_between(g, theta0, -0.3, quadrature)
    assert run.t[-1] == pytest.approx(t, rel=1e-3)


def _time_between(g, theta0, theta1, points):
    """Time to swing from rest at theta0 down to theta1 (rad), L = 1 m: the substitution
    sin(q/2) = k sin(phi) removes the endpoint singularity."""
    import numpy as np

    k = math.sin(theta0 / 2)
    phi0, phi1 = math.pi / 2, math.asin(math.sin(theta1 / 2) / k)
    phi = np.linspace(phi1, phi0, points)
    integrand = 1 / np.sqrt(1 - (k * np.sin(phi)) ** 2)
    return float(np.trapezoid(integrand, phi)) / math.sqrt(g)


def test_a_clamped_start_pushed_out_ends_at_the_limit_at_once(tmp_path):
    # limits [0.5, 1]: clamped from 0.2 to 0.5, gravity pulls the bob back toward 0, out
    robot = lagrangian.load(_robot(tmp_path, 0.5, 1.0))
    run = robot.simulate(1.0, initial={"hinge": 0.2}, limits="clamp")
    assert run.status == lagrangian.RunStatus.LIMIT and run.t[-1] < 1e-3
    assert "reached its position limit 0.5 rad" in run.message


def test_started_anyway_says_so(swinging, cli):
    robot = lagrangian.load(swinging)
    run = robot.simulate(0.05, initial={"hinge": 0.7}, limits=False, samples=5)
    assert run.q[0, 0] == 0.7 and run.status == lagrangian.RunStatus.FINISHED
    assert run.message.endswith("rad: started there, the limits ignored")
    code, out, err = cli("simulate", str(swinging), "--t-end", "0.05", "--initial", "hinge=0.7",
                         "--clamp-start", "--samples", "5", "--json")
    assert code == 0, err
    document = json.loads(out)
    assert "clamped to the limit" in document["message"]
    code, _, err = cli("simulate", str(swinging), "--t-end", "0.05", "--clamp-start",
                       "--ignore-limits")
    assert code == 2 and len(err.strip().splitlines()) == 1
    with pytest.raises(lagrangian.InputError, match="limits is True, False or 'clamp'"):
        robot.simulate(0.05, limits="sometimes")


def test_a_joint_on_its_limit_hides_no_crossing():
    # the Panda's finger starts on its lower limit 0: joint 2, started at 1.7 and falling,
    # still stops at its limit 1.7628 rad (it ran through to 3.1 rad before)
    if "panda" not in {r["name"] for r in lagrangian.example_robots()}:
        pytest.skip("example-robot-data is not installed")
    panda = lagrangian.load("panda")
    run = panda.simulate(0.5, initial={"panda_joint2": 1.7}, samples=11)
    assert run.status == lagrangian.RunStatus.LIMIT
    assert "joint 'panda_joint2' (panda_joint2) reached its position limit 1.7628" in run.message
    assert run.q[-1, 1] == pytest.approx(1.7628, abs=1e-6)


# A slider resting on its lower limit 0 beside a 1 m pendulum hinged on the same base (their
# motions independent): the pendulum's crossing is the one named.
TWIN = """<?xml version="1.0"?>
<robot name="twin">
  <link name="base"/>
  <link name="slide"><inertial><mass value="1"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <link name="bob"><inertial><origin xyz="0 0 -1"/><mass value="1"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <joint name="slider" type="prismatic"><parent link="base"/><child link="slide"/>
    <axis xyz="1 0 0"/><limit lower="0" upper="1" effort="1" velocity="10"/></joint>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="bob"/>
    <axis xyz="0 1 0"/><limit lower="-0.3" upper="0.6" effort="1" velocity="10"/></joint>
</robot>
"""


def test_the_joint_that_crossed_is_named_not_one_resting_on_its_limit(tmp_path):
    # the event's root leaves the hinge 1e-13 short of -0.3 or past it; the slider, exactly on
    # 0, was named about half the time (from rest at 0.45 rad and at 0.35 rad, both were)
    path = tmp_path / "twin.urdf"
    path.write_text(TWIN)
    robot = lagrangian.load(path)
    for theta0 in (0.45, 0.35):
        run = robot.simulate(3, initial={"hinge": theta0}, samples=11)
        assert run.status == lagrangian.RunStatus.LIMIT
        assert run.message.startswith("joint 'hinge' (hinge) reached its position limit -0.3")
        assert run.q[-1, 0] == 0.0
        assert run.t[-1] == pytest.approx(_time_between(9.81, theta0, -0.3, 200_001), rel=1e-3)


def test_on_a_floating_base_too(tmp_path):
    # the twin on a free 10 kg base: the slider rests on its limit 0 (it hid every crossing:
    # the floating Panda, its finger at 0, ran joint 2 through 1.7628 to 2.02 rad), and a start
    # beyond a limit run with limits=False says so in the result, as on a fixed base
    path = tmp_path / "twin_floating.urdf"
    # (the slider along y, the hinge's axis: the base's recoil in x and z, its turn about y,
    # push it nowhere)
    path.write_text(TWIN.replace('<link name="base"/>', '<link name="base"><inertial><mass '
                                 'value="10"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" '
                                 'izz="1"/></inertial></link>')
                    .replace('<axis xyz="1 0 0"/>', '<axis xyz="0 1 0"/>'))
    robot = lagrangian.load(path, floating_base=True)
    run = robot.simulate(1.0, initial={"hinge": 0.0, "hinge_dot": -2.0}, samples=11)
    assert run.status == lagrangian.RunStatus.LIMIT
    assert run.message.startswith("joint 'hinge' (hinge) reached its position limit -0.3")
    hinge = list(run.coordinates).index("hinge")
    assert run.q[-1, hinge] == pytest.approx(-0.3, abs=1e-6)
    run = robot.simulate(0.05, initial={"hinge": 0.7}, limits=False, samples=3)
    assert run.q[0, hinge] == 0.7
    assert run.message.endswith("starts at 0.7, above its position limit 0.6 (range -0.3 to "
                                "0.6) rad: started there, the limits ignored")
