"""optimize on a ball joint: a free rigid body (no gravity) pivoted at its centre of mass and
turned by a moment in its own axes, rest to rest by the angle THETA about its principal axis n
(moment of inertia I_N) in T seconds. About a principal axis the turn stays on that axis (no
gyroscopic moment), so it is I_N theta_ddot = u: the least integral of u^2 dt from rest to rest
is u = I_N THETA (6/T^2 - 12 t/T^3) n, with cost 12 I_N^2 THETA^2 / T^3. The start is named as
simulate's (the ball's quaternion w x y z, its angular velocity in the body's axes), the
quaternion stays unit at the nodes, and the optimal moment replayed by simulate reaches the
goal's orientation."""

from __future__ import annotations

import json

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import InputError

pytest.importorskip("casadi")

THETA, T = 1.2, 1.5
PRINCIPAL = np.array([0.2, 0.3, 0.4])  # kg m^2, about the principal axes
_c, _s = np.cos(0.5), np.sin(0.5)  # the principal axes turned 1 rad about (1, 1, 1)/sqrt(3)
_axis = np.ones(3) / np.sqrt(3)
_K = np.array([[0, -_axis[2], _axis[1]], [_axis[2], 0, -_axis[0]], [-_axis[1], _axis[0], 0]])
ROTATION = np.eye(3) + np.sin(1.0) * _K + (1 - np.cos(1.0)) * _K @ _K
INERTIA = ROTATION @ np.diag(PRINCIPAL) @ ROTATION.T
N, I_N = ROTATION[:, 2], PRINCIPAL[2]  # the axis of the largest moment, in the body's axes
FULL = " ".join(f"{INERTIA[i, j]:.17g}" for i, j in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2),
                                                    (1, 2)))
BODY = f"""<mujoco model="turned_body"><option gravity="0 0 0"/><worldbody>
<body name="body"><joint name="ball" type="ball"/>
<inertial pos="0 0 0" mass="1" fullinertia="{FULL}"/></body></worldbody></mujoco>"""
START = np.array([np.cos(0.3), np.sin(0.3) * 0.6, 0.0, np.sin(0.3) * 0.8])  # w x y z
INPUTS = ["ball_wx", "ball_wy", "ball_wz"]
Q_NAMES, W_NAMES = ["ball_qw", "ball_qx", "ball_qy", "ball_qz"], INPUTS


def _product(p, q):
    """The quaternion product p (x) q, w x y z."""
    return np.r_[p[0] * q[0] - p[1:] @ q[1:], p[0] * q[1:] + q[0] * p[1:] + np.cross(p[1:], q[1:])]


GOAL = _product(START, np.r_[np.cos(THETA / 2), np.sin(THETA / 2) * N])  # turned in body axes


@pytest.fixture(scope="module")
def body(tmp_path_factory):
    path = tmp_path_factory.mktemp("ball_optimize") / "body.xml"
    path.write_text(BODY)
    return path, lagrangian.load(path)


@pytest.fixture(scope="module", params=[("hermite-simpson", 11, 1e-4), ("trapezoidal", 41, 1e-2)])
def turn(request, body):
    method, nodes, tolerance = request.param
    start = dict(zip(Q_NAMES, START, strict=True))
    goal = {**dict(zip(Q_NAMES, GOAL, strict=True)), **dict.fromkeys(W_NAMES, 0.0)}
    result = lagrangian.optimize(body[1], INPUTS, T, nodes, start=start, goal=goal, method=method)
    return result, tolerance


def test_the_least_effort_turn_is_the_closed_form(turn):
    result, tolerance = turn
    assert result.converged and result.defects["final_state"] < 1e-9
    assert list(result.states) == [*Q_NAMES, *W_NAMES]
    expected = 12 * I_N**2 * THETA**2 / T**3
    assert abs(result.cost - expected) <= tolerance * expected
    u = np.column_stack([result.inputs[name] for name in INPUTS])
    closed = I_N * THETA * (6 / T**2 - 12 * result.t / T**3)[:, None] * N
    assert np.abs(u - closed).max() <= 10 * tolerance * np.abs(closed).max()
    q = np.column_stack([result.states[name] for name in Q_NAMES])
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-9)  # held at the nodes
    np.testing.assert_allclose(q[0], START, atol=1e-12)


def test_simulate_replays_the_turn_to_the_goal(body, turn):
    result, tolerance = turn
    run = body[1].simulate(T, initial=result.initial_state(), controller=result.controller(),
                           rtol=1e-11, atol=1e-12, samples=len(result.t))
    final = np.asarray(run.q)[-1]
    if tolerance < 1e-3:  # Hermite-Simpson's u(t) is the closed form's quadratic: exact
        assert np.abs(final - GOAL).max() < 1e-6
    assert np.abs(final - GOAL).max() <= result.defects["replay"] + 1e-9
    assert np.abs(np.asarray(run.q_dot)[-1]).max() <= result.defects["replay"] + 1e-9


