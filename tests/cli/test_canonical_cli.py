"""lagrangian simulate --canonical: Hamilton's equations in (q, p) from the command line."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lagrangian.cli import main


def test_simulate_canonical_reports_the_momenta_of_its_final_state(capsys):
    """p = M q_dot at the end, with the double pendulum's closed-form M (m = l = 1)."""
    with pytest.raises(SystemExit) as exit_info:
        main(["simulate", "double_pendulum", "--t-end", "1", "--canonical", "--json"])
    assert exit_info.value.code == 0
    document = json.loads(capsys.readouterr().out)
    assert "(q, p)" in document["backend"] and document["status"] == "finished"
    s = document["final_state"]
    c = np.cos(s["theta1"] - s["theta2"])
    p1 = 2 * s["theta1_dot"] + c * s["theta2_dot"]
    p2 = c * s["theta1_dot"] + s["theta2_dot"]
    assert document["final_momenta"]["p_theta1"] == pytest.approx(p1, abs=1e-10)
    assert document["final_momenta"]["p_theta2"] == pytest.approx(p2, abs=1e-10)
    assert document["relative_energy_drift"] < 1e-7


def test_simulate_canonical_refuses_impacts_in_one_line(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["simulate", "bouncing_ball", "--t-end", "1", "--canonical"])
    assert exit_info.value.code == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "(q, p)" in error and "Traceback" not in error
