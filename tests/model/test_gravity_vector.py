"""Gravity as a vector (issue 27): ``load(path, gravity=(gx, gy, gz))``, System.with_gravity and
``--gravity GX,GY,GZ``: a closed form for the two-link arm under any gravity, Pinocchio's
``model.gravity`` for a spatial arm on every backend, and bad input refused in one line."""

from __future__ import annotations

import ctypes
import json
import math
import shutil
import subprocess

import numpy as np
import pytest

import lagrangian

pytest.importorskip("yourdfpy")

# two_link_arm: joints about -y (a positive angle lifts), upper arm 2 kg with its centre at
# 0.5 m, forearm 1.5 kg with its centre 0.4 m past the 1 m upper arm.
M1, C1, M2, L1, C2 = 2.0, 0.5, 1.5, 1.0, 0.4


def closed_form_gravity(q, g):
    """dV/dq with V = -(g_x X + g_z Z), X and Z the first moments m x and m z of the arm."""
    q1, q2 = q
    gx, _, gz = g  # a force along y has no moment about the joints' y axes
    dX = [-(M1 * C1 + M2 * L1) * math.sin(q1) - M2 * C2 * math.sin(q1 + q2),
          -M2 * C2 * math.sin(q1 + q2)]
    dZ = [(M1 * C1 + M2 * L1) * math.cos(q1) + M2 * C2 * math.cos(q1 + q2),
          M2 * C2 * math.cos(q1 + q2)]
    return [-(gx * dX[i] + gz * dZ[i]) for i in range(2)]


@pytest.mark.parametrize("g", [(0, 0, -9.81), (9.81, 0, 0), (3.0, -2.0, -9.0), (0, 5.0, 0)])
def test_the_arms_gravity_torques_are_the_closed_form(g):
    system = lagrangian.load("two_link_arm", gravity=g)
    assert system.parameters["g"] == pytest.approx(math.hypot(*g), rel=1e-15)
    q = np.array([0.4, -1.2])
    for f in (system.dynamics(), system.dynamics(backend="numpy")):
        np.testing.assert_allclose(f.gravity(q), closed_form_gravity(q, g), rtol=1e-12,
                                   atol=1e-12)


def test_with_gravity_equals_load_with_gravity_and_the_default_is_down():
    down = lagrangian.load("two_link_arm")
    q = np.array([0.3, 0.2])
    np.testing.assert_array_equal(down.with_gravity((0, 0, -9.81)).dynamics().gravity(q),
                                  down.dynamics().gravity(q))
    wall = down.with_gravity((-9.81, 0, 0))
    np.testing.assert_allclose(wall.dynamics().gravity(q),
                               lagrangian.load("two_link_arm", gravity=(-9.81, 0, 0))
                               .dynamics().gravity(q), rtol=1e-15)
    none = down.with_gravity((0, 0, 0)).dynamics()
    np.testing.assert_array_equal(none.gravity(q), [0.0, 0.0])


def test_the_standalone_c_carries_the_direction():
    tilted = lagrangian.load("two_link_arm", gravity=(9.81, 0, 0)).to_c(prefix="arm").source
    down = lagrangian.load("two_link_arm").to_c(prefix="arm").source
    assert tilted != down  # the direction is compiled in (a rebuild keyed by it)


@pytest.mark.parametrize("gravity, words", [
    ((1.0, 2.0), "three numbers"), ((0, 0, float("nan")), "finite"), ("0,0,-9.81", "three numbers"),
])
def test_bad_gravity_is_refused(gravity, words):
    with pytest.raises(lagrangian.InputError, match=words) as raised:
        lagrangian.load("two_link_arm", gravity=gravity)
    assert raised.value.field == "gravity"


def test_a_model_without_gravity_has_none_to_turn():
    with pytest.raises(lagrangian.InputError, match="declares no gravity"):
        lagrangian.load("pendulum").with_gravity((0, 0, -9.81))  # its V is written out


def test_cli_gravity_vector(cli):
    result = cli("dynamics", "two_link_arm", "--q", "0.4,-1.2", "--gravity", "9.81,0,0", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    np.testing.assert_allclose(document["gravity"], closed_form_gravity((0.4, -1.2), (9.81, 0, 0)),
                               rtol=1e-12)
    # weightless: a robot at rest stays at rest
    result = cli("simulate", "two_link_arm", "--t-end", "0.5", "--initial", "shoulder=0.3",
                 "--gravity", "0,0,0", "--json")
    assert result.code == 0, result.err
    final = json.loads(result.out)["final_state"]
    assert final["shoulder"] == pytest.approx(0.3, abs=1e-12) and final["elbow"] == pytest.approx(0)
    assert final["shoulder_dot"] == pytest.approx(0, abs=1e-12)
    # wall-mounted, gravity along +x: hanging straight along +x is the stable equilibrium
    result = cli("equilibria", "two_link_arm", "--gravity", "9.81,0,0", "--json")
    assert result.code == 0, result.err
    found = json.loads(result.out)["equilibria"]
    straight = [e for e in found if max(abs(x) for x in e["coordinates"].values()) < 1e-9]
    assert straight and straight[0]["stable"]
    assert cli("modes", "two_link_arm", "--gravity", "9.81,0,0").code == 0


@pytest.mark.parametrize("text, words", [("1,2", "expected 3"), ("a,0,0", "--gravity"),
                                         ("0,0,-9.81m", "--gravity")])
def test_cli_bad_gravity_exits_2(cli, text, words):
    result = cli("dynamics", "two_link_arm", "--gravity", text)
    assert result.code == 2 and result.err.count("\n") == 1
    assert result.err.startswith("error: ") and words in result.err


def test_cli_gravity_on_a_model_without_gravity_exits_2(cli):
    result = cli("dynamics", "pendulum", "--gravity", "0,0,-9.81")
    assert result.code == 2 and "declares no gravity" in result.err


@pytest.mark.skipif(not (shutil.which("gcc") or shutil.which("cc")), reason="no C compiler")
def test_codegen_with_gravity_gives_the_tilted_torques(cli, tmp_path):

    result = cli("codegen", "two_link_arm", "--out", str(tmp_path), "--name", "arm",
                 "--gravity", "9.81,0,0")
    assert result.code == 0, result.err
    library = tmp_path / "arm.so"
    subprocess.run([shutil.which("gcc") or shutil.which("cc"), "-std=c99", "-O2", "-shared",
                    "-fPIC", str(tmp_path / "arm.c"), "-o", str(library), "-lm"], check=True)
    c = ctypes.CDLL(str(library))
    vec = ctypes.c_double * 2
    params = (ctypes.c_double * 3).in_dll(c, "arm_parameters")
    assert params[0] == pytest.approx(9.81)  # the magnitude g, a runtime parameter
    out = vec()
    c.arm_gravity(vec(0.4, -1.2), params, out)
    np.testing.assert_allclose(list(out), closed_form_gravity((0.4, -1.2), (9.81, 0, 0)),
                               rtol=1e-12)