def test_a_ball_start_or_goal_is_refused_in_one_line(body):
    system = body[1]
    with pytest.raises(InputError, match=r"joint 'ball' quaternion .* norm 2") as info:
        lagrangian.optimize(system, INPUTS, T, 5, goal={"ball_qw": 2.0, "ball_qx": 0,
                                                        "ball_qy": 0, "ball_qz": 0})
    with pytest.raises(InputError, match=r"start: .*ball.* norm 0\.5"):
        lagrangian.optimize(system, INPUTS, T, 5, start={"ball_qw": 0.5})
    with pytest.raises(InputError, match="'ball__x' is an Euler angle .* give its quaternion"):
        lagrangian.optimize(system, INPUTS, T, 5, start={"ball__x": 0.1})
    assert "\n" not in str(info.value)


def test_the_command_line_turns_the_ball(body, cli):
    goal = ",".join(f"{name}={value:.17g}" for name, value in zip(Q_NAMES, GOAL, strict=True))
    start = ",".join(f"{name}={value:.17g}" for name, value in zip(Q_NAMES, START, strict=True))
    result = cli("optimize", str(body[0]), "--from", start, "--to", goal,
                 "--to", "ball_wx=0,ball_wy=0,ball_wz=0", "--t-final", str(T), "--nodes", "11",
                 "--method", "hermite-simpson", "--bound", "ball_wx=-5:5", "--input", "ball_wx",
                 "--input", "ball_wy", "--input", "ball_wz", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["converged"]
    assert abs(document["cost"] - 12 * I_N**2 * THETA**2 / T**3) < 1e-4 * document["cost"]
    bad = cli("optimize", str(body[0]), "--to", "ball_qw=2,ball_qx=0,ball_qy=0,ball_qz=0",
              "--input", "ball_wx", "--nodes", "5")
    assert bad.code == 2 and len(bad.err.strip().splitlines()) == 1 and "ball" in bad.err


FREE_BODY = {  # a body of mass 2 kg on a joint with its own position and turn, no gravity
    "mjcf free joint": ("pod.xml", """<mujoco model="pod"><option gravity="0 0 0"/><worldbody>
<body name="pod"><freejoint name="grip"/>
<inertial pos="0 0 0" mass="2" diaginertia="0.2 0.3 0.4"/></body></worldbody></mujoco>""",
                        ("grip_x", "grip_qw", "grip_qz"),
                        ["grip_x", "grip_y", "grip_z", "grip_wx", "grip_wy", "grip_wz"]),
    "urdf floating joint between links": ("pod.urdf", """<robot name="pod"><link name="hull"/>
<link name="pod"><inertial><origin xyz="0 0 0"/><mass value="2"/>
<inertia ixx="0.2" ixy="0" ixz="0" iyy="0.3" iyz="0" izz="0.4"/></inertial></link>
<link name="fin"><inertial><mass value="0.5"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01"
iyz="0" izz="0.01"/></inertial></link><joint name="fin" type="continuous"><parent link="hull"/>
<child link="fin"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/></joint>
<joint name="grip" type="floating"><parent link="hull"/><child link="pod"/></joint></robot>""",
                                          ("grip_x", "grip_qw", "grip_qz"),
                                          ["grip_vx", "grip_vy", "grip_vz", "grip_wx",
                                           "grip_wy", "grip_wz"]),
}


@pytest.mark.parametrize("kind", list(FREE_BODY))
def test_a_free_body_moved_and_turned_rest_to_rest(kind, tmp_path):
    """About its centre of mass a free body's translation and turn decouple (Newton-Euler): the
    least effort to move it by 0.3 m along x while turning it by THETA about its principal z
    is 12 (m^2 0.3^2 + I_z^2 THETA^2) / T^3, its force and moment in its own axes (the URDF's
    hull also holds a fin on a hinge, left at rest)."""
    if kind.startswith("urdf"):
        pytest.importorskip("yourdfpy")
    name, text, (x, qw, qz), inputs = FREE_BODY[kind]
    path = tmp_path / name
    path.write_text(text)
    system = lagrangian.load(path)
    if kind.startswith("urdf"):
        system = system.with_parameters(g=0.0)
    states = system.to_casadi(inputs=inputs).states
    goal = {**dict.fromkeys(states, 0.0), x: 0.3, qw: np.cos(THETA / 2), qz: np.sin(THETA / 2)}
    result = lagrangian.optimize(system, inputs, T, 11, goal=goal, method="hermite-simpson")
    assert result.converged
    expected = 12 * (2.0**2 * 0.3**2 + 0.4**2 * THETA**2) / T**3
    assert abs(result.cost - expected) <= 1e-4 * expected
    run = system.simulate(T, initial=result.initial_state(), controller=result.controller(),
                          rtol=1e-11, atol=1e-12)
    final = dict(zip(run.coordinates, np.asarray(run.q)[-1], strict=True))
    # u(t) between the nodes is the scheme's quadratic: exact for the slides' world force,
    # a force in the turning body's axes is that to the scheme's error
    for name, value in ((x, 0.3), (qz, np.sin(THETA / 2))):
        assert abs(final[name] - value) <= min(result.defects["replay"] + 1e-9, 1e-5)
