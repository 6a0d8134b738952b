"""docs/robotics.md: its commands run, its Python runs, its C++ compiles with g++ -Wall -Werror,
and what they show is the physics (closed forms of the shipped two-link arm)."""

from __future__ import annotations

import json
import math
import re
import shlex
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("yourdfpy")

DOC = Path(__file__).resolve().parents[1] / "docs" / "robotics.md"


def section(name: str) -> str:
    text = DOC.read_text(encoding="utf-8")
    return text[text.index(f"<!-- BEGIN {name} -->"):text.index(f"<!-- END {name} -->")]


def commands(name: str) -> list[list[str]]:
    lines = []
    for block in re.findall(r"```console\n(.*?)```", section(name), re.S):
        lines += [shlex.split(line[2:]) for line in block.splitlines() if line.startswith("$ ")]
    assert all(args[0] == "lagrangian" for args in lines)
    return [args[1:] for args in lines]


def wall_gravity(q1, q2, g=9.81):
    """g(q) of two_link_arm (2 kg, centre 0.5 m; 1.5 kg, centre 0.4 m past 1 m) under gravity
    g along +x: dV/dq with V = -g (m x summed)."""
    return [g * (2.5 * math.sin(q1) + 0.6 * math.sin(q1 + q2)), g * 0.6 * math.sin(q1 + q2)]


def test_the_command_lines(cli):
    (gravity, equilibria, as_json, show, beyond, stops, through, payload,
     inertial) = commands("robotics-cli")
    result = cli(*gravity)
    assert result.code == 0, result.err
    for value in wall_gravity(0.3, 0.5):
        assert f"{value:.9g}" in result.out
    result = cli(*equilibria, "--json")
    found = json.loads(result.out)["equilibria"]
    assert any(e["stable"] and max(map(abs, e["coordinates"].values())) < 1e-9 for e in found)
    document = json.loads(cli(*as_json).out)
    assert document["joint_names"] == {"shoulder": "shoulder", "elbow": "elbow"}
    assert "elbow = 'elbow'" in cli(*show).out.splitlines()[-1]
    result = cli(*beyond)
    assert result.code == 0
    (line,) = [x for x in result.err.splitlines() if x.startswith("warning: ")]
    assert "'shoulder'" in line and "[-3.1, 3.1] rad" in line
    document = json.loads(cli(*stops, "--json").out)
    assert document["status"] == "limit" and "joint 'shoulder'" in document["message"]
    assert document["final_state"]["shoulder"] == pytest.approx(-3.1, abs=1e-9)
    free = json.loads(cli(*through, "--json").out)
    assert free["status"] == "finished" and free["t_final"] == pytest.approx(3.0)
    for record in free["limits_exceeded"]:  # the arm's velocity limits are 5 rad/s
        assert record["quantity"] == "velocity" and record["value"] > record["limit"] == 5.0
    M = np.array(json.loads(cli(*payload, "--json").out)["mass_matrix"])
    assert M[1, 1] == pytest.approx(0.34 + 2.0 * 0.5**2, rel=1e-12)  # M22 + m r^2
    M = np.array(json.loads(cli(*inertial, "--json").out)["mass_matrix"])
    assert M[1, 1] == pytest.approx(0.1 + 3.5 * 0.4**2, rel=1e-12)  # I_C + m r^2, m = 3.5 kg


def test_the_python():
    code = re.findall(r"```python\n(.*?)```", section("robotics-python"), re.S)[0]
    scope: dict = {}
    exec(compile(code, str(DOC), "exec"), scope)
    g = wall_gravity(0.3, 0.5)
    np.testing.assert_allclose(scope["g_wall"], g, rtol=1e-12)
    assert f"[{g[0]:.4g}, {g[1]:.4g}]" in code
    assert scope["names"] == {"shoulder": "shoulder", "elbow": "elbow"}
    assert scope["joints"] == {"shoulder": "shoulder", "elbow": "elbow"}
    assert scope["limits"] == {"shoulder": (-3.1, 3.1), "elbow": (-3.1, 3.1)}
    a = scope["a"]
    assert np.isnan(a[17]).all() and np.isfinite(np.delete(a, 17, axis=0)).all()
    assert scope["bad"].count == 1 and scope["bad"].total == 10_000
    assert scope["M_heavy"][1, 1] == pytest.approx(0.1 + 3.5 * 0.4**2, rel=1e-12)


@pytest.mark.skipif(shutil.which("g++") is None or shutil.which("gcc") is None,
                    reason="g++ or gcc is not installed (Debian: apt-get install g++)")
def test_the_cpp_controller(cli, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (codegen,) = commands("robotics-cpp")
    assert cli(*codegen).code == 0
    source = re.findall(r"```cpp\n(.*?)```", section("robotics-cpp"), re.S)[0]
    Path("controller.cpp").write_text(source)
    for line in re.findall(r"^//\s+(?:controller\.cpp:)?\s*((?:gcc|g\+\+) .*)$", source, re.M):
        subprocess.run(shlex.split(line), check=True)
    out = subprocess.run(["./controller"], check=True, capture_output=True, text=True).stdout
    c = math.cos(0.5)  # M11 = 2.54 + 1.2 cos(elbow), M12 = 0.34 + 0.6 cos, M22 = 0.34
    assert [float(x) for x in out.split()] == pytest.approx(
        [2.54 + 1.2 * c, 0.34 + 0.6 * c, 0.34 + 0.6 * c, 0.34], abs=1e-4)
    assert "3.5931 0.8665" in source


def test_the_ball_joint_export(cli, tmp_path, monkeypatch, capsys):
    """The ball-joint block: the C export's header has q 4 and v 3 numbers, and the unrolled
    kernel holds a 2 kg bob 0.5 m below its ball turned 0.4 rad about x by m g d sin(0.4)
    about x; M's entry about x is I + m d^2; its codegen command writes the C."""
    monkeypatch.chdir(tmp_path)
    code = re.findall(r"```python\n(.*?)```", section("robotics-ball-export"), re.S)[0]
    exec(compile(code, "robotics-ball-export", "exec"), {})
    sizes, gravity, inertia = capsys.readouterr().out.strip().splitlines()
    assert sizes == "[['SPHERICAL_PENDULUM_N', '3'], ['SPHERICAL_PENDULUM_NQ', '4']]"
    moment = [float(x) for x in gravity.strip("[]").split()]
    assert moment == pytest.approx([2.0 * 9.81 * 0.5 * math.sin(0.4), 0.0, 0.0], abs=1e-8)
    assert float(inertia) == pytest.approx(0.01 + 2.0 * 0.5**2, abs=1e-8)
    (codegen,) = commands("robotics-ball-export")
    assert cli(*codegen).code == 0
    assert "#define SPHERICAL_PENDULUM_NQ 4" in Path("gen/spherical_pendulum.h").read_text()
