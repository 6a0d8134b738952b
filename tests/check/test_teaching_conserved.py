"""docs/teaching.md, "Answer files: what L conserves, Routh and Hamilton": every command in it
is re-run and prints what the page shows."""

from __future__ import annotations

import re
import shlex

import pytest

import docs_blocks
from lagrangian.check.conserved_answers import MECHANICS_CODES
from lagrangian.cli import main


def test_commands_print_what_the_page_shows(tmp_path, monkeypatch, capsys):
    text = docs_blocks.block("teaching-conserved")
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
            with pytest.raises(SystemExit) as exit_info:
                main(args[1:])
            assert exit_info.value.code == (0 if "verdict: correct" in shown else 1)
            assert capsys.readouterr().out == shown, command
            checked += 1
    assert checked == 3


def test_every_code_is_named_on_the_page():
    page = docs_blocks.block_file("teaching-conserved").read_text(encoding="utf-8")
    assert all(f"`{code}`" in page for code in MECHANICS_CODES)
