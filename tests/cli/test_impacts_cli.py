"""`lagrangian cycle` and `simulate` on models with impacts: the JSON keys, the numbers against
closed forms, and bad input refused in one line (exit 2)."""

from __future__ import annotations

import json
import math

import pytest

G = 9.81


def test_cycle_json_of_the_rimless_wheel_at_a_slope_given_by_set(cli):
    code, out, err = cli("cycle", "rimless_wheel", "--set", "gamma=0.1", "--json")
    assert code == 0, err
    document = json.loads(out)
    assert {"state", "period", "multipliers", "stable"} <= set(document)
    alpha = math.pi / 8
    c = math.cos(2 * alpha)
    before = math.sqrt(4 * G * math.sin(alpha) * math.sin(0.1) / (1 - c * c))
    assert document["state"]["theta_dot"] == pytest.approx(c * before, rel=1e-8)
    # McGeer's stance from gamma - alpha to gamma + alpha from the vertical, by energy
    from scipy.integrate import quad

    period = quad(lambda phi: 1 / math.sqrt((c * before) ** 2 + 2 * G * (
        math.cos(0.1 - alpha) - math.cos(phi))), 0.1 - alpha, 0.1 + alpha,
        epsabs=1e-13, epsrel=1e-13)[0]
    assert document["period"] == pytest.approx(period, rel=1e-8)
    (re, im), = document["multipliers"]
    assert (re, im) == pytest.approx((c * c, 0.0), abs=1e-8)
    assert document["stable"] is True


def test_cycle_refuses_a_model_without_impacts(cli):
    code, out, err = cli("cycle", "pendulum")
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and "no impacts" in err and "Traceback" not in err


def test_cycle_refuses_a_bad_guess_name(cli):
    code, _, err = cli("cycle", "rimless_wheel", "--guess", "phi=0.1")
    assert code == 2 and err.startswith("error:") and "phi" in err


def test_simulate_json_lists_the_impacts(cli):
    code, out, err = cli("simulate", "bouncing_ball", "--t-end", "5", "--samples", "51",
                         "--json")
    assert code == 0, err
    document = json.loads(out)
    assert document["status"] == "accumulated"
    impacts = document["impacts"]
    t1 = math.sqrt(2 / G)
    assert impacts["accumulation_time"] == pytest.approx(t1 * 1.8 / 0.2, abs=1e-9)
    first = impacts["list"][0]
    assert set(first) == {"t", "name", "before", "after", "impulse", "energy_lost", "residual"}
    assert first["t"] == pytest.approx(t1, abs=1e-12) and first["name"] == "floor"
    assert impacts["count"] == len(impacts["list"])


def test_simulate_text_shows_the_impacts(cli):
    code, out, err = cli("simulate", "bouncing_ball", "--t-end", "1", "--samples", "11")
    assert code == 0, err
    assert "1 impact:" in out and "floor" in out and "t = 0.4515236409" in out


def test_impact_options_refused_without_impacts(cli):
    code, _, err = cli("simulate", "pendulum", "--t-end", "0.1", "--settle")
    assert code == 2 and "--settle" in err and "no [[impacts]]" in err


def test_setting_an_impacts_parameter_is_no_stray_setting(cli):
    code, _, err = cli("simulate", "bouncing_ball", "--set", "e=0.5", "--t-end", "0.1",
                       "--samples", "3")
    assert code == 0 and "appears in no equation" not in err
