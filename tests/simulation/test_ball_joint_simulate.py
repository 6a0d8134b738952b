"""simulate through ball joints (MuJoCo's, w x y z, the angular velocity in the body's axes), on
a fixed and a floating base (simulation/floating.py, tree_state.py): a free spherical pendulum
keeps T + V and the vertical angular momentum (both in closed form from the file's numbers); a
ball pendulum started in a plane stays in it and swings as the same body on a hinge; MuJoCo's
own RK4 trajectories (fixed and floating) reproduced to their integration error."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import LagrangianError

# the bob hangs 0.6 m below its pivot (0.1 m above the body's origin), off axis, with a full
# inertia tensor about its centre of mass (kg m^2)
PENDULUM = """<mujoco model="spherical_pendulum"><worldbody><body name="bob" pos="0 0 1">
<joint name="ball" type="{kind}" pos="0 0 0.1" axis="0 1 0"/>
<inertial pos="{centre} -0.5" mass="1.3" fullinertia="{inertia}"/></body></worldbody></mujoco>"""
MASS, PIVOT, CENTRE = 1.3, np.array([0.0, 0.0, 1.1]), np.array([0.05, 0.02, -0.6])
I_CENTRE = np.array([[0.04, 0.001, -0.002], [0.001, 0.03, 0.003], [-0.002, 0.003, 0.02]])
# about the pivot: parallel axes, r the centre from the pivot in the body's axes
J_PIVOT = I_CENTRE + MASS * (CENTRE @ CENTRE * np.eye(3) - np.outer(CENTRE, CENTRE))

# a ball (its anchor off the body's origin), then a hinge about (0, 1, 1) in a turned body
ARM = """<mujoco model="arm"><option integrator="RK4" timestep="{dt}"/><worldbody>
<body name="upper" pos="0 0 1">{free}<joint name="shoulder" type="ball" pos="0 0 0.05"/>
<geom type="capsule" fromto="0 0 0 0.05 0 -0.3" size="0.03" mass="1"/>
<body name="fore" pos="0 0 -0.3" euler="0 20 10"><joint name="elbow" axis="0 1 1"/>
<geom type="box" size="0.02 0.03 0.15" pos="0 0 -0.15" mass="0.5"/>
</body></body></worldbody></mujoco>"""
# the floating one: a 4 kg trunk on a free joint (full inertia) carries the arm
LIMB = """<mujoco model="limb"><option integrator="RK4" timestep="{dt}"/><worldbody>
<body name="trunk" pos="0 0 0.5"><freejoint name="root"/>
<inertial pos="0.01 0.02 -0.01" mass="4" fullinertia="0.1 0.2 0.25 0.01 -0.02 0.03"/>
<body name="arm" pos="0.2 0.1 0" euler="10 0 20"><joint name="shoulder" type="ball" pos="0 0 0.03"/>
<geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03"/>
<body name="forearm" pos="0 0 -0.3"><joint name="elbow" axis="1 1 0"/>
<geom type="box" size="0.02 0.03 0.15" pos="0 0 -0.15"/></body></body></body>
</worldbody></mujoco>"""


def _load(tmp_path_factory, text: str, name: str, **options):
    path = tmp_path_factory.mktemp("ball_simulate") / f"{name}.xml"
    path.write_text(text)
    return lagrangian.load(path, **options), path


def _rotation(q):
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


@pytest.fixture(scope="module")
def pendulum(tmp_path_factory):
    inertia = "0.04 0.03 0.02 0.001 -0.002 0.003"
    return _load(tmp_path_factory, PENDULUM.format(kind="ball", centre="0.05 0.02", inertia=inertia),
                 "spherical")[0]


def test_a_free_spherical_pendulum_keeps_its_energy_and_vertical_angular_momentum(pendulum):
    """T + V = 1/2 w.J_O w + m g z_c and L_z = (R J_O w)_z, from the file's numbers."""
    q0 = np.array([0.9, 0.3, -0.2, 0.1]) / np.linalg.norm([0.9, 0.3, -0.2, 0.1])
    w0 = np.array([1.5, -0.7, 2.0])
    names = ("ball_qw", "ball_qx", "ball_qy", "ball_qz", "ball_wx", "ball_wy", "ball_wz")
    run = pendulum.simulate(2.0, initial=dict(zip(names, [*q0, *w0], strict=True)),
                            rtol=1e-11, atol=1e-11, samples=41)
    assert run.status == "finished"
    assert run.coordinates == ("ball_qw", "ball_qx", "ball_qy", "ball_qz")
    assert tuple(run.columns())[5:8] == ("ball_wx", "ball_wy", "ball_wz")
    q, w = run.q, run.q_dot
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, rtol=0, atol=1e-14)
    assert np.linalg.norm(q[-1] - q0) > 0.1  # it swung
    energy = [0.5 * wi @ J_PIVOT @ wi + MASS * 9.81 * (PIVOT + _rotation(qi) @ CENTRE)[2]
              for qi, wi in zip(q, w, strict=True)]
    momentum = [(_rotation(qi) @ J_PIVOT @ wi)[2] for qi, wi in zip(q, w, strict=True)]
    np.testing.assert_allclose(energy, energy[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(momentum, momentum[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(run.energy, energy, rtol=0, atol=1e-9)  # the run's own T + V


@pytest.fixture(scope="module")
def planar(tmp_path_factory):
    # the centre in the x-z plane and y a principal axis: a swing about y stays in that plane
    inertia = "0.04 0.03 0.02 0 0.001 0"  # ixx iyy izz ixy ixz iyz
    return tuple(_load(tmp_path_factory, PENDULUM.format(kind=kind, centre="0.05 0",
                                                         inertia=inertia),
                       kind)[0] for kind in ("ball", "hinge"))


def test_a_ball_pendulum_started_in_a_plane_stays_in_it_and_swings_as_the_hinge_one(planar):
    ball, hinge = planar
    theta0, rate0 = 1.2, -0.5  # rad, rad/s about y
    swung = ball.simulate(3.0, initial={"ball_qw": np.cos(theta0 / 2),
                                        "ball_qy": np.sin(theta0 / 2), "ball_wy": rate0},
                          rtol=1e-11, atol=1e-11, samples=61)
    hinged = hinge.simulate(3.0, initial={"ball": theta0, "ball_dot": rate0}, rtol=1e-11,
                            atol=1e-11, samples=61)
    assert swung.status == hinged.status == "finished"
    q, w = swung.q, swung.q_dot
    np.testing.assert_allclose(q[:, [1, 3]], 0.0, rtol=0, atol=1e-12)  # no turn out of it
    np.testing.assert_allclose(w[:, [0, 2]], 0.0, rtol=0, atol=1e-12)
    angle = np.unwrap(2 * np.arctan2(q[:, 2], q[:, 0]))
    assert np.ptp(angle) > 2.0  # a large swing, far from the linear one
    np.testing.assert_allclose(angle, hinged.q[:, 0], rtol=0, atol=1e-8)
    np.testing.assert_allclose(w[:, 1], hinged.q_dot[:, 0], rtol=0, atol=1e-8)


def _mujoco_run(mujoco, text: str, qpos, qvel, t_end: float, dt: float):
    model = mujoco.MjModel.from_xml_string(text.format(dt=repr(dt), free=""))
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = qpos, qvel
    for _ in range(round(t_end / dt)):
        mujoco.mj_step(model, data)
    return data.qpos.copy(), data.qvel.copy()


@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
def test_the_trajectory_is_mujocos_to_its_rk4_error(tmp_path_factory, floating):
    """MuJoCo's RK4 (mj_integratePos on the ball's quaternion) at dt and dt/2: its error at
    dt/2 is about their difference / 15 (fourth order); ours (DOP853, rtol 1e-11) is within."""
    mujoco = pytest.importorskip("mujoco")
    from lagrangian.model.mjcf_state import mujoco_layout

    text = LIMB if floating else ARM
    system, _ = _load(tmp_path_factory, text.format(dt=0.01, free=""), "robot",
                      **({"floating_base": True} if floating else {}))
    layout = mujoco_layout(system)
    rng = np.random.default_rng(3)
    qpos = rng.uniform(-1, 1, layout.nq)
    qvel = rng.uniform(-1.5, 1.5, layout.nv)
    base = 7 if floating else 0
    if floating:
        qpos[3:7] /= np.linalg.norm(qpos[3:7])
    qpos[base:base + 4] /= np.linalg.norm(qpos[base:base + 4])
    t_end = 0.5
    coarse = _mujoco_run(mujoco, text, qpos, qvel, t_end, 5e-4)
    fine = _mujoco_run(mujoco, text, qpos, qvel, t_end, 2.5e-4)
    q, v = layout.from_mujoco(qpos, qvel)
    d = system.dynamics()
    start = {**dict(zip(d.coordinates, q, strict=True)),
             **{(n if n not in d.coordinates else f"{n}_dot"): x
                for n, x in zip(d.velocity_names, v, strict=True)}}
    run = system.simulate(t_end, initial=start, rtol=1e-11, atol=1e-11, samples=2)
    assert run.status == "finished"
    ours = layout.to_mujoco(run.q[-1], run.q_dot[-1])
    for k in range(2):  # qpos, then qvel
        error = np.abs(fine[k] - coarse[k]).max() / 15
        assert np.abs(ours[k] - fine[k]).max() <= 3 * error + 1e-10, k
    assert np.abs(ours[0] - qpos).max() > 0.05  # it moved


def test_what_a_ball_joint_does_not_take_is_refused_in_one_line(tmp_path_factory):
    system, _ = _load(tmp_path_factory, ARM.format(dt=0.01, free=""), "arm")
    cases = [({"initial": {"shoulder__x": 0.1}}, "'shoulder__x' is an Euler angle of the "
              "ball joint 'shoulder'"),
             ({"initial": {"shoulder_qw": 0.5}}, "ball joint 'shoulder' quaternion"),
             ({"initial": {"shoulder_qq": 0.5}}, "'shoulder_qq' is not a coordinate"),
             ({"stop_when": "shoulder__y > 1"}, "'shoulder__y' is an Euler angle"),
             ({"limits": "clamp"}, "is not clamped")]
    for options, message in cases:
        with pytest.raises(LagrangianError, match=message) as caught:
            system.simulate(0.1, **options)
        assert "\n" not in str(caught.value)


def test_a_stop_condition_on_a_ball_quaternion_ends_the_run_there(tmp_path_factory):
    system, _ = _load(tmp_path_factory, ARM.format(dt=0.01, free=""), "arm")
    run = system.simulate(2.0, initial={"shoulder_wx": 3.0}, stop_when="shoulder_qw < 0.9")
    assert run.status == "stopped"
    assert run.q[-1, 0] == pytest.approx(0.9, abs=1e-7)


def test_a_controllers_moment_on_a_ball_does_the_work_the_energy_gains(pendulum):
    """u = a moment in the body's axes (N m): T + V - h0 = int u.w dt (the work balance, its
    integral by Simpson's rule on the samples: 401 of them close it to about 1e-9 J)."""
    run = pendulum.simulate(1.0, initial={"ball_wx": 1.0},
                            controller=lambda t, q, v: np.array([0.3, -0.2, 0.5 * np.cos(t)]),
                            rtol=1e-11, atol=1e-11, samples=401)
    assert run.status == "finished" and run.invariant == "work_balance"
    assert np.ptp(run.energy) > 0.1  # the moment did work
    assert abs(run.balance).max() < 1e-8
    np.testing.assert_allclose(np.linalg.norm(run.q, axis=1), 1.0, rtol=0, atol=1e-14)


def test_a_hinges_position_limit_beside_a_ball_still_ends_the_run(tmp_path_factory):
    """The elbow's range (30 degrees, MJCF's default unit) stops a run that swings it there."""
    text = ARM.format(dt=0.01, free="").replace(
        'axis="0 1 1"/>', 'axis="0 1 1" limited="true" range="-30 30"/>')
    system, _ = _load(tmp_path_factory, text, "limited")
    run = system.simulate(2.0, initial={"elbow_dot": 4.0, "shoulder_wz": 1.0})
    assert run.status == "limit" and "joint 'elbow'" in run.message
    assert abs(run.q[-1, 4]) == pytest.approx(np.radians(30), abs=1e-7)
    with pytest.raises(LagrangianError, match="joint 'elbow' .* starts at 0.7"):
        system.simulate(0.1, initial={"elbow": 0.7})


def test_the_drawing_turns_the_balls_hinges_to_the_quaternions_rotation(tmp_path_factory):
    """The animation draws the model's bodies, a ball as three hinges x, y, z: their angles
    give Rx Ry Rz = R(q) at every sample, and the rates are the angles' (by differences)."""
    from lagrangian.simulation.tree_state import drawing_coordinates

    system, _ = _load(tmp_path_factory, ARM.format(dt=0.01, free=""), "drawn")
    run = system.simulate(1.0, initial={"shoulder_wx": 2.0, "shoulder_wy": -1.0,
                                        "shoulder_wz": 3.0, "elbow_dot": 1.0}, samples=201)
    q, v = drawing_coordinates(system.model, run.t, run.q, run.q_dot)
    assert [c.name for c in system.model.coordinates] == ["shoulder__x", "shoulder__y",
                                                           "shoulder__z", "elbow"]

    def turn(axis, angle):
        c, s = np.cos(angle), np.sin(angle)
        i, j = [k for k in range(3) if k != axis]
        R = np.eye(3)
        R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
        return R if axis != 1 else R.T  # about y the sine's sign is the other way

    for k in range(0, 201, 10):
        R = turn(0, q[k, 0]) @ turn(1, q[k, 1]) @ turn(2, q[k, 2])
        np.testing.assert_allclose(R, _rotation(run.q[k, :4]), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(q[:, 3], run.q[:, 4])  # the elbow as it is
    np.testing.assert_array_equal(v[:, 3], run.q_dot[:, 3])
    assert np.abs(np.diff(q[:, :3], axis=0)).max() < 0.5  # unwrapped: no jump of 2 pi


def test_a_run_goes_on_from_its_last_state(pendulum):
    """Two runs of 1 s, the second from the first's last_state, end where one of 2 s does."""
    start = {"ball_wx": 1.5, "ball_wz": 2.0}
    options = {"rtol": 1e-11, "atol": 1e-11, "samples": 3}
    whole = pendulum.simulate(2.0, initial=start, **options)
    first = pendulum.simulate(1.0, initial=start, **options)
    second = pendulum.simulate(2.0, initial=first.last_state, **options)
    assert second.t[0] == 1.0
    np.testing.assert_allclose(second.q[-1], whole.q[-1], rtol=0, atol=1e-8)
    np.testing.assert_allclose(second.q_dot[-1], whole.q_dot[-1], rtol=0, atol=1e-8)


@pytest.mark.parametrize("method", ["DOP853", "Radau"])
def test_a_fast_spin_turns_at_the_closed_forms_rate_through_many_charts(tmp_path_factory,
                                                                         method):
    """A body symmetric about the vertical spun at w = 10 rad/s about it: q = (cos wt/2, 0, 0,
    sin wt/2) at every sample, through about 20 moves of the ball's chart (one per radian)."""
    text = PENDULUM.format(kind="ball", centre="0 0", inertia="0.04 0.04 0.02 0 0 0")
    system, _ = _load(tmp_path_factory, text, "spin")
    run = system.simulate(2.0, initial={"ball_wz": 10.0}, method=method, rtol=1e-11,
                          atol=1e-11, samples=41)
    assert run.status == "finished"
    expected = np.stack([np.cos(5 * run.t), 0 * run.t, 0 * run.t, np.sin(5 * run.t)], -1)
    np.testing.assert_allclose(run.q, expected, rtol=0, atol=1e-8)
    np.testing.assert_allclose(run.q_dot, [[0.0, 0.0, 10.0]] * len(run.t), rtol=0, atol=1e-8)
