"""docs/control.md: every Python snippet runs and prints the physics it promises, and every
command runs (JSON parsed, checked against the Python API's closed forms)."""

from __future__ import annotations

import json
import re
import shlex

import numpy as np
import pytest

import docs_blocks
import lagrangian

pytest.importorskip("yourdfpy")


def _python(name: str) -> str:
    return re.findall(r"```python\n(.*?)```", docs_blocks.block(name, "control.md"), re.S)[0]


def _command(name: str, which: int = 0) -> list[str]:
    (line,) = [x for x in re.findall(r"```console\n(.*?)```", docs_blocks.block(name, "control.md"),
                                     re.S)[which].splitlines() if x.startswith("$ ")]
    args = shlex.split(line[2:])
    assert args[0] == "lagrangian"
    return args[1:]


def _run(name: str, capsys) -> list[str]:
    exec(compile(_python(name), "docs/control.md", "exec"), {})
    return capsys.readouterr().out.strip().splitlines()


def test_lqr_from_modes_section(capsys):
    theta, x = map(float, _run("control-lqr-modes", capsys)[-1].split())
    assert theta == pytest.approx(np.pi, abs=1e-3) and x == pytest.approx(0, abs=1e-2)


def test_lqr_section(capsys, cli):
    lines = _run("control-lqr", capsys)
    theta, x = map(float, lines[-1].split())
    assert theta == pytest.approx(np.pi, abs=1e-3) and x == pytest.approx(0, abs=1e-2)
    result = cli(*_command("control-lqr"))
    assert result.code == 0, result.err
    assert all(re_ < 0 for re_, _ in json.loads(result.out)["control"]["closed_loop_eigenvalues"])


def test_computed_torque_section(capsys, cli):
    assert _run("control-computed-torque", capsys)[-1] == "True"
    result = cli("simulate", "two_link_arm", "--t-end", "1", "--control", "computed-torque",
                 "--about", "shoulder=0.5,elbow=0.2", "--kp", "100", "--kd", "20", "--json")
    assert result.code == 0, result.err
    final = json.loads(result.out)["final_state"]
    # the error from rest at the model's initial state decays as (1 + 10 t) exp(-10 t)
    assert final["shoulder"] == pytest.approx(0.5, abs=1e-2 * 0.5)
    assert final["elbow"] == pytest.approx(0.2, abs=1e-2)


@pytest.mark.slow
def test_computed_torque_on_the_panda_section(capsys):
    pin = pytest.importorskip("pinocchio")
    from pathlib import Path
    if not any((p / "share/example-robot-data/robots").is_dir()
               for p in Path(pin.__file__).parents):
        pytest.skip("example-robot-data is not installed")
    assert _run("control-computed-torque-panda", capsys)[-1] == "True"


def test_derivatives_section(capsys, cli):
    lines = _run("control-derivatives", capsys)
    assert float(lines[0].strip("[] ")) == pytest.approx(9.81 * 0.5 * np.cos(0.4), rel=1e-9)
    assert lines[-1] == "(51, 2, 2) (51, 2, 1)"
    result = cli(*_command("control-derivatives"))
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert np.array(document["dtau_dq"]).shape == (2, 2)


def test_along_section(cli):
    result = cli(*_command("control-along"))
    assert result.code == 0, result.err
    along = json.loads(result.out)["linearize_along"]
    A = np.array(along["A"])
    assert A.shape == (51, 2, 2)
    assert A[0, 1, 0] == pytest.approx(-9.81 / 0.5 * np.cos(1.0), rel=1e-9)  # -g/L cos theta


def test_along_section_takes_a_ball_in_its_tangent(capsys):
    names, shape = _run("control-along", capsys)
    assert names.startswith("('delta_shoulder_wx', 'delta_shoulder_wy', 'delta_shoulder_wz'")
    assert shape == "(6, 8, 8)"


def test_regressor_section(capsys, cli):
    count, error = _run("control-regressor", capsys)[-1].split()
    assert int(count) >= 2 and float(error) < 0.05
    result = cli(*_command("control-regressor"))
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["parameters"] == ["m1", "m2"] and len(document["base"]["names"]) == 2


def test_floating_regressor_section(capsys, cli):
    """Y pi is the inverse dynamics; the base's six equations identify more than a fixed base
    (two_link_arm: 24 of 30 against 6 of 20); the command's Y pi is its own tau."""
    lines = _run("control-regressor-floating", capsys)
    assert lines[0] == "(8, 30) True"
    floating, fixed = map(int, lines[1].split())
    assert floating > fixed and (floating, fixed) == (24, 6)
    result = cli(*_command("control-regressor-floating"))
    assert result.code == 0, result.err
    document = json.loads(result.out)
    Y, pi = np.array(document["regressor"]), np.array(document["values"])
    assert Y.shape == (8, 30) and len(document["velocities"]) == 8
    assert len(document["base"]["names"]) == 24
    inverse = json.loads(cli("dynamics", "two_link_arm", "--floating-base", "--q",
                             "0.1,0.2,0.3,0,0,0.6,0.8,0.4,-0.7", "--a", "0,0,0,0,0,0,0,0",
                             "--json").out)["inverse_dynamics"]
    np.testing.assert_allclose(Y @ pi, inverse, rtol=0, atol=1e-12 * np.abs(inverse).max())


