"""Limit cycles through impacts: the rimless wheel's fixed point, period and multiplier in
closed form (McGeer), and the compass gait against an implementation written here from
Goswami's equations (the legs' M, the Coriolis and gravity terms, and the heel strike by
angular momentum conserved about the new foot and, for the old stance leg, about the hip)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

import lagrangian
from lagrangian.errors import InputError

G = 9.81


def rimless_closed_form(spokes: int, gamma: float, l: float = 1.0):
    """(omega+, period, multiplier): omega-^2 = omega+^2 + 4 g/l sin(alpha) sin(gamma),
    omega+ = cos(2 alpha) omega-, the stance from gamma - alpha to gamma + alpha from vertical;
    the return map omega+ -> cos(2 alpha) sqrt(omega+^2 + ...) has slope cos(2 alpha)^2."""
    alpha = math.pi / spokes
    c = math.cos(2 * alpha)
    before = math.sqrt(4 * G / l * math.sin(alpha) * math.sin(gamma) / (1 - c * c))
    after = c * before

    def rate(phi):
        return math.sqrt(after**2 + 2 * G / l * (math.cos(gamma - alpha) - math.cos(phi)))

    period = integrate.quad(lambda phi: 1 / rate(phi), gamma - alpha, gamma + alpha,
                            epsabs=1e-13, epsrel=1e-13)[0]
    return after, period, c * c


@pytest.fixture(scope="module")
def wheel():
    return lagrangian.load("rimless_wheel")


@pytest.mark.parametrize(("spokes", "gamma"), [(8, 0.08), (10, 0.1)])
def test_the_rimless_wheel_in_closed_form(wheel, spokes, gamma):
    system = wheel.with_parameters(spokes=spokes, gamma=gamma) if (spokes, gamma) != (8, 0.08) \
        else wheel
    omega, period, multiplier = rimless_closed_form(spokes, gamma)
    guess = {"theta": -math.pi / spokes, "theta_dot": 1.05 * omega}
    cycle = system.limit_cycle(guess)
    assert cycle.state["theta"] == pytest.approx(-math.pi / spokes, abs=1e-12)
    assert cycle.state["theta_dot"] == pytest.approx(omega, rel=1e-8)
    assert cycle.period == pytest.approx(period, rel=1e-8)
    assert len(cycle.multipliers) == 1
    assert cycle.multipliers[0] == pytest.approx(multiplier, abs=1e-8)
    assert cycle.stable and cycle.impact == "spoke"


def test_a_model_without_impacts_has_no_cycle():
    with pytest.raises(InputError, match="no impacts"):
        lagrangian.load("pendulum").limit_cycle()


def test_a_guess_that_falls_is_one_line(wheel):
    with pytest.raises(InputError) as caught:
        wheel.limit_cycle({"theta": -0.39, "theta_dot": -3.0})  # rolls back uphill for ever
    assert "\n" not in str(caught.value)


# -- the compass gait, written here from Goswami's equations ----------------------------------

M_LEG, M_HIP, A, B, GAMMA = 5.0, 10.0, 0.5, 0.5, 0.0525
L = A + B


def goswami_rhs(t, x, gamma=GAMMA):
    """M theta_ddot + C theta_dot + g = 0 in (stance, swing), each leg's foot-to-hip angle
    from the slope's normal (Goswami et al. 1998, in these angles)."""
    th1, th2, w1, w2 = x
    c, s = math.cos(th1 - th2), math.sin(th1 - th2)
    M = np.array([[M_LEG * A**2 + (M_HIP + M_LEG) * L**2, -M_LEG * L * B * c],
                  [-M_LEG * L * B * c, M_LEG * B**2]])
    coriolis = np.array([-M_LEG * L * B * s * w2**2, M_LEG * L * B * s * w1**2])
    gravity = np.array([-(M_LEG * A + M_HIP * L + M_LEG * L) * G * math.sin(th1 + gamma),
                        M_LEG * B * G * math.sin(th2 + gamma)])
    return [w1, w2, *np.linalg.solve(M, -coriolis - gravity)]


def _cross(r, v):
    return r[0] * v[1] - r[1] * v[0]


