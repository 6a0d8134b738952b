"""The docs' examples of what you can see (issue 22) run as written: the commands and Python of
docs/analysis.md (watch-modes), docs/simulation.md (lecture-media) and docs/sweeps.md
(sweep-figure), each between its <!-- BEGIN x --> and <!-- END x --> markers, and write the
files they name, of the size they ask for."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
from PIL import Image

from lagrangian.cli import main

DOCS = Path(__file__).resolve().parents[1] / "docs"


def _blocks(page: str, marker: str) -> tuple[list[list[str]], list[str]]:
    """(the commands of the console blocks, the Python blocks) between the markers."""
    text = (DOCS / page).read_text(encoding="utf-8")
    section = text[text.index(f"<!-- BEGIN {marker} -->"):text.index(f"<!-- END {marker} -->")]
    commands = [shlex.split(line[2:]) for block in re.findall(r"```console\n(.*?)```", section,
                                                              re.S)
                for line in block.replace("\\\n", "").splitlines() if line.startswith("$ ")]
    return commands, re.findall(r"```python\n(.*?)```", section, re.S)


def _run(command: list[str]) -> None:
    assert command[0] == "lagrangian"
    with pytest.raises(SystemExit) as exit_info:
        main(command[1:])
    assert exit_info.value.code in (0, None)


def test_watch_modes_example(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    commands, code = _blocks("analysis.md", "watch-modes")
    for command in commands:
        _run(command)
    for block in code:
        exec(compile(block, "docs/analysis.md", "exec"), {})
    with Image.open("modes.gif") as gif:
        assert gif.size == (800, 400) and gif.n_frames == 40
    assert Image.open("shapes.png").size[0] >= 400
    assert "Mode 2 of Double pendulum" in Path("mode2.html").read_text(encoding="utf-8")


def test_lecture_media_example(tmp_path, monkeypatch, capsys):
    imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg")
    monkeypatch.chdir(tmp_path)
    commands, code = _blocks("simulation.md", "lecture-media")
    for command in commands:
        _run(command)
    for block in code:
        exec(compile(block, "docs/simulation.md", "exec"), {})
    meta = next(imageio_ffmpeg.read_frames("swing.mp4"))
    assert tuple(meta["size"]) == (1280, 720) and meta["fps"] == pytest.approx(30)
    with Image.open("swing.gif") as gif:
        assert gif.size == (800, 600) and gif.info["duration"] == 40


def test_sweep_figure_example(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    commands, _ = _blocks("sweeps.md", "sweep-figure")
    for command in commands:
        _run(command)
    with Image.open("damping.png") as image:
        assert image.size[1] > image.size[0]  # three panels: frequency, zeta, growth rate
