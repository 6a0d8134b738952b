"""docs/simulation.md's falling-rod block: its command runs and its Python runs (its assert is
the closed form omega+ = -3 (1 + e) v cos(theta) / (2 L))."""

from __future__ import annotations

import re
import shlex

from docs_blocks import block


def test_the_command(cli):
    line, = [line for code in re.findall(r"```console\n(.*?)```", block("falling-rod"), re.S)
             for line in code.splitlines() if line.startswith("$ ")]
    code, out, err = cli(*shlex.split(line[2:])[1:])
    assert code == 0, err
    assert "end_a" in out and "end_b" in out


def test_the_python(capsys):
    code, = re.findall(r"```python\n(.*?)```", block("falling-rod"), re.S)
    exec(compile(code, "docs/simulation.md", "exec"), {})
    assert capsys.readouterr().out.split()[0] == "end_a"
