"""Complex (gyroscopic) modes: the phase of each coordinate in the JSON and the motion over a
period in the plot, against the closed form of a charged particle in a magnetic field."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import lagrangian
from lagrangian.output.modes import mode_shape_figure, mode_snapshots


def test_charged_particle_phases_follow_the_cyclotron_motion(cli):
    """m x'' = q B y', m y'' = -q B x': at omega = q B / m the particle circles clockwise,
    x = a cos(omega t), y = -a sin(omega t) = a cos(omega t + pi/2): y leads by +90 degrees."""
    code, out, _ = cli("modes", "charged_particle", "--json")
    assert code == 0
    document = json.loads(out)
    rigid, cyclotron = document["modes"]
    m, q, b = 1.0, 2.0, 1.5
    assert cyclotron["frequency"] == pytest.approx(q * b / m)
    assert cyclotron["phase"] == pytest.approx({"x": 0.0, "y": math.pi / 2}, abs=1e-12)
    assert cyclotron["amplitude"] == pytest.approx({"x": 1.0, "y": 1.0}, rel=1e-12)
    assert cyclotron["shape"] == pytest.approx({"x": 1.0, "y": 0.0}, abs=1e-12)  # kept
    assert rigid["phase"] == {"x": 0.0, "y": 0.0}
    # the phases are the angles of the complex shape entries
    analysis = lagrangian.load("charged_particle").modes()
    shape = analysis.modes[1].complex_shape
    assert [cyclotron["phase"][n] for n in ("x", "y")] == pytest.approx(
        [math.atan2(v.imag, v.real) for v in shape], abs=1e-15)


def test_a_real_mode_has_phase_zero_or_pi(cli):
    code, out, _ = cli("modes", "two_mass", "--json")
    second = json.loads(out)["modes"][1]
    assert second["phase"] == pytest.approx({"x1": 0.0, "x2": math.pi})
    assert second["amplitude"] == pytest.approx({"x1": 1.0, "x2": 1.0})


def test_the_plot_draws_a_complex_mode_over_one_period():
    analysis = lagrangian.load("charged_particle").modes()
    figure = mode_shape_figure(analysis)
    rigid_panel, cyclotron_panel = figure.axes[:2]
    assert not [line for line in rigid_panel.get_lines() if line.get_label() == "motion"]
    x_curve, y_curve = [line for line in cyclotron_panel.get_lines()
                        if line.get_label() == "motion"]
    theta = 2 * np.pi * (np.asarray(x_curve.get_xdata()) / 0.8 + 0.5)  # x slot centred at 0
    np.testing.assert_allclose(x_curve.get_ydata(), np.cos(theta), atol=1e-12)
    np.testing.assert_allclose(y_curve.get_ydata(), -np.sin(theta), atol=1e-12)
    # the snapshots of a chain-like plot are the same motion
    phases, shapes = mode_snapshots(analysis.modes[1], 4)
    np.testing.assert_allclose(shapes, [[1, 0], [0, -1], [-1, 0], [0, 1]], atol=1e-12)
