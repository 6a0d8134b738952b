"""The built-in falling rod against closed forms: its first impact's time, the velocities after
it (angular momentum about the striking end kept: omega+ = -3 (1 + e) v cos(theta) / (2 L)),
the impulse and the energy lost; a run that never passes through the floor with either end."""

from __future__ import annotations

import math

import numpy as np
import pytest

import lagrangian

G, M, L = 9.81, 1.0, 1.0
Y0, THETA = 1.0, 0.3  # the example's drop: centre 1 m up, tilted 0.3 rad


@pytest.fixture(scope="module")
def rod():
    return lagrangian.load("falling_rod")


def closed_form(e: float, theta: float = THETA, y0: float = Y0):
    """(t, v, (x_dot, y_dot, omega) after) of the first strike of the lower end from rest: the
    end's velocity after is (0, e v) (stick), and the impulse passes through the end, so the
    angular momentum about it, -m v (L/2) cos(theta), is kept: (m L^2/3) omega = -(1 + e) m v
    (L/2) cos(theta)."""
    t = math.sqrt(2 * (y0 - L / 2 * math.sin(theta)) / G)
    v = G * t
    omega = -3 * (1 + e) * v * math.cos(theta) / (2 * L)
    return t, v, (-omega * L / 2 * math.sin(theta), e * v + omega * L / 2 * math.cos(theta), omega)


def about_end(state: dict, theta: float) -> float:
    """Angular momentum about the lower end (at (-L/2 cos, -L/2 sin) from the centre)."""
    rx, ry = L / 2 * math.cos(theta), L / 2 * math.sin(theta)  # centre from the end
    return M * (rx * state["y_dot"] - ry * state["x_dot"]) + M * L**2 / 12 * state["theta_dot"]


@pytest.mark.parametrize("e", [0.0, 0.5])
def test_the_first_strike_in_closed_form(rod, e):
    run = rod.with_parameters(e=e).simulate(0.5)
    first = run.impacts[0]
    t, v, (x_dot, y_dot, omega) = closed_form(e)
    assert first.name == "end_a" and first.time == pytest.approx(t, abs=1e-10)
    assert first.before["y_dot"] == pytest.approx(-v, rel=1e-9)
    assert first.after["theta_dot"] == pytest.approx(omega, rel=1e-9)
    assert first.after["x_dot"] == pytest.approx(x_dot, rel=1e-9)
    assert first.after["y_dot"] == pytest.approx(y_dot, rel=1e-9, abs=1e-12)
    assert about_end(first.after, THETA) == pytest.approx(about_end(first.before, THETA),
                                                          rel=1e-9)
    assert first.impulse == pytest.approx([M * x_dot, M * (y_dot + v)], rel=1e-9)
    kinetic = 0.5 * M * (x_dot**2 + y_dot**2) + 0.5 * M * L**2 / 12 * omega**2
    assert first.energy_lost == pytest.approx(0.5 * M * v**2 - kinetic, rel=1e-9)
    assert first.residual < 1e-12


def test_falling_flat_onto_a_corner_turns_at_3v_over_2l():
    """theta -> 0, e = 0: omega+ = 3 v / 2 L, the issue's closed form (cos(theta) = 1)."""
    t, v, (_, _, omega) = closed_form(0.0, theta=1e-6)
    assert abs(omega) == pytest.approx(3 * v / (2 * L), rel=1e-11)
    run = lagrangian.load("falling_rod").with_parameters(e=0).simulate(
        0.5, initial={"theta": 1e-6})
    assert run.impacts[0].after["theta_dot"] == pytest.approx(omega, rel=1e-9)


@pytest.mark.parametrize(("e", "t_end"), [(0.5, 3.0), (0.5, 10.0), (0.8, 10.0)])
def test_neither_end_passes_through_the_floor(rod, e, t_end):
    """The rod tumbles, both ends striking in turn, until the strikes accumulate; after each
    strike the other end's fall (even within the first step) and a second end near the floor
    are seen."""
    run = rod.with_parameters(e=e).simulate(t_end)
    y, theta = run.q[:, 1], run.q[:, 2]
    for end in (y - L / 2 * np.sin(theta), y + L / 2 * np.sin(theta)):
        assert end.min() > -1e-9
    assert {r.name for r in run.impacts} == {"end_a", "end_b"}
    assert run.status == "accumulated" and "comes to rest" in run.message
    assert all(r.energy_lost > -1e-9 for r in run.impacts)  # e < 1 with stick: never a gain
