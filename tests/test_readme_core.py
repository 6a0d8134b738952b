"""The core section (docs/getting-started/engineers.md): its Python example runs and its console
lines are real output."""

import re

import pytest

import docs_blocks


def core_section() -> str:
    return docs_blocks.block("core")


def test_python_example_runs(capsys):
    code = re.findall(r"```python\n(.*?)```", core_section(), re.S)[0]
    exec(compile(code, "core", "exec"), {})
    out = capsys.readouterr().out
    assert "Matrix([[F*L*cos(theta)]])" in out
    assert "{'theta': 0.877" in out


@pytest.mark.parametrize("line", [
    "  [theta1]  l1**2*(m1 + m2)*theta1_ddot + l1*l2*m2*theta2_ddot*cos(theta1 - theta2) = "
    "-g*l1*(m1 + m2)*sin(theta1) - l1*l2*m2*theta2_dot**2*sin(theta1 - theta2)",
    "T = (l1**2*theta1_dot**2*(m1 + m2) + 2*l1*l2*m2*theta1_dot*theta2_dot*cos(theta1 - theta2) "
    "+ l2**2*m2*theta2_dot**2)/2",
])
def test_console_lines_are_real_output(cli, line):
    assert line in core_section()
    assert line in cli("derive", "double_pendulum").out


def test_forces_example_is_real_output(cli):
    shown = "Generalized forces at theta = 0.523599:\n  Q[theta] = 43.3013 N*m\n      from F: 43.3013 N*m\n"
    assert shown in core_section()
    assert cli("forces", "virtual_work_link", "--at", "theta=30deg").out == shown
