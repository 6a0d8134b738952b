"""LQR on a ball joint: a body balanced upright on a ball (a spherical inverted pendulum, its
centre of mass D above the pivot) by the three moments of the ball's Euler hinges. Upright the
axes decouple: about each horizontal axis theta_ddot = a theta + b u with a = m g D / J,
b = 1/J (J = I + m D^2 about the pivot), about the vertical a = 0, b = 1/I_z. With Q = I and
R = 1 the closed-loop poles are the stable roots of the symmetric root locus
(s^2 - a)^2 + b^2 (1 - s^2) = 0. The controller reads the run's quaternion state in the Euler
angles of its linear model and gives the ball's moment back: simulated from a 0.1 rad tilt the
body returns upright, and at a small tilt the run follows the linear closed loop's decay."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.linalg import expm

import lagrangian
from lagrangian.errors import InputError

M, D, G = 2.0, 0.4, 9.81
I_CENTRE = np.array([0.05, 0.08, 0.03])  # kg m^2 about the centre of mass, body axes
TOP = f"""<mujoco model="ball_top"><option gravity="0 0 -{G}"/><worldbody>
<body name="top" pos="0 0 1"><joint name="pivot" type="ball"/>
<inertial pos="0 0 {D}" mass="{M}" diaginertia="{' '.join(map(str, I_CENTRE))}"/>
</body></worldbody></mujoco>"""
HINGES = ["pivot__x", "pivot__y", "pivot__z"]
UPRIGHT = dict.fromkeys(HINGES, 0.0)
Q_NAMES = ["pivot_qw", "pivot_qx", "pivot_qy", "pivot_qz"]


@pytest.fixture(scope="module")
def top(tmp_path_factory):
    path = tmp_path_factory.mktemp("ball_lqr") / "top.xml"
    path.write_text(TOP)
    system = lagrangian.load(path)
    regulator = lagrangian.lqr(system.linearize(UPRIGHT, inputs=HINGES), 1.0, 1.0)
    return path, system, regulator


def _tilt(q: np.ndarray) -> np.ndarray:
    """The angle (rad) between the body's axis and the vertical, of quaternions w x y z."""
    x, y = q[..., 1], q[..., 2]
    return np.arccos(np.clip(1 - 2 * (x * x + y * y), -1.0, 1.0))


def _start(system, angles) -> dict[str, float]:
    """The run's start (the ball's quaternion) at the Euler angles R = Rx Ry Rz."""
    half = np.asarray(angles) / 2
    q = np.array([1.0, 0, 0, 0])
    for k in range(3):
        turn = np.zeros(4)
        turn[0], turn[k + 1] = np.cos(half[k]), np.sin(half[k])
        q = np.r_[q[0] * turn[0] - q[1:] @ turn[1:],
                  q[0] * turn[1:] + turn[0] * q[1:] + np.cross(q[1:], turn[1:])]
    return dict(zip(Q_NAMES, q, strict=True))


def test_the_closed_loop_poles_are_the_symmetric_root_locus(top):
    regulator = top[2]
    expected = []
    for a, b in ((M * G * D / (I_CENTRE[0] + M * D**2), 1 / (I_CENTRE[0] + M * D**2)),
                 (M * G * D / (I_CENTRE[1] + M * D**2), 1 / (I_CENTRE[1] + M * D**2)),
                 (0.0, 1 / I_CENTRE[2])):
        squares = np.roots([1.0, -(2 * a + b * b), a * a + b * b])
        expected += [-np.sqrt(complex(s)) for s in squares]  # the left half-plane roots
    found = regulator.closed_loop_eigenvalues
    assert np.all(found.real < 0)
    np.testing.assert_allclose(np.sort_complex(found), np.sort_complex(np.array(expected)),
                               rtol=1e-6)


def test_a_tilted_body_returns_upright(top):
    _, system, regulator = top
    start = {**_start(system, [0.1, -0.05, 0.03]), "pivot_wx": 0.2, "pivot_wz": -0.1}
    run = system.simulate(3.0, initial=start, controller=regulator, rtol=1e-10, atol=1e-12,
                          samples=31)
    q = np.asarray(run.q)
    assert run.completed and _tilt(q[0]) > 0.1
    assert _tilt(q[-1]) < 1e-3  # the tilt's poles are at -3.4 1/s and faster
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)


def test_at_a_small_tilt_the_run_follows_the_linear_closed_loop(top):
    _, system, regulator = top
    tilt = 1e-3
    angles = tilt * np.array([1.0, -0.5, 0.3])
    run = system.simulate(4.0, initial=_start(system, angles), controller=regulator,
                          rtol=1e-11, atol=1e-14, samples=41)
    x = np.array([regulator.state(q, v) for q, v in zip(np.asarray(run.q),
                                                         np.asarray(run.q_dot), strict=True)])
    predicted = np.array([expm(regulator.closed_loop * t) @ np.r_[angles, 0, 0, 0]
                          for t in np.asarray(run.t)])
    assert np.abs(x - predicted).max() < 0.2 * tilt * tilt  # the nonlinear terms: O(tilt^2)


