"""docs/bridges.md: its Python and its commands run, and what they show is the physics."""

from __future__ import annotations

import json
import re
import shlex

import numpy as np
import pytest

from docs_blocks import block


def python_of(name: str) -> str:
    (code,) = re.findall(r"```python\n(.*?)```", block(name, "bridges.md"), re.S)
    return code


def commands(name: str) -> list[list[str]]:
    lines = [shlex.split(line[2:]) for code in re.findall(r"```console\n(.*?)```",
                                                            block(name, "bridges.md"), re.S)
             for line in code.splitlines() if line.startswith("$ ")]
    assert all(args[0] == "lagrangian" for args in lines)
    return [args[1:] for args in lines]


def test_casadi_block_gives_the_linearized_A(capsys):
    import lagrangian

    namespace: dict = {}
    exec(python_of("bridges-casadi"), namespace)  # noqa: S102 - our own documentation
    A = np.asarray(namespace["A"]([0, 0, 0, 0], [0]))
    expected = lagrangian.load("double_pendulum").linearize(
        {"theta1": 0, "theta2": 0}).A
    assert np.allclose(A, expected, rtol=1e-10, atol=1e-10)
    assert "inputs=['theta1']" in capsys.readouterr().out


def test_optimize_block_swings_the_pole_up():
    namespace: dict = {}
    exec(python_of("bridges-optimize"), namespace)  # noqa: S102 - our own documentation
    swing, run = namespace["swing"], namespace["run"]
    assert swing.converged
    assert np.abs(swing.states["x"]).max() <= 1 + 1e-6  # the track's bound held
    assert np.abs(swing.inputs["push"]).max() <= 20 + 1e-6
    assert np.abs(run.q[-1] - [0, np.pi]).max() <= swing.defects["replay"] + 1e-6
    # the optimum (N^2 s) of two tools independent of ours on the cart-pole written from its
    # textbook equations: CasADi/IPOPT multiple shooting (RK4, 200 intervals) and SciPy's SLSQP
    # on a trapezoidal collocation of its own (61 nodes); benchmarks/swing_up_references.py
    for optimum in (323.726, 324.886):
        assert swing.cost == pytest.approx(optimum, rel=0.01)


def test_optimize_commands(cli):
    text, as_json = commands("bridges-optimize-cli")
    result = cli(*text)
    assert result.code == 0, result.err
    assert "converged" in result.out and "NOT" not in result.out
    document = json.loads(cli(*as_json).out)
    assert document["converged"] and document["states"]["theta"][-1] == pytest.approx(np.pi)


def test_mjcf_block_reads_the_arm(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(python_of("bridges-mjcf"), namespace)  # noqa: S102 - our own documentation
    dynamics = namespace["dynamics"]
    assert dynamics.mass_matrix([0.3])[0, 0] == pytest.approx(0.51, rel=1e-12)
    assert dynamics.gravity([0.3])[0] == pytest.approx(2 * 9.81 * 0.5 * np.sin(0.3), rel=1e-12)


def test_fmu_blocks_export_and_simulate_the_pendulum(cli, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (export,) = commands("bridges-fmu-cli")
    result = cli(*export)
    assert result.code == 0, result.err
    namespace: dict = {}
    exec(python_of("bridges-fmu"), namespace)  # noqa: S102 - our own documentation
    assert "[]" in capsys.readouterr().out
    period = float(np.diff(namespace["up"]).mean())
    assert period == pytest.approx(2 * np.pi * np.sqrt(0.5 / 9.81), rel=1e-5)


def test_opty_block_prints_the_cart_poles_equations(capsys):
    namespace: dict = {}
    exec(python_of("bridges-opty"), namespace)  # noqa: S102 - our own documentation
    equations = namespace["equations"]
    assert [str(x) for x in equations.states] == ["x(t)", "theta(t)", "x_dot(t)", "theta_dot(t)"]
    assert "r_push(t)" in capsys.readouterr().out


def test_optimize_ball_block_turns_the_body_by_the_closed_form(tmp_path, monkeypatch, capsys,
                                                                cli):
    """Rest to rest by THETA about a principal axis in T: cost 12 I^2 THETA^2 / T^3."""
    monkeypatch.chdir(tmp_path)  # the example writes body.xml where it runs
    namespace: dict = {}
    exec(python_of("bridges-ball-optimize"), namespace)  # noqa: S102 - our own documentation
    best = namespace["best"]
    assert best.converged
    assert best.cost == pytest.approx(12 * 0.4**2 * 1.2**2 / 1.5**3, rel=1e-4)
    assert capsys.readouterr().out.strip().splitlines()[-1] == "True"
    (as_json,) = commands("bridges-ball-optimize")
    result = cli(*as_json)
    assert result.code == 0, result.err
    assert json.loads(result.out)["cost"] == pytest.approx(best.cost, rel=1e-5)