def test_control_law_section(capsys, cli, tmp_path, monkeypatch):
    compiled, stepped, same = _run("control-law", capsys)[-1].split()
    assert same == "True" and stepped == "scipy" and compiled in ("compiled", "scipy")
    text = re.findall(r'write_text\("""(.*?)"""\)', _python("control-law"), re.S)[0]
    (tmp_path / "pd_pendulum.toml").write_text(text, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = cli(*_command("control-law"))
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["control"]["inputs"] == ["theta"] and "Kp" in document["control"]["laws"]["theta"]
    # the same law as a Python callable, run through the API, ends at the same state
    def pd(t, q, v):
        return -4.0 * (q - 0.2 * np.sin(t)) - 2.0 * v

    same = lagrangian.load(tmp_path / "pd_pendulum.toml").simulate(4, controller=pd)
    assert document["final_state"]["theta"] == pytest.approx(same.final_state["theta"], abs=1e-7)


def test_constrained_section(capsys, cli):
    lines = _run("control-constrained", capsys)
    assert float(lines[0]) == pytest.approx(9.81 / 0.5, rel=1e-12)
    assert lines[-1] == "(11, 4, 4)"
    result = cli(*_command("control-constrained"))
    assert result.code == 0, result.err
    along = json.loads(result.out)["linearize_along"]
    assert np.array(along["A"]).shape == (11, 4, 4) and along["inputs"] == ["x", "y"]
    result = cli(*_command("control-constrained", 1))  # dynamics of the slider-crank
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["constraints"] == ["loop_y", "loop_x"] and len(document["multipliers"]) == 2
    assert np.array(document["dqdd_dtau"]).shape == (3, 3)


def test_manifold_section(capsys, cli):
    lines = _run("control-manifold", capsys)
    assert lines[0] == "('x', 'x_dot') ('y',)"
    result = cli(*_command("control-manifold"))
    assert result.code == 0, result.err
    along = json.loads(result.out)["linearize_along"]
    assert along["states"] == ["x", "x_dot"] and along["dependent"] == ["y"]
    for A in np.array(along["A"]):  # hanging at rest: [[0, 1], [-g/L, 0]] at every sample
        np.testing.assert_allclose(A, [[0, 1], [-9.81 / 0.5, 0]], atol=1e-9)


def test_control_law_codegen_section(cli, tmp_path, monkeypatch):
    import shutil
    import subprocess

    compiler = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if compiler is None:
        pytest.skip("no C compiler")
    text = re.findall(r'write_text\("""(.*?)"""\)', _python("control-law"), re.S)[0]
    (tmp_path / "pd_pendulum.toml").write_text(text, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = cli(*_command("control-law-codegen"))
    assert result.code == 0, result.err
    main = re.findall(r"```c\n(.*?)```", docs_blocks.block("control-law-codegen", "control.md"),
                      re.S)[0]
    (tmp_path / "main.c").write_text(main, encoding="utf-8")
    subprocess.run([compiler, "-std=c99", "-pedantic", "-Wall", "-Werror", "-Igen", "main.c",
                    "gen/pd.c", "-o", "main", "-lm"], check=True)
    tau, a = map(float, subprocess.run(["./main"], check=True, capture_output=True,
                                       text=True).stdout.split())
    # theta = 0.3 at rest, t = 0: u = -Kp theta; m L^2 a = u - m g L sin(theta)
    assert tau == pytest.approx(-4.0 * 0.3, abs=1e-6)
    assert a == pytest.approx((tau - 9.81 * 0.5 * np.sin(0.3)) / 0.25, abs=1e-6)
    assert f"{tau:.6f} {a:.6f}" in main  # the printed figures in the page are these


def test_computed_torque_on_ball_joints_section(capsys, tmp_path, monkeypatch, cli):
    monkeypatch.chdir(tmp_path)  # the example writes wrist.xml where it runs
    lines = _run("control-computed-torque-ball", capsys)
    assert lines[0] == str(("shoulder_qw", "shoulder_qx", "shoulder_qy", "shoulder_qz",
                            "elbow"))
    assert lines[-1] == "True"
    result = cli("simulate", "wrist.xml", "--t-end", "3", "--control", "computed-torque",
                 "--about", "shoulder_qw=0.8,shoulder_qx=0.6", "--json")
    assert result.code == 0, result.err
    final = json.loads(result.out)["final_state"]
    assert final["shoulder_qw"] == pytest.approx(0.8, abs=1e-8)
    assert final["shoulder_qx"] == pytest.approx(0.6, abs=1e-8)


def test_lqr_on_a_ball_joint_section(capsys, tmp_path, monkeypatch, cli):
    monkeypatch.chdir(tmp_path)  # the example writes top.xml where it runs
    lines = _run("control-ball-lqr", capsys)
    assert float(lines[0]) < -0.5 and lines[-1] == "True"
    result = cli(*_command("control-ball-lqr"))
    assert result.code == 0, result.err
    final = json.loads(result.out)["final_state"]
    assert np.hypot(final["pivot_qx"], final["pivot_qy"]) < 1e-3  # upright: sin(tilt / 2)
