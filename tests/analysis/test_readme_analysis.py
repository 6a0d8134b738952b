"""The analysis section (docs/getting-started/engineers.md) shows real output: re-run it and compare."""

from __future__ import annotations

import re

import pytest

import docs_blocks
from lagrangian.cli import main


def section() -> str:
    return docs_blocks.block("analysis")


def test_readme_modes_two_mass_output_is_current(capsys):
    block = re.search(r"```console\n\$ lagrangian modes two_mass\n(.*?)```", section(), re.S)
    assert block
    with pytest.raises(SystemExit) as exit_info:
        main(["modes", "two_mass"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out == block.group(1)


def test_readme_python_examples_run(capsys):
    for code in re.findall(r"```python\n(.*?)```", section(), re.S):
        exec(compile(code, "analysis", "exec"), {})  # noqa: S102 (our own documentation)
    printed = capsys.readouterr().out
    assert "[1.         1.73205081]" in printed
    assert "20.4375 0.8333333333333334" in printed
    assert "Matrix([[0, 0], [0, -g*l*m]])" in printed


def test_steady_rates_are_read_as_the_command_line_writes_them(capsys):
    """600 rpm is 20 pi rad/s; an expression in the parameters is kept for the analysis; a
    quantity in the wrong units names the field."""
    import lagrangian

    code = re.search(r"```python\n(import lagrangian\n\ncoin = .*?)```", section(), re.S)
    assert code
    exec(compile(code.group(1), "analysis", "exec"), {})  # noqa: S102 (our own documentation)
    assert "{'spin_dot': 62.83185307179586, 'x_dot': 'sqrt(g*r/3)'}" in capsys.readouterr().out
    coin = lagrangian.load("rolling_coin").model
    rates = lagrangian.parse_steady_rates(coin, {"spin_dot": "600rpm"})
    assert rates["spin_dot"] == pytest.approx(20 * 3.141592653589793, rel=1e-15)
    with pytest.raises(lagrangian.InputError, match="not in units compatible") as error:
        lagrangian.parse_steady_rates(coin, {"spin_dot": "3 N"})
    assert error.value.field == "steady.spin_dot"
