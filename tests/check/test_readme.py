"""The check section (docs/getting-started/students-and-teachers.md) shows real output: every
command in it is re-run here."""

from __future__ import annotations

import re
import shlex

import pytest

import docs_blocks
from lagrangian.cli import main

pytestmark = pytest.mark.smoke  # pytest -m smoke: the quick subset


def section() -> str:
    return docs_blocks.block("check")


def test_readme_commands_print_what_the_readme_shows(tmp_path, monkeypatch, capsys):
    text = section()
    for block in re.findall(r"```toml\n(.*?)```", text, re.S):
        name = re.match(r"# (\S+\.toml)", block)
        if name:
            (tmp_path / name.group(1)).write_text(block, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    checked = 0
    for block in re.findall(r"```console\n(.*?)```", text, re.S):
        runs = re.split(r"^\$ ", block, flags=re.M)[1:]
        last_code = None
        for run in runs:
            command, _, shown = run.partition("\n")
            if command == "echo $?":
                assert shown.strip() == str(last_code)
                continue
            args = shlex.split(command)
            assert args[0] == "lagrangian"
            with pytest.raises(SystemExit) as exit_info:
                main(args[1:])
            last_code = exit_info.value.code
            assert capsys.readouterr().out == shown, command
            checked += 1
    assert checked >= 5
