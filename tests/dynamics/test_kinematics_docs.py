"""docs/robot-kinematics.md: its Python example runs and its command prints the documented
arrays; the two-link arm's frames obey the closed form of a planar arm."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import lagrangian

DOC = Path(__file__).resolve().parents[2] / "docs" / "robot-kinematics.md"
pytest.importorskip("yourdfpy")


def _section() -> str:
    text = DOC.read_text(encoding="utf-8")
    return text[text.index("<!-- BEGIN kinematics -->"):text.index("<!-- END kinematics -->")]


def test_python_example_runs(capsys):
    code = re.findall(r"```python\n(.*?)```", _section(), re.S)[0]
    exec(compile(code, str(DOC), "exec"), {})
    assert "('base', 'upper', 'fore', 'shoulder', 'elbow')" in capsys.readouterr().out


def test_command_gives_the_planar_arm_closed_form(cli):
    """The elbow sits at l1 (cos q1, sin q1) in the x-z plane of the two-link arm; turning the
    shoulder moves it at l1 per rad, perpendicular to the upper arm."""
    command = re.findall(r"\$ lagrangian (.*)", _section())[0].split()
    result = cli(*command)
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["frame"] == "fore" and document["reference"] == "local_world_aligned"
    placement = np.array(document["placement"])
    arm = lagrangian.load("two_link_arm")
    length = float(np.linalg.norm(placement[:3, 3]))
    assert np.allclose(placement[:3, 3] / length, [np.cos(0.3), 0.0, np.sin(0.3)])
    jacobian = np.array(document["jacobian"])
    assert np.allclose(jacobian[:3, 0], length * np.array([-np.sin(0.3), 0.0, np.cos(0.3)]))
    assert np.allclose(jacobian[:3, 1], 0.0)  # the elbow's own rate does not move its origin
    assert arm.dynamics().frames[-1] == "elbow"


def test_cli_refuses_bad_frames_in_one_line(cli):
    result = cli("kinematics", "two_link_arm", "--frame", "hand")
    assert result.code == 2
    assert result.err.strip().startswith("error: --frame: no frame named 'hand'")
    assert len(result.err.strip().splitlines()) == 1