def test_an_input_that_is_not_a_force_is_refused_in_one_line(top):
    system = top[1]
    linear = system.linearize(UPRIGHT, inputs=[*HINGES, "g"])
    with pytest.raises(InputError, match="coordinates or actuators .* not 'g'") as info:
        lagrangian.lqr(linear, 1.0, 1.0)
    assert "\n" not in str(info.value)


def test_the_command_line_balances_the_body(top, cli):
    path = str(top[0])
    start = ",".join(f"{k}={v:.17g}" for k, v in _start(None, [0.1, -0.05, 0.0]).items())
    result = cli("simulate", path, "--t-end", "3", "--initial", start, "--control", "lqr",
                 "--inputs", ",".join(HINGES), "--about", "pivot__x=0,pivot__y=0,pivot__z=0",
                 "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    final = np.array([document["final_state"][name] for name in Q_NAMES])
    assert _tilt(final) < 1e-3
    assert document["control"]["inputs"] == HINGES
    assert all(re < 0 for re, _ in document["control"]["closed_loop_eigenvalues"])
    for arguments, names in ((("--inputs", "g"), "not 'g'"),
                             (("--inputs", "pivot__x", "--Q", "x"), "Q"),
                             (("--inputs", "pivot__x", "--about", "pivot_qw=1"),
                              "for the joint 'pivot' pivot__x, pivot__y, pivot__z")):
        bad = cli("simulate", path, "--t-end", "1", "--control", "lqr", *arguments)
        assert bad.code == 2 and len(bad.err.strip().splitlines()) == 1, bad.err
        assert names in bad.err


HELD = """<robot name="held"><link name="hull"/>
<link name="pod"><inertial><origin xyz="0.1 -0.05 -0.2"/><mass value="0.8"/>
<inertia ixx="0.004" ixy="0" ixz="0" iyy="0.005" iyz="0" izz="0.006"/></inertial></link>
<link name="fin"><inertial><origin xyz="0.1 0 0"/><mass value="0.3"/>
<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.002"/></inertial></link>
<joint name="hook" type="floating"><parent link="hull"/><child link="pod"/></joint>
<joint name="fin" type="continuous"><parent link="hull"/><child link="fin"/>
<origin xyz="1 0 0"/><axis xyz="0 0 1"/></joint></robot>"""


def test_a_body_held_on_a_floating_joint_between_links(tmp_path):
    """LQR on a URDF floating joint between links (its model coordinates x y z roll pitch yaw):
    at rest the trim is the pod's weight held at its joint, a force (0, 0, m g) and the moment
    c x (0, 0, m g) of its centre of mass c; from a push the regulator brings it back."""
    pytest.importorskip("yourdfpy")
    path = tmp_path / "held.urdf"
    path.write_text(HELD)
    system = lagrangian.load(path)
    names = [c.name for c in system.model.coordinates]
    linear = system.linearize(dict.fromkeys(names, 0.0), inputs=names)
    weight, centre = 0.8 * G, np.array([0.1, -0.05, -0.2])
    trim = [linear.trim[f"hook_{a}"] for a in ("x", "y", "z", "roll", "pitch", "yaw")]
    np.testing.assert_allclose(trim, np.r_[0, 0, weight, np.cross(centre, [0, 0, weight])],
                               atol=1e-9)
    regulator = lagrangian.lqr(linear, 1.0, 1.0)
    assert np.all(regulator.closed_loop_eigenvalues.real < 0)
    dynamics = system.dynamics()
    pushed = regulator._charts.charts.configuration(np.array([0.05, -0.02, 0.01, 0.1, -0.05,
                                                              0.08, 0.1]))
    run = system.simulate(6.0, initial=dict(zip(dynamics.coordinates, pushed, strict=True)),
                          controller=regulator, rtol=1e-8, atol=1e-10, samples=7)
    assert run.completed
    back = regulator.state(np.asarray(run.q)[-1], np.asarray(run.q_dot)[-1])
    assert np.abs(back).max() < 1e-3


def test_the_linearization_along_a_balanced_run_is_in_the_balls_tangent(top):
    """A(t) along the regulated run, x = [dq; v] with q = q_run (+) dq: the ball's tangent
    drifts by d(dq)/dt = dw - w(t) x dq (A's q-q block -[w(t)]x), dq_dot = dv (I), and u acts
    on the ball's three moments (control/along.py; the transition test:
    test_linearize_along_manifold.py)."""
    _, system, regulator = top
    start = _start(None, [0.1, -0.05, 0.0])
    run = system.simulate(0.5, initial=start, controller=regulator, samples=6)
    along = system.linearize_along(run)
    w = np.asarray(run.q_dot)[:, :3]
    cross = np.zeros((6, 3, 3))  # [w]x y = w x y
    cross[:, 0, 1], cross[:, 0, 2], cross[:, 1, 2] = -w[:, 2], w[:, 1], -w[:, 0]
    cross -= np.swapaxes(cross, 1, 2)
    np.testing.assert_array_equal(along.A[:, :3, :3], -cross)
    n = system.dynamics().nv
    np.testing.assert_allclose(along.A[:, :n, n:], np.broadcast_to(np.eye(n), (6, n, n)))
    assert along.state_names[:3] == ("delta_pivot_wx", "delta_pivot_wy", "delta_pivot_wz")
    assert along.inputs == ("pivot_wx", "pivot_wy", "pivot_wz") and along.B.shape == (6, 2 * n, 3)
