"""simulate through a URDF floating joint between two links (a free flyer below the root:
q its x y z in the parent's joint frame then qx qy qz qw, v the child's linear then angular
velocity relative to its parent in its own axes), on a fixed and a floating base: a body let go
at rest falls at g in the world whatever its parent does; one spun about a principal axis turns
as the closed form q0 (x) exp(w t), one tumbling keeps its angular momentum R I w and T + V;
every quaternion of norm 1 to rounding with no renormalization; and Pinocchio's aba stepped by
RK4 on its own manifold (integrate, dIntegrate) gives the same trajectory."""

from __future__ import annotations

import json

import numpy as np
import pytest

import lagrangian

G = 9.81
# a heavy post on a hinge beside a free top (the floating joint is not the root's only moving
# joint, so it is no floating base); the top's inertial at its frame's origin, principal axes
# along its own (kg m^2), the joint's frame turned
SPINNER = """<robot name='spinner'><link name='ground'/>
<link name='post'><inertial><origin xyz='0 0 0.5'/><mass value='3'/>
<inertia ixx='0.1' ixy='0' ixz='0' iyy='0.1' iyz='0' izz='0.02'/></inertial></link>
<link name='top'><inertial><origin xyz='0 0 0'/><mass value='0.7'/>
<inertia ixx='0.004' ixy='0' ixz='0' iyy='0.006' iyz='0' izz='0.009'/></inertial></link>
<joint name='hinge' type='revolute'><parent link='ground'/><child link='post'/>
<axis xyz='0 0 1'/><limit lower='-9' upper='9' effort='1' velocity='99'/></joint>
<joint name='spin' type='floating'><parent link='ground'/><child link='top'/>
<origin xyz='0.3 -0.2 2' rpy='0.4 -0.3 0.7'/></joint></robot>"""
INERTIA = np.diag([0.004, 0.006, 0.009])


def _rotation(x, y, z, w):
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


@pytest.fixture(scope="module")
def robots(tmp_path_factory):
    """Each robot's (System, path): the spinner, and tests/model's arm (fixed: the free box's
    parent and child both move) and pod (on a floating hull)."""
    from tests.model.test_urdf_floating_mid_tree import ARM, POD

    folder = tmp_path_factory.mktemp("free_simulate")
    out = {}
    for key, text, floating in (("spinner", SPINNER, False), ("arm", ARM, False),
                                ("pod", POD, True)):
        path = folder / f"{key}.urdf"
        path.write_text(text)
        out[key] = lagrangian.load(path, floating_base=floating), path
    return out


def test_a_top_let_go_falls_at_g_and_spins_as_the_closed_form(robots):
    """Spun about its major axis at 7 rad/s for 2 s (14 rad: the chart moves many times): its
    quaternion is exp(w t / 2 z), its origin (the centre of mass) falls as 1/2 g t^2 in the world,
    and |q| = 1 to rounding."""
    system, _ = robots["spinner"]
    run = system.simulate(2.0, initial={"spin_wz": 7.0, "hinge_dot": 1.0}, rtol=1e-12,
                          atol=1e-12, samples=41)
    assert run.status == "finished"
    t, q = run.t, run.q
    names = list(run.coordinates)
    iq = names.index("spin_qx")
    closed = np.column_stack([0 * t, 0 * t, np.sin(3.5 * t), np.cos(3.5 * t)])
    np.testing.assert_allclose(q[:, iq:iq + 4], closed, atol=1e-9)
    assert np.max(np.abs(np.linalg.norm(q[:, iq:iq + 4], axis=1) - 1)) < 1e-14
    dynamics = system.dynamics()
    origin = np.array([dynamics.placement(qi, "top")[:3, 3] for qi in q])
    np.testing.assert_allclose(origin, [0.3, -0.2, 2.0] - np.outer(0.5 * G * t * t, [0, 0, 1]),
                               atol=1e-8)
    np.testing.assert_allclose(q[:, names.index("hinge")], t, atol=1e-9)  # the post: unmoved


def test_a_tumbling_top_keeps_its_angular_momentum_and_energy(robots):
    """w about no principal axis (near the intermediate one, so the top flips over): L = R I w
    is constant, and T + V to the integrator's tolerance."""
    system, _ = robots["spinner"]
    w0 = np.array([0.3, 6.0, 0.4])
    start = dict(zip(("spin_wx", "spin_wy", "spin_wz"), w0, strict=True))
    run = system.simulate(3.0, initial={**start, "spin_vx": 0.4, "spin_vz": 1.0},
                          rtol=1e-12, atol=1e-12, samples=31)
    names, velocities = list(run.coordinates), list(run.velocity_names)
    iq, iw = names.index("spin_qx"), velocities.index("spin_wx")
    # in the joint's frame (fixed to the ground): R(q) I w
    momenta = [_rotation(*q[iq:iq + 4]) @ INERTIA @ w[iw:iw + 3]
               for q, w in zip(run.q, run.q_dot, strict=True)]
    np.testing.assert_allclose(momenta, np.tile(momenta[0], (len(momenta), 1)), atol=1e-10)
    assert run.q_dot[-1, iw + 1] < -5.9  # it tumbled: the spin about y flipped (Dzhanibekov)
    energy = run.energy
    assert np.max(np.abs(energy - energy[0])) < 1e-9 * abs(energy[0])
    assert np.max(np.abs(np.linalg.norm(run.q[:, iq:iq + 4], axis=1) - 1)) < 1e-14


