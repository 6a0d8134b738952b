"""The section on bodies in space (docs/getting-started/engineers.md): its model file reads, its
Python runs, and its console line is real output."""

import re

import docs_blocks
import lagrangian


def section() -> str:
    return docs_blocks.block("bodies3d")


def test_model_file_is_the_heavy_top_example():
    text = re.findall(r"```toml\n(.*?)```", section(), re.S)[0]
    shown = lagrangian.System(lagrangian.parse_model(text)).equations_of_motion()
    example = lagrangian.load("heavy_top").equations_of_motion()
    assert shown.mass_matrix == example.mass_matrix
    assert shown.forcing == example.forcing


def test_console_line_is_real_output(cli):
    line = re.findall(r"```console\n\$ lagrangian derive heavy_top\n(.*?)\n```", section(),
                      re.S)[0]
    assert line in cli("derive", "heavy_top").out


def test_python_example_runs(capsys):
    code = re.findall(r"```python\n(.*?)```", section(), re.S)[0]
    exec(compile(code, "bodies3d", "exec"), {})
    assert "{'q1': 0.0, 'q2': 0.3}" in capsys.readouterr().out
