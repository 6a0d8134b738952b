"""The README's analysis section shows real output: re-run it and compare."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from lagrangian.cli import main

README = Path(__file__).resolve().parents[2] / "README.md"


def section() -> str:
    text = README.read_text(encoding="utf-8")
    match = re.search(r"<!-- BEGIN analysis -->(.*?)<!-- END analysis -->", text, re.S)
    assert match, "README.md lacks the analysis section"
    return match.group(1)


def test_readme_modes_two_mass_output_is_current(capsys):
    block = re.search(r"```console\n\$ lagrangian modes two_mass\n(.*?)```", section(), re.S)
    assert block
    with pytest.raises(SystemExit) as exit_info:
        main(["modes", "two_mass"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out == block.group(1)


def test_readme_python_examples_run(capsys):
    for code in re.findall(r"```python\n(.*?)```", section(), re.S):
        exec(compile(code, "README.md", "exec"), {})  # noqa: S102 (our own documentation)
    printed = capsys.readouterr().out
    assert "[1.         1.73205081]" in printed
    assert "20.4375 0.8333333333333334" in printed
    assert "Matrix([[0, 0], [0, -g*l*m]])" in printed