@pytest.mark.parametrize("key, start", [
    ("arm", {"grip_wx": 2.0, "grip_vy": 0.5, "shoulder_dot": 1.0, "lid_dot": -2.0}),
    ("pod", {"pod_joint_wz": 3.0, "pod_joint_vx": 0.4, "base_wy": 1.0, "fin_joint_dot": 2.0})])
def test_an_unactuated_run_keeps_t_plus_v(robots, key, start):
    """The box's parent and child both moving (the arm), or the pod on a floating hull: T + V
    constant to the step control's tolerance over 2 s, |q| = 1 to rounding."""
    system, _ = robots[key]
    run = system.simulate(2.0, initial=start, rtol=1e-10, atol=1e-10, samples=101,
                          limits=False)  # the hinges swing past their URDF limits
    assert run.status == "finished"
    energy = run.energy
    assert np.ptp(run.kinetic_energy) > 0.1 * np.max(np.abs(run.kinetic_energy))  # it swaps
    # relative to the largest T (the box falls): measured 2e-9 at rtol 1e-10
    assert np.max(np.abs(energy - energy[0])) < 1e-8 * np.max(np.abs(run.kinetic_energy))
    stem = "grip" if key == "arm" else "pod_joint"
    iq = list(run.coordinates).index(f"{stem}_qx")
    assert np.max(np.abs(np.linalg.norm(run.q[:, iq:iq + 4], axis=1) - 1)) < 1e-14


def test_the_docs_crane_runs_and_its_hook_falls_at_g_while_the_crane_is_driven(
        tmp_path, monkeypatch, capsys):
    """docs/floating-base.md's crane block: its layout printed, and with slew and travel
    pushed the hook let go at rest falls at g in the world (1/2 g t^2 to 1e-8, x and y still),
    its quaternion unit to rounding."""
    import re

    from tests.docs_blocks import block, block_file

    monkeypatch.chdir(tmp_path)
    code = re.findall(r"```python\n(.*?)```", block("free-joint"), re.S)[0]
    namespace: dict = {}
    exec(compile(code, str(block_file("free-joint")), "exec"), namespace)
    lines = capsys.readouterr().out.splitlines()
    assert lines[:2] == ["10 9", "('hook_x', 'hook_y', 'hook_z', 'hook_qx', 'hook_qy', "
                         "'hook_qz', 'hook_qw')"]
    # its acceleration g, the run's fall, its turn in the world none
    assert lines[2:5] == ["True", "True", "True"]
    run, crane = namespace["run"], namespace["crane"]
    assert run.status == "finished" and run.t[-1] == 1.0
    hook = np.array([crane.placement(q, "hook")[:3, 3] for q in run.q])
    np.testing.assert_allclose(hook, np.tile(hook[0], (len(hook), 1))
                               - np.outer(0.5 * G * run.t ** 2, [0, 0, 1]), atol=1e-8)
    assert np.ptp(run.q[:, 0]) > 1.0  # the boom slewed above it
    assert np.max(np.abs(np.linalg.norm(run.q[:, 5:9], axis=1) - 1)) < 1e-14


def _pinocchio_rk4(model, q, v, t_end, dt):
    """Pinocchio's aba stepped by RK4 on the configuration manifold (the Munthe-Kaas form:
    q = q_n (+) theta, theta_dot = dIntegrate(q_n, theta)^-1 v), q and v at t_end."""
    pin = pytest.importorskip("pinocchio")
    data = model.createData()
    tau = np.zeros(model.nv)

    def f(q0, theta, w):
        J = pin.dIntegrate(model, q0, theta, pin.ArgumentPosition.ARG1)
        return np.linalg.solve(J, w), pin.aba(model, data, pin.integrate(model, q0, theta), w, tau)

    zero = np.zeros(model.nv)
    for _ in range(round(t_end / dt)):
        k1 = f(q, zero, v)
        k2 = f(q, dt / 2 * k1[0], v + dt / 2 * k1[1])
        k3 = f(q, dt / 2 * k2[0], v + dt / 2 * k2[1])
        k4 = f(q, dt * k3[0], v + dt * k3[1])
        theta = dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v = v + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        q = pin.integrate(model, q, theta)
    return q, v


