"""The simulate section (docs/getting-started/engineers.md) shows what the program prints: its
commands are re-run here (only the wall time may differ), so the docs cannot drift from the
program again (issue 12)."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

import docs_blocks
from lagrangian.api.simulation import Simulation
from lagrangian.cli import main

WALL = re.compile(r"wall time [0-9.e+-]+ s")


def _commands() -> list[tuple[list[str], str]]:
    """(arguments, the lines shown after the command) for each command of the section's first
    console block, continuation lines joined."""
    section = docs_blocks.block("simulate", "getting-started/engineers.md")
    block = re.findall(r"```console\n(.*?)```", section, re.S)[0].replace("\\\n", "")
    runs = []
    for run in re.split(r"^\$ ", block, flags=re.M)[1:]:
        command, _, shown = run.partition("\n")
        runs.append((shlex.split(command), shown))
    return runs


def _run(args, monkeypatch, capsys):
    assert args[0] == "lagrangian"
    with pytest.raises(SystemExit) as exit_info:
        main(args[1:])
    assert exit_info.value.code == 0
    return capsys.readouterr()


def test_readme_simulate_commands_print_what_the_readme_shows(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    # the GIF itself is tested with the animation (tests/output); here only what is printed
    monkeypatch.setattr(Simulation, "animate",
                        lambda self, path, **_: Path(path).write_bytes(b"GIF89a"))
    (first, first_shown), (second, _), (third, third_shown) = _commands()
    printed = _run(first, monkeypatch, capsys)
    assert WALL.sub("wall time", printed.out) == WALL.sub("wall time", first_shown)
    assert printed.err == ""
    assert _run(second, monkeypatch, capsys).out.startswith("{")  # its JSON, not shown there
    assert _run(third, monkeypatch, capsys).err == third_shown  # the one warning shown
