"""docs/simulation.md's impacts section: its commands run and its Python runs (its asserts are
the closed forms: the ball's accumulation time, McGeer's multiplier)."""

from __future__ import annotations

import json
import re
import shlex

from docs_blocks import block


def test_the_commands(cli):
    text = block("impacts")
    lines = [shlex.split(line[2:]) for code in re.findall(r"```console\n(.*?)```", text, re.S)
             for line in code.splitlines() if line.startswith("$ ")]
    assert [args[:2] for args in lines] == [["lagrangian", "simulate"], ["lagrangian", "cycle"],
                                            ["lagrangian", "cycle"]]
    ball, wheel, gait = (cli(*args[1:]) for args in lines)
    assert ball.code == 0 and json.loads(ball.out)["impacts"]["count"] > 50
    assert wheel.code == 0 and "multipliers (linearized Poincare map): 0.5" in wheel.out
    assert gait.code == 0 and json.loads(gait.out)["stable"] is True


def test_the_python(capsys):
    code, = re.findall(r"```python\n(.*?)```", block("impacts"), re.S)
    exec(compile(code, "docs/simulation.md", "exec"), {})
    assert "accumulated" in capsys.readouterr().out
