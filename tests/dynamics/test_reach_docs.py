"""docs/robot-kinematics.md, the `reach` block: its Python example runs, and its two commands
print what the library computes, obeying the laws (h_g = A_g q_dot; a wrench's torque is
-J^T w; the armature on M's diagonal)."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from tests.docs_blocks import block

import lagrangian

pytest.importorskip("yourdfpy")


def test_python_example_runs(capsys):
    code = re.findall(r"```python\n(.*?)```", block("reach"), re.S)[0]
    exec(compile(code, "reach", "exec"), {})
    assert "'armature': 0.05" in capsys.readouterr().out


def test_commands_print_the_new_quantities(cli):
    kinematics, dynamics = (line.split() for line in re.findall(r"\$ lagrangian (.*)",
                                                                 block("reach")))
    arm = lagrangian.load("two_link_arm").dynamics()
    q, v = np.array([0.3, 0.5]), np.array([1.0, 2.0])
    result = cli(*kinematics)
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert {"placement", "jacobian", "center_of_mass", "center_of_mass_jacobian"} <= set(document)
    Ag = np.array(document["centroidal_momentum_matrix"])
    np.testing.assert_allclose(Ag, arm.centroidal_momentum_matrix(q), atol=1e-12)
    np.testing.assert_allclose(document["centroidal_momentum"], Ag @ v, atol=1e-12)
    np.testing.assert_allclose(document["jacobian_dot_times_v"],
                               arm.jacobian_dot_times_v(q, v, "fore"), atol=1e-12)
    # the linear momentum is m times the centre of mass's velocity
    np.testing.assert_allclose(Ag[:3] @ v, arm.kinematics.mass()
                               * np.array(document["center_of_mass_jacobian"]) @ v, atol=1e-12)
    result = cli(*dynamics)
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["wrenches"] == {"fore": [0.0, 0.0, -10.0, 0.0, 0.0, 0.0]}
    assert document["actuators"]["shoulder"]["armature"] == 0.05
    rigid_mass = arm.mass_matrix(q)
    np.testing.assert_allclose(np.array(document["mass_matrix"]) - rigid_mass,
                               np.diag([0.05, 0.0]), atol=1e-12)
    damping = np.array([document["actuators"][c]["damping"] for c in ("shoulder", "elbow")])
    friction = np.array([document["actuators"][c]["friction"] for c in ("shoulder", "elbow")])
    J = arm.jacobian(q, "fore")
    expected = (arm.bias_forces(q, v) + damping * v + friction * np.sign(v)
                - J.T @ np.array([0, 0, -10.0, 0, 0, 0]))
    np.testing.assert_allclose(document["inverse_dynamics"], expected, atol=1e-12)


@pytest.mark.parametrize(("arguments", "message"), [
    (("--wrench", "fre=1,2,3,0,0,0"), "error: --wrench: no frame named 'fre'; did you mean 'fore'"),
    (("--wrench", "fore=1,2"),
     "error: --wrench fore: expected 6 comma-separated values (fx, fy, fz, mx, my, mz), got 2"),
    (("--wrench", "fore"), "error: --wrench: expected NAME=VALUE"),
    (("--armature", "shoulde=0.1"), "error: --armature: no joint named 'shoulde'; did you mean"),
    (("--armature", "shoulder=-1"), "error: --armature shoulder: a rotor inertia is a finite"),
])
def test_bad_wrenches_and_armatures_are_one_line(cli, arguments, message):
    result = cli("dynamics", "two_link_arm", "--a", "0,0", *arguments)
    assert result.code == 2
    assert result.err.strip().startswith(message), result.err
    assert len(result.err.strip().splitlines()) == 1


def test_a_wrench_needs_inverse_or_forward_dynamics(cli):
    result = cli("dynamics", "two_link_arm", "--wrench", "fore=0,0,1,0,0,0")
    assert result.code == 2 and "error: --wrench: a wrench acts in" in result.err


def test_floating_example_runs_and_obeys_newton(capsys):
    """The floating-reach block: C v = b - g, a push's linear momentum rate is the push."""
    code = re.findall(r"```python\n(.*?)```", block("floating-reach"), re.S)[0]
    exec(compile(code, "floating-reach", "exec"), {})
    assert capsys.readouterr().out.splitlines() == [
        "True", "(6,)", "[ 0.  0. 10.]", "['shoulder', 'elbow']"]


def test_floating_commands_print_the_library_numbers(cli):
    kinematics, dynamics = (line.split() for line in re.findall(r"\$ lagrangian (.*)",
                                                                 block("floating-reach")))
    arm = lagrangian.load("two_link_arm", floating_base=True).dynamics()
    q = np.array([0, 0, 0, 0, 0, 0.6, 0.8, 0.3, 0.5])
    v = np.array([0.1, 0, -0.2, 0.3, 0, 0.5, 1.0, 2.0])
    result = cli(*kinematics)
    assert result.code == 0, result.err
    document = json.loads(result.out)
    Ag = np.array(document["centroidal_momentum_matrix"])
    assert Ag.shape == (6, 8)
    np.testing.assert_allclose(Ag, arm.centroidal_momentum_matrix(q), atol=1e-12)
    # the linear momentum is m times the centre of mass's velocity
    np.testing.assert_allclose(Ag[:3] @ v, arm.kinematics.mass()
                               * np.array(document["center_of_mass_jacobian"]) @ v, atol=1e-12)
    np.testing.assert_allclose(document["jacobian_dot_times_v"],
                               arm.jacobian_dot_times_v(q, v, "fore"), atol=1e-12)
    result = cli(*dynamics)
    assert result.code == 0, result.err
    C = np.array(json.loads(result.out)["coriolis_matrix"])
    np.testing.assert_allclose(C @ v, arm.bias_forces(q, v) - arm.gravity(q), atol=1e-12)
