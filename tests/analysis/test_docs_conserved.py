"""docs/analysis.md's conserved-quantities block runs and shows current output."""

from __future__ import annotations

import math
import re

import pytest

import docs_blocks
from lagrangian.cli import main


def test_conserved_block_runs_and_its_frequency_is_the_closed_form(capsys):
    section = docs_blocks.block("conserved")
    for code in re.findall(r"```python\n(.*?)```", section, re.S):
        exec(compile(code, "conserved", "exec"), {})  # noqa: S102 (our own documentation)
    printed = capsys.readouterr().out.splitlines()
    assert "momentum: p_phi = l**2*m*phi_dot*sin(theta)**2" in printed[1]
    frequency = float(printed[3].strip("[]"))
    closed = math.sqrt(9.81 * (1 + 3 * math.cos(0.6) ** 2) / (0.8 * math.cos(0.6)))
    assert frequency == pytest.approx(closed, rel=1e-8)
    console = re.search(r"```console\n\$ lagrangian conserved bead_on_hoop\n(.*?)```", section,
                        re.S)
    with pytest.raises(SystemExit) as exit_info:
        main(["conserved", "bead_on_hoop"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out == console.group(1)
