"""The Poincare map built once per equations and parameter values (analysis/limit_cycle.py):
a second cycle reuses it and finds the same orbit; other parameter values get their own map,
so the rimless wheel's period follows its slope (McGeer) while its multiplier cos^2(2 alpha)
does not; the variational flow's Phi(T) against the flow's central differences."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

import lagrangian
from lagrangian.analysis import limit_cycle as module

G = 9.81


def mcgeer(spokes: int, gamma: float) -> tuple[float, float]:
    """(omega+, period) of the rimless wheel with l = 1 m."""
    alpha = math.pi / spokes
    c = math.cos(2 * alpha)
    after = c * math.sqrt(4 * G * math.sin(alpha) * math.sin(gamma) / (1 - c * c))
    period = integrate.quad(lambda phi: 1 / math.sqrt(after**2 + 2 * G * (
        math.cos(gamma - alpha) - math.cos(phi))), gamma - alpha, gamma + alpha,
        epsabs=1e-13, epsrel=1e-13)[0]
    return after, period


@pytest.fixture(scope="module")
def wheel():
    return lagrangian.load("rimless_wheel")


def test_a_second_cycle_reuses_the_map_and_finds_the_same_orbit(wheel):
    first = wheel.limit_cycle()
    maps = dict(module._MAPS)
    second = wheel.limit_cycle()
    assert dict(module._MAPS) == maps  # nothing rebuilt
    assert second.state == first.state and second.period == first.period


@pytest.mark.parametrize("gamma", [0.1, 0.12])
def test_other_parameter_values_get_their_own_map(wheel, gamma):
    wheel.limit_cycle()
    cycle = wheel.with_parameters(gamma=gamma).limit_cycle(
        {"theta": -math.pi / 8, "theta_dot": 1.05 * mcgeer(8, gamma)[0]})
    omega, period = mcgeer(8, gamma)
    assert cycle.state["theta_dot"] == pytest.approx(omega, rel=1e-8)
    assert cycle.period == pytest.approx(period, rel=1e-8)
    assert cycle.multipliers[0] == pytest.approx(math.cos(math.pi / 4) ** 2, abs=1e-8)


def test_the_variational_flow_is_the_flows_derivative():
    """Phi(T) from FlowSensitivity.rhs against central differences of the compiled flow."""
    gait = lagrangian.load("compass_gait")
    cycle = gait.limit_cycle()
    flow = next(entry[2] for entry in module._MAPS.values()
                if entry[0] is gait.equations_of_motion()).flow
    x = np.array(list(cycle.state.values()))
    T, rtol = 0.3, 1e-12

    def run(fun, y0):
        return integrate.solve_ivp(fun, (0, T), y0, method="DOP853", rtol=rtol,
                                   atol=rtol).y[:, -1]

    Phi = run(flow.rhs, np.concatenate([x, np.eye(4).ravel()]))[4:].reshape(4, 4)
    step = 1e-6
    columns = [(run(gait._numeric.rhs, x + step * e) - run(gait._numeric.rhs, x - step * e))
               / (2 * step) for e in np.eye(4)]
    assert Phi == pytest.approx(np.array(columns).T, abs=1e-6)
