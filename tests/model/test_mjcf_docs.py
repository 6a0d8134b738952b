"""docs/bridges.md's MuJoCo layout blocks run, and what they print is the physics: a velocity
along the world's x seen from a body turned 45 degrees about z, and MuJoCo's qacc as ours; a
free joint in MuJoCo's own layout, its state copied unchanged, and its commands."""

from __future__ import annotations

import json
import re
import shlex

import numpy as np
import pytest

from docs_blocks import block


def test_the_layout_block_converts_a_drones_state(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (code,) = re.findall(r"```python\n(.*?)```", block("bridges-mujoco-layout", "bridges.md"), re.S)
    namespace: dict = {}
    exec(code, namespace)  # noqa: S102 - our own documentation
    v, a, q = namespace["v"], namespace["a"], namespace["q"]
    assert v[:3] == pytest.approx([np.sqrt(0.5), -np.sqrt(0.5), 0], abs=1e-6)
    forward = namespace["drone"].dynamics(actuators=True).forward_dynamics(q, v, np.zeros(7))
    assert np.allclose(forward, a, rtol=0, atol=1e-9)
    # the tilt joint's armature (1e-3 kg m^2) is in MuJoCo's M and in ours
    assert namespace["model"].dof_armature[6] == pytest.approx(1e-3)
    assert dict(namespace["drone"].model.source_armature) == {"tilt": 1e-3}


def test_the_ball_joint_block_prints_the_pendulums_physics(tmp_path, monkeypatch):
    """The bob (2 kg, 0.5 m below the pivot, 0.01 kg m^2 about its centre) tilted 0.5 rad:
    g = m g l sin 0.5 about x, M_xx = 0.01 + m l^2; a turn about the bob's z by 0.1 rad."""
    monkeypatch.chdir(tmp_path)
    (code,) = re.findall(r"```python\n(.*?)```", block("bridges-ball-joint", "bridges.md"), re.S)
    namespace: dict = {}
    exec(code, namespace)  # noqa: S102 - our own documentation
    f, tilt = namespace["f"], np.array(namespace["tilt"])
    assert f.gravity(tilt) == pytest.approx([2 * 9.81 * 0.5 * np.sin(0.5), 0, 0], abs=1e-12)
    assert f.mass_matrix(tilt)[0, 0] == pytest.approx(0.51, abs=1e-12)
    turned = f.integrate(tilt, [0.0, 0.0, 1.0], 0.1)
    expected = [np.cos(0.25) * np.cos(0.05), np.sin(0.25) * np.cos(0.05),
                -np.sin(0.25) * np.sin(0.05), np.cos(0.25) * np.sin(0.05)]
    assert turned == pytest.approx(expected, abs=1e-12)


def test_the_free_joint_block_takes_mujocos_state_unchanged(tmp_path, monkeypatch, cli):
    """q = qpos, v = qvel: MuJoCo's qacc itself; M's world-x entry the drone's 1.6 kg. The
    commands: the same state, and a run spinning about the vertical that falls g t^2 / 2."""
    monkeypatch.chdir(tmp_path)
    text = block("bridges-free-joint", "bridges.md")
    (code,) = re.findall(r"```python\n(.*?)```", text, re.S)
    namespace: dict = {}
    exec(code, namespace)  # noqa: S102 - our own documentation
    f, data = namespace["f"], namespace["data"]
    assert f.coordinates[:4] == ("root_x", "root_y", "root_z", "root_qw")
    np.testing.assert_allclose(f.forward_dynamics(data.qpos, data.qvel, np.zeros(7)),
                               data.qacc, rtol=0, atol=1e-9)
    assert f.mass_matrix(data.qpos)[0, 0] == pytest.approx(1.6, abs=1e-12)
    lines = [shlex.split(line[2:]) for line in
             re.findall(r"```console\n(.*?)```", block("bridges-free-joint-cli", "bridges.md"),
                        re.S)[0].splitlines() if line.startswith("$ ")]
    dynamics, simulate = (args[1:] for args in lines)
    result = cli(*dynamics)
    assert result.code == 0, result.err
    assert re.search(r"root_z\s+-9.81\n", result.out)  # no force holds it up
    result = cli(*simulate)
    assert result.code == 0, result.err
    final = json.loads(result.out)["final_state"]
    assert final["root_z"] == pytest.approx(1 - 9.81 * 0.5**2 / 2, abs=1e-9)
    assert final["root_qz"] == pytest.approx(np.sin(0.5 * 0.5 / 2), abs=1e-6)  # 0.25 rad turned