def heel_strike(x):
    """Angular momentum of the walker about the new foot, and of the old stance leg about the
    hip, conserved; the legs swap."""
    th1, th2, w1, w2 = x
    e1, e2 = np.array([math.sin(th1), math.cos(th1)]), np.array([math.sin(th2), math.cos(th2)])
    d1, d2 = np.array([math.cos(th1), -math.sin(th1)]), np.array([math.cos(th2), -math.sin(th2)])
    hip = L * e1
    foot = hip - L * e2
    points = [A * e1, hip, hip - B * e2]  # stance leg, hip, swing leg
    before = [A * w1 * d1, L * w1 * d1, L * w1 * d1 - B * w2 * d2]
    masses = [M_LEG, M_HIP, M_LEG]
    whole = sum(m * _cross(p - foot, v) for m, p, v in zip(masses, points, before, strict=True))
    leg = M_LEG * _cross(points[0] - hip, before[0])
    # after: new stance angle th2 (the old swing leg, foot at `foot`), new swing angle th1;
    # velocities linear in the new rates (u1, u2): v = P1 u1 + P2 u2
    per_rate = [(A * d2, np.zeros(2)), (L * d2, np.zeros(2)), (L * d2, -B * d1)]
    # the masses after, in the order [old swing leg, hip, old stance leg]
    order = [2, 1, 0]
    rows = np.zeros((2, 2))
    for k, (m, (p1, p2)) in enumerate(zip(masses, per_rate, strict=True)):
        p = points[order[k]]
        rows[0] += [m * _cross(p - foot, p1), m * _cross(p - foot, p2)]
    rows[1] = [M_LEG * _cross(points[0] - hip, per_rate[2][0]),
               M_LEG * _cross(points[0] - hip, per_rate[2][1])]
    u1, u2 = np.linalg.solve(rows, [whole, leg])
    return np.array([th2, th1, u1, u2])


def goswami_step(x, gamma=GAMMA):
    """The state just after the next heel strike and the time: th1 + th2 first falls below 0
    (the swing foot passes the stance leg's mirror image), then rises through it."""
    def mirror(t, y, _gamma):
        return y[0] + y[1]

    mirror.terminal = True
    t0, y0 = 0.0, np.asarray(x, dtype=float)
    for direction in (-1, 1):
        mirror.direction = direction
        run = integrate.solve_ivp(goswami_rhs, (t0, t0 + 5), y0, method="DOP853", rtol=1e-12,
                                  atol=1e-12, events=mirror, first_step=1e-6, args=(gamma,))
        t0, y0 = run.t_events[0][-1], run.y_events[0][-1]
    return heel_strike(y0), t0


@pytest.fixture(scope="module")
def gait():
    return lagrangian.load("compass_gait").limit_cycle()


def test_the_compass_gait_is_a_fixed_point_of_goswamis_step(gait):
    x = np.array(list(gait.state.values()))
    after, period = goswami_step(x)
    assert after == pytest.approx(x, abs=1e-7)
    assert gait.period == pytest.approx(period, abs=1e-8)
    assert x[0] == pytest.approx(-x[1], abs=1e-12)  # on the heel strike's guard


def goswami_multipliers(x, gamma=GAMMA):
    """Finite differences of the independent map here (the library uses none), less the
    section's 0."""
    h = 1e-6
    columns = [(goswami_step(x + h * e, gamma)[0] - goswami_step(x - h * e, gamma)[0]) / (2 * h)
               for e in np.eye(4)]
    eigenvalues = np.linalg.eigvals(np.array(columns).T)
    return sorted(eigenvalues[np.argsort(np.abs(eigenvalues))[1:]], key=lambda m: -abs(m))


def assert_same_multipliers(ours, theirs):
    assert len(ours) == len(theirs) == 3
    for mine in ours:
        assert min(abs(mine - other) for other in theirs) < 1e-5


def test_the_compass_gaits_multipliers_agree_with_goswamis_map(gait):
    x = np.array(list(gait.state.values()))
    assert_same_multipliers(gait.multipliers, goswami_multipliers(x))
    assert gait.stable


def test_the_compass_gait_at_a_slope_given_by_set(cli):
    """`cycle compass_gait --set gamma=0.03`: the fixed point, period and multipliers of
    Goswami's map at that slope (issue 41's must-show, the CLI as a user meets it)."""
    import json

    code, out, err = cli("cycle", "compass_gait", "--set", "gamma=0.03", "--json")
    assert code == 0, err
    document = json.loads(out)
    x = np.array(list(document["state"].values()))
    after, period = goswami_step(x, 0.03)
    assert after == pytest.approx(x, abs=1e-7)
    assert document["period"] == pytest.approx(period, abs=1e-8)
    assert_same_multipliers([complex(re, im) for re, im in document["multipliers"]],
                            goswami_multipliers(x, 0.03))
    assert document["stable"] is True


def test_a_driven_model_has_no_autonomous_cycle():
    from lagrangian.model.examples import example_text
    from lagrangian.model.reader import parse_model

    text = example_text("rimless_wheel").replace(
        '[[impacts]]', '[generalized_forces]\ntheta = "0.1*sin(t)"\n\n[[impacts]]')
    with pytest.raises(InputError, match="explicit time"):
        lagrangian.System(parse_model(text)).limit_cycle()


def test_a_cycle_search_from_the_models_own_start_names_it_not_a_guess():
    """The falling rod comes to rest: no cycle. Without --guess the refusal names the model's
    initial state (its coordinates), with one the guess."""
    rod = lagrangian.load("falling_rod")
    with pytest.raises(InputError) as caught:
        rod.limit_cycle()
    assert caught.value.field == "coordinates"
    with pytest.raises(InputError) as caught:
        rod.limit_cycle({"theta": 0.3})
    assert caught.value.field == "guess"
