"""Trim for inputs: linearize, modes(inputs=...) and LQR solve for the input values that make the
requested state an equilibrium (the cart-pendulum upright with F = 1 N in its file: F = 0 holds
it), state them, and refuse, naming the coordinate, only when no input can hold it."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import lagrangian

M, m, L, G = 2.0, 0.5, 0.6, 9.81  # cart_pendulum.toml's cart, bob, rod and gravity


@pytest.fixture(scope="module")
def pushed(tmp_path_factory):
    """cart_pendulum with its push F = 1 N in the file (and started near the top)."""
    text = Path(lagrangian.example_path("cart_pendulum")).read_text(encoding="utf-8")
    text = text.replace('F = { value = 0.0', 'F = { value = 1.0')
    text = text.replace("initial = 0.2", "initial = 3.0")
    path = tmp_path_factory.mktemp("trim") / "pushed.toml"
    path.write_text(text, encoding="utf-8")
    return str(path)


@pytest.fixture(scope="module")
def system(pushed):
    return lagrangian.load(pushed)


def test_the_upright_is_trimmed_by_f_zero(system):
    linear = system.linearize({"x": 0, "theta": math.pi}, inputs=["F"])
    assert linear.trim == {"F": 0.0} and linear.nominal_inputs == {"F": 1.0}
    # upright: M = [[M + m, -m L], [-m L, m L^2]], K = -m g L on theta, B_q = [1, 0]
    mass = np.array([[M + m, -m * L], [-m * L, m * L**2]])
    assert linear.mass_matrix == pytest.approx(mass, rel=1e-12)
    assert linear.stiffness_matrix == pytest.approx(np.array([[0, 0], [0, -m * G * L]]), abs=1e-12)
    assert linear.B[2:, 0] == pytest.approx(np.linalg.solve(mass, [1.0, 0.0]), rel=1e-12)
    # the inverted pendulum's growth rate sqrt(g (M + m) / (M L))
    assert linear.eigenvalues()[0].real == pytest.approx(math.sqrt(G * (M + m) / (M * L)),
                                                         rel=1e-9)
    assert "trim F=0" in repr(linear)


def test_lqr_about_the_trim_holds_the_upright(system):
    regulator = lagrangian.lqr(system.linearize({"x": 0, "theta": math.pi}, inputs=["F"]), 1, 1)
    assert regulator.trim == {"F": 0.0} and regulator.summary()["trim"] == {"F": 0.0}
    assert np.all(regulator.closed_loop_eigenvalues.real < 0)
    # at the upright at rest the controller cancels the file's F = 1 N: F + u = 0
    assert regulator(0.0, np.array([0.0, math.pi]), np.zeros(2)) == pytest.approx([-1.0])
    run = system.simulate(8.0, controller=regulator, samples=50)
    assert run.status == lagrangian.RunStatus.FINISHED
    final = run.final_state
    assert final["theta"] == pytest.approx(math.pi, abs=2e-3)
    assert abs(final["x"]) < 0.05 and abs(final["theta_dot"]) < 5e-3


def test_a_torque_input_holds_a_leaning_pendulum(system):
    # a generalized force on theta holds it at 1 rad: m g L sin(1); F holds the cart (F = 0:
    # the file's 1 N taken off)
    linear = system.linearize({"x": 0, "theta": 1.0}, inputs=["F", "theta"])
    assert linear.trim["theta"] == pytest.approx(m * G * L * math.sin(1.0), rel=1e-12)
    assert linear.trim["F"] == pytest.approx(0.0, abs=1e-12)
    assert linear.nominal_inputs == {"F": 1.0, "theta": 0.0}
    analysis = system.modes({"x": 0, "theta": 1.0}, inputs=["F", "theta"])
    assert analysis.linear_model.trim == linear.trim


def test_no_input_can_hold_it_refused_naming_the_coordinate(system):
    # F pushes the cart only: the pendulum's gravity torque -m g L sin(1) stays on theta
    with pytest.raises(lagrangian.ModelError) as refusal:
        system.linearize({"x": 0, "theta": 1.0}, inputs=["F"])
    message = str(refusal.value)
    assert "not an equilibrium for any value of the inputs (F)" in message
    assert f"{-m * G * L * math.sin(1.0):.3g} stays on theta" in message
    with pytest.raises(lagrangian.ModelError, match="stays on x"):  # F = 1 N is no torque's
        system.linearize({"x": 0, "theta": math.pi}, inputs=["theta"])


def test_the_command_line_states_the_trim(cli, pushed):
    code, out, err = cli("modes", pushed, "--about", "x=0,theta=pi", "--inputs", "F")
    assert code == 0, err
    assert "trim (the inputs' values that hold the equilibrium, SI): F = 0" in out
    code, out, _ = cli("modes", pushed, "--about", "x=0,theta=pi", "--inputs", "F", "--json")
    document = json.loads(out)
    assert document["trim"] == {"F": 0.0} and document["inputs"] == ["F"]
    assert np.ravel(document["input_matrix"])[2:] == pytest.approx(
        np.linalg.solve([[M + m, -m * L], [-m * L, m * L**2]], [1.0, 0.0]), rel=1e-12)
    code, out, err = cli("simulate", pushed, "--t-end", "4", "--control", "lqr", "--about",
                         "x=0,theta=pi", "--inputs", "F", "--samples", "20", "--json")
    assert code == 0, err
    assert json.loads(out)["control"]["trim"] == {"F": 0.0}
    code, _, err = cli("modes", pushed, "--about", "x=0,theta=1", "--inputs", "F")
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "stays on theta" in err and "Traceback" not in err


def test_the_documented_trim(cli, capsys):
    # docs/control.md's control-trim block: its Python prints the trim, the run back upright
    # and the leaning torque's closed form; its command prints the trim line
    import re
    import shlex

    import docs_blocks

    text = docs_blocks.block("control-trim", "control.md")
    (code,) = re.findall(r"```python\n(.*?)```", text, re.S)
    exec(compile(code, "docs/control.md", "exec"), {})
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[0] == "{'F': 0.0} {'F': 1.0}"
    theta, x = map(float, lines[1].split())
    assert theta == pytest.approx(math.pi, abs=1e-3) and x == pytest.approx(0, abs=1e-2)
    torque, closed_form = map(float, lines[2].split())
    assert torque == pytest.approx(closed_form, rel=1e-12)
    (console,) = re.findall(r"```console\n(.*?)```", text, re.S)
    args = shlex.split(console.strip()[2:])[1:]
    result = cli(*args)
    assert result.code == 0, result.err
    assert "trim (the inputs' values that hold the equilibrium, SI): F = 0" in result.out
