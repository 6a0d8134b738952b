"""`modes --steady` of a rolling coin written by a user (issue 21): its own coordinate names and
order, the no-slip constraints written by hand. Every printed mode keeps those constraints and
the lean-yaw mode is its closed form; the rigid-body modes are distinct shifts, free of noise."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

M, R, G = 2.0, 0.3, 9.81
I_DIAMETER, I_AXIS = M * R**2 / 4, M * R**2 / 2

COIN = """
name = "my coin"
[coordinates]
x = { unit = "m", initial = 0.0 }
y = { unit = "m", initial = 0.0 }
psi = { unit = "rad", initial = 0.0 }
theta = { unit = "rad", initial = 0.0 }
phi = { unit = "rad", initial = 0.0 }
[parameters]
m = { value = 2.0, unit = "kg" }
r = { value = 0.3, unit = "m" }
g = { value = 9.81, unit = "m/s^2" }
[gravity]
g = "g"
direction = [0, 0, -1]
[[bodies]]
name = "disc"
mass = "m"
inertia = ["m*r^2/4", "m*r^2/2", "m*r^2/4"]
position = ["x + r*sin(psi)*sin(theta)", "y - r*cos(psi)*sin(theta)", "r*cos(theta)"]
rotation = [["z", "psi"], ["x", "theta"], ["y", "phi"]]
[[constraints]]
name = "roll_x"
velocity = "x_dot - r*phi_dot*cos(psi)"
[[constraints]]
name = "roll_y"
velocity = "y_dot - r*phi_dot*sin(psi)"
"""


@pytest.fixture(scope="module")
def coin_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("coin") / "coin.toml"
    path.write_text(COIN, encoding="utf-8")
    return path


def printed_modes(cli, path, spin_rate):
    code, out, err = cli("modes", str(path), "--about", "theta=0", "--steady",
                         f"phi_dot={spin_rate},x_dot={spin_rate * R}", "--json")
    assert code == 0, err
    document = json.loads(out)
    names = document["coordinates"]
    modes = []
    for mode in document["modes"]:
        shape = np.array([mode["amplitude"][n] * np.exp(1j * mode["phase"][n]) for n in names])
        # the eigenvalue of the printed (complex) shape: s = sigma + i omega_d
        omega, zeta = mode["frequency"], mode["damping_ratio"] or 0.0
        s = complex(-zeta * omega, omega * math.sqrt(max(1 - zeta**2, 0.0)))
        modes.append((s, dict(zip(names, shape, strict=True))))
    return modes


@pytest.mark.parametrize("spin_rate", [4.0, 10.0])
def test_every_printed_mode_keeps_the_hand_written_rolling_constraints(cli, coin_path, spin_rate):
    """x_dot = r phi_dot cos(psi), y_dot = r phi_dot sin(psi) about psi = 0, phi_dot = W:
    dx_dot = r dphi_dot, dy_dot = r W dpsi; a mode u e^(st) has s u_x = r s u_phi and
    s u_y = r W u_psi (a rigid shift, s = 0, never turns the heading)."""
    for s, u in printed_modes(cli, coin_path, spin_rate):
        size = max(abs(v) for v in u.values()) * (1 + abs(s))
        assert abs(s * u["x"] - R * s * u["phi"]) <= 1e-9 * size
        assert abs(s * u["y"] - R * spin_rate * u["psi"]) <= 1e-9 * size


@pytest.mark.parametrize("spin_rate", [4.0, 10.0])
def test_the_lean_yaw_mode_is_its_closed_form(cli, coin_path, spin_rate):
    """omega^2 = (I_a (I_a + m r^2) W^2 / I_d - m g r) / (I_d + m r^2); lean over yaw
    omega I_d / (I_a W), a quarter period behind; the contact point's side step y over yaw
    r W / omega (from dy_dot = r W dpsi)."""
    omega = math.sqrt((I_AXIS * (I_AXIS + M * R**2) * spin_rate**2 / I_DIAMETER - M * G * R)
                      / (I_DIAMETER + M * R**2))
    (mode,) = [(s, u) for s, u in printed_modes(cli, coin_path, spin_rate) if s != 0]
    s, u = mode
    assert s.imag == pytest.approx(omega, rel=1e-10) and s.real == 0
    ratio = u["theta"] / u["psi"]
    assert abs(ratio) == pytest.approx(omega * I_DIAMETER / (I_AXIS * spin_rate), rel=1e-9)
    assert np.angle(ratio, deg=True) == pytest.approx(-90.0, abs=1e-7)
    assert abs(u["y"] / u["psi"]) == pytest.approx(R * spin_rate / omega, rel=1e-9)


def test_the_rigid_body_modes_are_distinct_clean_shifts(cli, coin_path):
    """Rolling on, sliding the whole coin along x or y, or turning it about its axle leave the
    steady motion a steady motion: the zero-frequency modes are such shifts, each a different
    one, with no round-off left in the other coordinates (LAPACK repeated one and left 1e-8
    of the heading in it)."""
    rigid = [u for s, u in printed_modes(cli, coin_path, 4.0) if s == 0]
    assert len(rigid) == 3
    shapes = np.array([[u[n] for n in ("x", "y", "psi", "theta", "phi")] for u in rigid])
    assert np.linalg.matrix_rank(shapes, tol=1e-6) == 3
    assert np.all((shapes == 0) | (np.abs(shapes) > 1e-6))  # no round-off entries
    assert np.all(shapes[:, 2:4] == 0)  # neither heading nor lean
