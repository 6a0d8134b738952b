"""The right invariant is monitored: T + V, the Jacobi integral h, or the work balance
h - h0 - int P dt; JSON, CSV and the plot name which."""

from __future__ import annotations

import json

import numpy as np
import pytest

import lagrangian
from lagrangian.model.reader import parse_model


def run(system, t_end=5.0, **options):
    return system.simulate(t_end, rtol=1e-10, atol=1e-10, **options)


@pytest.mark.parametrize("name", ["bead_on_hoop", "charged_particle"])
def test_rotating_frame_and_magnetic_force_conserve_the_jacobi_integral(name):
    sim = run(lagrangian.load(name))
    summary = sim.summary()
    assert summary["invariant"] == "jacobi_integral"
    assert summary["relative_invariant_drift"] < 1e-7
    # no false alarm on T + V (it is not conserved here)
    assert summary["energy_conserved"] is False
    assert summary["relative_energy_drift"] is None


def test_bead_on_hoop_jacobi_integral_is_the_closed_form():
    system = lagrangian.load("bead_on_hoop")
    sim = run(system, 2.0)
    m, R, g, W = 0.1, 0.5, 9.81, 6.0
    theta, rate = sim["theta"], sim["theta_dot"]
    h = m * R**2 * (rate**2 - W**2 * np.sin(theta) ** 2) / 2 - m * g * R * np.cos(theta)
    assert np.allclose(sim["jacobi_integral"], h, rtol=1e-12, atol=1e-12)
    assert np.ptp(h) < 1e-8 * abs(h[0])


def test_damped_oscillator_work_balance_closes():
    sim = run(lagrangian.load("damped_oscillator"), 10.0)
    assert sim.summary()["invariant"] == "work_balance"
    assert sim.summary()["relative_invariant_drift"] < 1e-6
    # the energy lost is the work of the damper, int c x_dot^2 dt, to the sampling accuracy
    energy = sim["energy"]
    assert energy[-1] < 0.5 * energy[0]
    assert np.max(np.abs(sim["work_balance"])) < 1e-6 * energy[0]


DRIVEN = """
name = "Driven pendulum"
[coordinates]
theta = { unit = "rad", initial = 0.3 }
[parameters]
m = 1.0
L = 1.0
g = 9.81
A = 2.0
w = 2.5
[gravity]
g = "g"
[[particles]]
name = "bob"
mass = "m"
position = ["L*sin(theta)", "-L*cos(theta)"]
[[loads]]
name = "drive"
torque = "A*cos(w*t)"
angle = "theta"
"""


def test_driven_pendulum_balances_the_work_of_the_drive():
    sim = run(lagrangian.System(parse_model(DRIVEN)), 8.0)
    summary = sim.summary()
    assert summary["invariant"] == "work_balance"
    assert summary["relative_invariant_drift"] < 1e-6
    assert np.ptp(sim["energy"]) > 0.1  # the energy itself changes a lot


SKATER = """
name = "Figure skater pulling in her arms"
[coordinates]
phi = { unit = "rad", initial = 0.0, rate = 2.0 }
[parameters]
I0 = 3.0
a = 0.6
w = 1.5
[[bodies]]
name = "skater"
mass = 60
inertia = "I0*(1 - a*sin(w*t)^2)"
position = [0, 0]
angle = "phi"
"""


def test_figure_skater_conserves_angular_momentum():
    sim = run(lagrangian.System(parse_model(SKATER)), 6.0)
    t, rate = sim["t"], sim["phi_dot"]
    momentum = 3.0 * (1 - 0.6 * np.sin(1.5 * t) ** 2) * rate
    assert np.max(np.abs(momentum - momentum[0])) < 1e-8 * abs(momentum[0])
    assert np.ptp(rate) > 1.0  # she spins up and down
    assert sim.summary()["invariant"] == "work_balance"  # I(t): the energy is not conserved
    assert sim.summary()["relative_invariant_drift"] < 1e-6


def test_json_csv_and_plot_name_the_quantity(cli, tmp_path):
    table, plot = tmp_path / "run.csv", tmp_path / "run.png"
    code, out, _ = cli("simulate", "bead_on_hoop", "--t-end", "1", "--json", "--out", str(table))
    assert code == 0
    document = json.loads(out)
    assert document["invariant"] == "jacobi_integral"
    assert {"energy_conserved", "relative_energy_drift"} <= set(document)  # kept
    header = table.read_text().splitlines()[0].split(",")
    assert "jacobi_integral" in header and "energy" in header
    figure = lagrangian.load("bead_on_hoop").simulate(1.0).plot(str(plot))
    titles = [ax.get_title() for ax in figure.axes]
    assert any(title.startswith("Jacobi integral h = q_dot . dL/dq_dot - L, relative drift")
               for title in titles)


def test_text_summary_names_the_quantity(cli):
    code, out, _ = cli("simulate", "damped_oscillator", "--t-end", "2")
    assert code == 0
    assert "  work balance h - h0 - int P dt, relative drift: " in out
