"""Models whose equations hold t explicitly in CasADi (each Function takes t last) and in
optimize: the shaken pendulum's rhs(x, u, t) equals simulate's right-hand side, and a block
pushed against a known force F0 sin(w t) to rest d away takes the least effort of the closed
form (u linear in t, by Pontryagin: its costate is)."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import InputError

BLOCK = """
name = "Block on a floor, a known force F0 sin(w t) on it"
[coordinates]
x = { unit = "m", initial = 0.0, rate = 0.0 }
[parameters]
m = { value = 2.0, unit = "kg" }
F = { value = 0.0, unit = "N" }
F0 = { value = 3.0, unit = "N" }
w = { value = 4.0, unit = "rad/s" }
[[particles]]
name = "block"
mass = "m"
position = ["x", 0]
[[loads]]
name = "push"
point = "block"
force = ["F + F0*sin(w*t)", 0]
"""


@pytest.fixture(scope="module")
def shaken():
    system = lagrangian.load("support_pendulum")
    return system, system.to_casadi(inputs=["theta"]), system.numeric()


def test_the_shaken_pendulum_takes_t(shaken):
    system, functions, numeric = shaken
    assert functions.time_dependent and "time_dependent=True" in repr(functions)
    assert functions.rhs.name_in() == ["x", "u", "t"]
    assert functions.mass_matrix.name_in() == ["q", "t"]
    rng = np.random.default_rng(0)
    for _ in range(5):
        x, t = rng.uniform(-2, 2, 2), rng.uniform(0, 10)
        ours = numeric.rhs(t, x)
        assert np.allclose(np.asarray(functions.rhs(x, [0.0], t)).ravel(), ours, rtol=0,
                           atol=1e-12)
        # a torque u on theta adds u / (m L^2) to theta_ddot (m = 1 kg, L = 0.5 m)
        pushed = np.asarray(functions.rhs(x, [0.7], t)).ravel()
        assert pushed[1] - ours[1] == pytest.approx(0.7 / 0.25, rel=1e-12)
    # the support's motion is in the forcing, not in M
    assert float(functions.mass_matrix([0.3], 0.0)) == pytest.approx(0.25)


def closed_form(m, F0, w, T, d):
    """u = a + b t taking the block from rest at 0 to rest at d in T s against F0 sin(w t):
    v(T) = 0 and x(T) = d are linear in (a, b); the effort a^2 T + a b T^2 + b^2 T^3 / 3."""
    impulse = F0 * (1 - np.cos(w * T)) / w            # the integral of f
    moment = F0 * (T / w - np.sin(w * T) / w ** 2)     # the integral of (T - s) f(s)
    a, b = np.linalg.solve([[T, T ** 2 / 2], [T ** 2 / 2, T ** 3 / 6]],
                           [-impulse, m * d - moment])
    return a, b, a * a * T + a * b * T * T + b * b * T ** 3 / 3


@pytest.mark.parametrize("method", ["trapezoidal", "hermite-simpson"])
def test_the_pushed_block_takes_the_closed_forms_least_effort(method, tmp_path):
    path = tmp_path / "block.toml"
    path.write_text(BLOCK)
    system = lagrangian.load(path)
    result = lagrangian.optimize(system, ["F"], 2.0, 41, method=method,
                                 start={"x": 0, "x_dot": 0}, goal={"x": 1.0, "x_dot": 0})
    a, b, effort = closed_form(2.0, 3.0, 4.0, 2.0, 1.0)
    assert result.converged
    # second order, (w h)^2 / 12 = 3e-3 with h = 0.05 s; fourth order
    tolerance = 5e-3 if method == "trapezoidal" else 1e-6
    assert result.cost == pytest.approx(effort, rel=tolerance)
    assert np.allclose(result.inputs["F"], a + b * result.t, rtol=0, atol=30 * tolerance)
    assert result.defects["replay"] < 10 * tolerance
    # the force of t is the model's: simulate with the optimal push ends at rest at 1 m
    run = system.simulate(2.0, initial=result.initial_state(), controller=result.controller(),
                          rtol=1e-10, atol=1e-10)
    assert run.q[-1, 0] == pytest.approx(1.0, abs=10 * tolerance)


def test_the_time_functions_refuse_a_bad_t(shaken):
    _, functions, _ = shaken
    with pytest.raises(RuntimeError):
        functions.rhs([0.1, 0.0], [0.0])  # t is needed
    with pytest.raises(InputError, match="t_final must be positive"):
        lagrangian.optimize(lagrangian.load("support_pendulum"), ["theta"], -1.0, 10)