@pytest.mark.parametrize("key", ["arm", "pod"])
def test_the_trajectory_is_pinocchios(robots, key):
    """From a moving start (the free flyer's parent and child both move on the arm; the pod's
    hull floats), 0.3 s: q and v equal Pinocchio's RK4 (dt = 2 ms) to 1e-8."""
    pin = pytest.importorskip("pinocchio")
    from tests.model.test_urdf_floating_mid_tree import _orders

    system, path = robots[key]
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer()) if key == "pod" \
        else pin.buildModelFromUrdf(str(path))
    dynamics = system.dynamics()
    iq, iv = _orders(dynamics, model)
    rng = np.random.default_rng(11)
    q0 = rng.uniform(-0.5, 0.5, dynamics.nq)
    for name in ("grip", "pod_joint", "base"):  # each quaternion unit
        if f"{name}_qx" in dynamics.coordinates:
            i = dynamics.coordinates.index(f"{name}_qx")
            q0[i:i + 4] /= np.linalg.norm(q0[i:i + 4])
    v0 = rng.uniform(-1, 1, dynamics.nv)
    start = {**dict(zip(dynamics.coordinates, q0, strict=True)),
             **{n if n not in dynamics.coordinates else f"{n}_dot": x
                for n, x in zip(dynamics.velocity_names, v0, strict=True)}}
    run = system.simulate(0.3, initial=start, rtol=1e-12, atol=1e-12, samples=2)
    np.testing.assert_allclose(run.q[0], q0, atol=1e-15)
    q, v = _pinocchio_rk4(model, q0[iq], v0[iv], 0.3, 2e-3)
    np.testing.assert_allclose(run.q[-1][iq], q, atol=1e-8)
    np.testing.assert_allclose(run.q_dot[-1][iv], v, atol=1e-8)


def test_the_command_runs_it_and_refuses_bad_starts_in_one_line(robots, cli):
    """lagrangian simulate: the free flyer's numbers named in the result (defaults: at its
    joint's origin, unturned, at rest); a non-unit quaternion, an rpy angle and a rate of its
    model coordinates each refused in one line (exit 2)."""
    _, path = robots["arm"]
    result = cli("simulate", str(path), "--t-end", "0.1", "--samples", "3", "--json",
                 "--initial", "grip_wz=2")
    assert result.code == 0, result.err
    final = json.loads(result.out)["final_state"]
    assert [k for k in final if k.startswith("grip")] == [
        "grip_x", "grip_y", "grip_z", "grip_qx", "grip_qy", "grip_qz", "grip_qw",
        "grip_vx", "grip_vy", "grip_vz", "grip_wx", "grip_wy", "grip_wz"]
    for given, says in (("grip_qw=0.5", "the floating joint 'grip' quaternion (grip_qx, grip_qy, "
                         "grip_qz, grip_qw) has norm 0.5"),
                        ("grip_roll=0.1", "'grip_roll' is not a number of the run's state"),
                        ("grip_x_dot=0.1", "'grip_x_dot' is not a number of the run's state")):
        bad = cli("simulate", str(path), "--t-end", "0.1", "--initial", given)
        lines = bad.err.strip().splitlines()
        assert bad.code == 2 and len(lines) == 1 and says in lines[0], (given, bad.err)
    floating, path = robots["pod"]
    result = cli("simulate", str(path), "--floating-base", "--t-end", "0.1", "--json",
                 "--initial", "pod_joint_wz=2")
    assert result.code == 0, result.err
    final = json.loads(result.out)["final_state"]
    assert "pod_joint_qw" in final and "base_qw" in final
    # the stop condition takes the joint's numbers
    run = floating.simulate(1.0, initial={"pod_joint_wz": 2.0}, stop_when="pod_joint_qw < 0.9")
    assert run.status == "stopped"
    assert run.q[-1, list(run.coordinates).index("pod_joint_qw")] == pytest.approx(0.9, abs=1e-7)


def test_the_drawing_turns_the_quaternion_into_the_urdfs_rpy(robots):
    """The animation's model coordinates of a run: the free flyer's rpy with
    Rz(yaw) Ry(pitch) Rx(roll) = R(q) at every sample, its x y z as they are."""
    from lagrangian.simulation.tree_state import drawing_coordinates

    system, _ = robots["arm"]
    run = system.simulate(1.0, initial={"grip_wx": 3.0, "grip_wz": -2.0, "grip_vy": 0.5},
                          samples=21)
    drawn_q, drawn_v = drawing_coordinates(system.model, run.t, run.q, run.q_dot)
    names = [c.name for c in system.model.coordinates]
    roll, pitch, yaw = (drawn_q[:, names.index(f"grip_{s}")] for s in ("roll", "pitch", "yaw"))
    for k, q in enumerate(run.q):
        c, s = np.cos, np.sin
        Rz = np.array([[c(yaw[k]), -s(yaw[k]), 0], [s(yaw[k]), c(yaw[k]), 0], [0, 0, 1]])
        Ry = np.array([[c(pitch[k]), 0, s(pitch[k])], [0, 1, 0], [-s(pitch[k]), 0, c(pitch[k])]])
        Rx = np.array([[1, 0, 0], [0, c(roll[k]), -s(roll[k])], [0, s(roll[k]), c(roll[k])]])
        np.testing.assert_allclose(Rz @ Ry @ Rx, _rotation(*q[5:9]), atol=1e-12)
    np.testing.assert_allclose(drawn_q[:, names.index("grip_x")], run.q[:, 2], atol=0)
    assert np.ptp(yaw) > 0.5 and np.all(np.isfinite(drawn_v))
