"""`lagrangian dynamics`: a URDF arm and a model file at one state; bad input exits 2."""

from __future__ import annotations

import json
import math

import pytest

pytest.importorskip("yourdfpy")

ARM = """<?xml version="1.0"?>
<robot name="pendulum_arm">
  <link name="base"/>
  <link name="rod"><inertial><origin xyz="0.5 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="tip"><inertial><origin xyz="0 0 0"/><mass value="0.5"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="rod"/>
    <axis xyz="0 -1 0"/><limit lower="-3" upper="3" effort="5" velocity="2"/>
    <dynamics damping="0.3" friction="0.1"/></joint>
  <joint name="slide" type="prismatic"><parent link="rod"/><child link="tip"/>
    <origin xyz="0.5 0 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.5" effort="5" velocity="1"/>
  </joint>
</robot>
"""


@pytest.fixture
def arm(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(ARM)
    return str(path)


def test_dynamics_of_a_urdf_arm_is_the_closed_form(cli, arm):
    # a rod (2 kg, centre 0.5 m, I = 0.1) turning about -y, a 0.5 kg slider at r = 0.5 + s
    q, s, qd, sd = 0.4, 0.1, 1.5, -0.7
    code, out, err = cli("dynamics", arm, "--q", f"{q},{s}", "--v", f"{qd},{sd}", "--json")
    assert code == 0, err
    doc = json.loads(out)
    r = 0.5 + s
    m11 = 2 * 0.25 + 0.1 + 0.5 * r**2 + 0.001
    assert doc["coordinates"] == ["hinge", "slide"]
    assert sum(doc["mass_matrix"], []) == pytest.approx([m11, 0.0, 0.0, 0.5], rel=1e-12,
                                                        abs=1e-12)
    g = 9.81
    gravity = [(2 * 0.5 + 0.5 * r) * g * math.cos(q), 0.5 * g * math.sin(q)]
    assert doc["gravity"] == pytest.approx(gravity, rel=1e-12)
    # Coriolis 2 m r r_dot theta_dot and centrifugal -m r theta_dot^2; damping ignored
    bias = [gravity[0] + 2 * 0.5 * r * sd * qd, gravity[1] - 0.5 * r * qd**2]
    assert doc["bias_forces"] == pytest.approx(bias, rel=1e-12)
    kinetic = 0.5 * m11 * qd**2 + 0.5 * 0.5 * sd**2
    assert doc["kinetic_energy"] == pytest.approx(kinetic, rel=1e-12)
    code, out, _ = cli("dynamics", arm, "--q", f"{q},{s}", "--v", f"{qd},{sd}", "--tau", "1,2",
                       "--json")
    accel = json.loads(out)["forward_dynamics"]
    assert accel == pytest.approx([(1 - bias[0]) / m11, (2 - bias[1]) / 0.5], rel=1e-10)
    code, out, _ = cli("dynamics", arm, "--q", f"{q}", "--lock", "slide=0.1", "--a", "2")
    assert code == 0
    assert f"{2 * m11 + gravity[0]:.9g}" in out
    code, out, _ = cli("derive", arm)
    assert code == 0 and "tau_hinge" in out and "tau_slide" in out


def test_dynamics_of_a_model_file(cli):
    code, out, _ = cli("dynamics", "pendulum", "--q", "0.3", "--a", "2", "--json")
    assert code == 0
    doc = json.loads(out)
    import lagrangian

    values = lagrangian.load("pendulum").parameters
    m, length, g = values["m"], values["L"], values["g"]
    assert doc["inverse_dynamics"] == pytest.approx(
        [m * length**2 * 2 + m * g * length * math.sin(0.3)], rel=1e-12)


@pytest.mark.parametrize(("args", "words"), [
    (("--q", "0.1"), "--q: expected 2 comma-separated values (hinge, slide), got 1"),
    (("--lock", "slid=0.1"), "--lock slid: no joint 'slid'"),
    (("--a", "1,1", "--tau", "1,1"), "give one"),
])
def test_bad_dynamics_input_exits_2(cli, arm, args, words):
    code, out, err = cli("dynamics", arm, *args)
    assert code == 2
    assert err.startswith("error: ") and words in err and "Traceback" not in err


def test_bad_urdf_file_exits_2(cli, tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'>")
    code, _, err = cli("derive", str(bad))
    assert code == 2 and "bad.urdf" in err and "not well-formed XML" in err


@pytest.mark.parametrize("args, what", [
    (("--set", "m=1e299,L=1e299"), "mass matrix"),   # m L^2 = 1e897
    (("--v", "1e200"), "kinetic energy"),             # m L^2 v^2 / 2
])
@pytest.mark.parametrize("json_", [False, True])
def test_a_value_beyond_floating_point_is_refused_not_printed(cli, args, what, json_):
    """inf is no mass matrix: one line, never `inf` printed nor a JSON traceback."""
    result = cli("dynamics", "pendulum", *args, *(("--json",) if json_ else ()))
    assert result.code == 2 and result.out == ""
    assert result.err.count("\n") == 1 and result.err.startswith("error: ")
    assert what in result.err and "not finite" in result.err


def test_titles_say_what_the_actuators_and_wrenches_add(cli, arm):
    """With --actuators (the hinge's damping 0.3 and friction 0.1), --armature and --wrench, M,
    the bias and the dynamics include them: the titles must say so (they printed the rigid
    body's M q_ddot + C q_dot + g over numbers that were not that)."""
    state = ("--q", "0.4,0.1", "--v", "1.5,-0.7")
    code, plain, err = cli("dynamics", arm, *state, "--a", "0,0", "--json")
    assert code == 0, err
    loaded = ("--actuators", "--armature", "slide=0.02", "--wrench", "tip=0,0,-10,0,0,0")
    code, out, err = cli("dynamics", arm, *state, "--a", "0,0", *loaded, "--json")
    assert code == 0, err
    plain, out = json.loads(plain), json.loads(out)
    # the numbers: M + diag(armature), bias + d q_dot + f_c sign(q_dot)
    assert out["mass_matrix"][1][1] - plain["mass_matrix"][1][1] == pytest.approx(0.02)
    assert out["bias_forces"][0] - plain["bias_forces"][0] == pytest.approx(0.3 * 1.5 + 0.1)
    code, text, err = cli("dynamics", arm, *state, "--a", "0,0", *loaded)
    assert code == 0, err
    titles = [line for line in text.splitlines() if not line.startswith(" ")]
    assert "mass matrix M(q) + diag(armature):" in titles
    assert "bias forces C(q, q_dot) q_dot + g(q) + d q_dot + f_c sign(q_dot):" in titles
    assert ("inverse dynamics tau = (M + diag(armature)) q_ddot + C q_dot + g + d q_dot + "
            "f_c sign(q_dot) - sum J^T w:") in titles
    code, text, err = cli("dynamics", arm, *state, "--tau", "0,0", "--wrench",
                          "tip=0,0,-10,0,0,0")
    assert code == 0, err
    assert "forward dynamics q_ddot = M^-1 (tau + sum J^T w - C q_dot - g):" in text
    assert "mass matrix M(q):" in text  # no actuators: the rigid body's titles


def test_a_floating_base_is_titled_by_its_velocity_not_q_dot(cli):
    """nv = nq - 1: the base's twist is not the rate of its coordinates."""
    code, text, err = cli("dynamics", "two_link_arm", "--floating-base", "--payload",
                          "base=50@-0.2,0.1,0", "--q", "0,0,0,0,0,0,1,0.3,0.5", "--tau",
                          "0,0,0,0,0,0,1,0")
    assert code == 0, err
    titles = [line for line in text.splitlines() if not line.startswith(" ")]
    assert "v:" in titles and "forward dynamics v_dot = M^-1 (tau - C v - g):" in titles
    assert not any("q_dot" in line for line in titles), titles


def test_kinematics_of_a_floating_base_is_titled_by_its_velocity(cli):
    code, text, err = cli("kinematics", "two_link_arm", "--floating-base", "--q",
                          "0,0,0,0,0,0,1,0.3,0.5", "--v", "0.1,0,0,0,0,0.2,1,2", "--centroidal")
    assert code == 0, err
    titles = [line for line in text.splitlines() if not line.startswith(" ")]
    assert "v:" in titles and any(t.startswith("J_dot v: [a; w_dot] at v_dot = 0") for t in titles)
    assert not any("q_dot" in line for line in titles), titles
