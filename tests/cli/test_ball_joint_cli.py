"""`lagrangian dynamics` and `simulate` on an MJCF robot with a ball joint: q and v in the names
the tree uses (the ball's w x y z quaternion, its angular velocity in the body's axes), M and FD
as MuJoCo's at the same qpos, a symmetric arm spinning about the vertical at the closed form's
rate; what a ball does not take, one line naming it (exit 2)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

# a ball shoulder, then an elbow about y; the capsules along -z: symmetric about the vertical
ARM = """<mujoco model="arm"><worldbody><body name="upper" pos="0 0 1">
<joint name="shoulder" type="ball"/>
<geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03" mass="1"/>
<body name="fore" pos="0 0 -0.3"><joint name="elbow" axis="0 1 0"/>
<geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03" mass="0.5"/>
</body></body></worldbody></mujoco>"""


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    path = tmp_path_factory.mktemp("ball_cli") / "arm.xml"
    path.write_text(ARM)
    return str(path)


def test_dynamics_takes_the_quaternion_and_gives_mujocos_mass_matrix_and_fd(cli, arm):
    mujoco = pytest.importorskip("mujoco")
    qpos = np.array([0.8, 0.2, -0.4, 0.3, 0.6])
    qpos[:4] /= np.linalg.norm(qpos[:4])
    qvel = np.array([0.5, -1.0, 2.0, 0.7])
    code, out, err = cli("dynamics", arm, "--q", ",".join(f"{x:.17g}" for x in qpos),
                         "--v", ",".join(f"{x:.17g}" for x in qvel), "--tau", "0,0,0,0", "--json")
    assert code == 0, err
    found = json.loads(out)
    assert found["coordinates"] == ["shoulder_qw", "shoulder_qx", "shoulder_qy", "shoulder_qz",
                                    "elbow"]
    assert found["velocities"] == ["shoulder_wx", "shoulder_wy", "shoulder_wz", "elbow"]
    model = mujoco.MjModel.from_xml_string(ARM)
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = qpos, qvel
    mujoco.mj_forward(model, data)
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    np.testing.assert_allclose(found["mass_matrix"], M, rtol=0, atol=1e-9)
    np.testing.assert_allclose(found["forward_dynamics"], data.qacc, rtol=0, atol=1e-9)


def test_dynamics_defaults_to_the_unturned_ball_and_names_a_bad_q(cli, arm):
    code, out, err = cli("dynamics", arm, "--json")
    assert code == 0, err
    assert json.loads(out)["q"] == [1.0, 0.0, 0.0, 0.0, 0.0]
    code, _, err = cli("dynamics", arm, "--q", "1,0,0,0.1")  # the Euler hinges' count
    assert code == 2 and err.count("\n") == 1
    assert "shoulder_qw, shoulder_qx, shoulder_qy, shoulder_qz, elbow" in err
    code, _, err = cli("dynamics", arm, "--q", "0.9,0.1,0,0,0.1")
    assert code == 2 and err.count("\n") == 1 and "ball joint 'shoulder'" in err


def test_a_symmetric_arm_spins_about_the_vertical_at_its_start_rate(cli, arm, tmp_path):
    """Spun at w about its axis of symmetry it keeps turning: q = (cos wt/2, 0, 0, sin wt/2),
    so q_z = 1/2 (a sixth of a turn) at t = pi/(3 w)."""
    table = tmp_path / "spin.csv"
    code, out, err = cli("simulate", arm, "--t-end", "2", "--initial", "shoulder_wz=2",
                         "--stop-when", "shoulder_qz > 0.5", "--out", str(table), "--json")
    assert code == 0, err
    found = json.loads(out)
    assert found["status"] == "stopped"
    assert found["t_final"] == pytest.approx(math.pi / 6, abs=1e-9)
    final = found["final_state"]
    assert final["shoulder_qw"] == pytest.approx(math.sqrt(3) / 2, abs=1e-9)
    assert final["shoulder_wz"] == pytest.approx(2.0, abs=1e-9)
    header = table.read_text().splitlines()[0].split(",")
    assert header[:10] == ["t", "shoulder_qw", "shoulder_qx", "shoulder_qy", "shoulder_qz",
                           "elbow", "shoulder_wx", "shoulder_wy", "shoulder_wz", "elbow_dot"]


@pytest.mark.parametrize("arguments, names", [
    (("--initial", "shoulder__x=0.2"), "'shoulder__x' is an Euler angle of the ball joint"),
    (("--initial", "shoulder_qw=0.5"), "ball joint 'shoulder' quaternion"),
    (("--control", "lqr", "--inputs", "g"), "LQR drives its coordinates or actuators"),
])
def test_simulate_refuses_what_a_ball_does_not_take_in_one_line(cli, arm, arguments, names):
    code, out, err = cli("simulate", arm, "--t-end", "0.1", *arguments)
    assert code == 2 and out == "" and err.count("\n") == 1, err
    assert names in err


def test_regressor_rows_are_the_velocities_and_y_pi_is_mujocos_inverse_dynamics(cli, arm):
    """`regressor` on a ball robot: Y's rows are v's (the ball's three moments, the elbow's
    torque), and tau = Y pi at a moving state equals MuJoCo's mj_rne (qfrc_bias + M qacc)."""
    mujoco = pytest.importorskip("mujoco")
    qpos = np.array([0.7, -0.1, 0.5, 0.2, -0.4])
    qpos[:4] /= np.linalg.norm(qpos[:4])
    qvel, qacc = np.array([0.3, -0.8, 1.5, 0.6]), np.array([1.0, 0.5, -0.2, 0.3])
    text = [",".join(f"{x:.17g}" for x in x_) for x_ in (qpos, qvel, qacc)]
    code, out, err = cli("regressor", arm, "--q", text[0], "--v", text[1], "--a", text[2],
                         "--json")
    assert code == 0, err
    found = json.loads(out)
    assert found["velocities"] == ["shoulder_wx", "shoulder_wy", "shoulder_wz", "elbow"]
    model = mujoco.MjModel.from_xml_string(ARM)
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:], data.qacc[:] = qpos, qvel, qacc
    mujoco.mj_inverse(model, data)
    np.testing.assert_allclose(found["tau"], data.qfrc_inverse, atol=1e-9)
    code, out, err = cli("regressor", arm)  # the default state: the ball unturned, at rest
    assert code == 0 and "Velocities (Y's rows): shoulder_wx" in out, err
