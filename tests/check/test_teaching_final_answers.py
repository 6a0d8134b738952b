"""docs/teaching.md, "Answer files: final answers": every command in it is re-run and prints
what the page shows, and its Python example runs."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from lagrangian.check.final_answers import FINAL_CODES
from lagrangian.cli import main

PAGE = Path(__file__).parents[2] / "docs" / "teaching.md"


def section() -> str:
    text = PAGE.read_text(encoding="utf-8")
    start = text.index("<!-- BEGIN teaching-final-answers -->")
    return text[start:text.index("<!-- END teaching-final-answers -->")]


def test_the_section_is_titled_as_linked():
    assert "## Answer files: final answers" in section()


def test_commands_print_what_the_page_shows(tmp_path, monkeypatch, capsys):
    text = section()
    for block in re.findall(r"```toml\n(.*?)```", text, re.S):
        name = re.match(r"# (\S+\.toml)", block)
        assert name, block
        (tmp_path / name.group(1)).write_text(block, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    checked = 0
    for block in re.findall(r"```console\n(.*?)```", text, re.S):
        for run in re.split(r"^\$ ", block, flags=re.M)[1:]:
            command, _, shown = run.partition("\n")
            args = shlex.split(command)
            assert args[0] == "lagrangian"
            with pytest.raises(SystemExit) as exit_info:
                main(args[1:])
            assert exit_info.value.code == (0 if "verdict: correct" in shown else 1)
            assert capsys.readouterr().out == shown, command
            checked += 1
    assert checked == 5


def test_python_example_runs(capsys):
    code = re.findall(r"```python\n(.*?)```", section(), re.S)[0]
    exec(compile(code, str(PAGE), "exec"), {})  # the page's own example, not user input
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "incorrect"
    assert out[1] == "[('K', 'matrix_entry'), ('omega[1]', None), ('omega[2]', None)]"


def test_every_code_is_documented():
    for code in FINAL_CODES:
        assert f"`{code}`" in section(), code
