"""simulate --control: the cart-pole balanced by LQR from the command line (JSON with K and the
promised eigenvalues), computed torque to a target, and bad flags refused in one line."""

from __future__ import annotations

import json

import numpy as np
import pytest


def test_lqr_from_the_command_line_balances_the_cart_pole(cli):
    result = cli("simulate", "cart_pendulum", "--t-end", "10", "--initial", "theta=3.0",
                 "--control", "lqr", "--about", "theta=pi", "--inputs", "F",
                 "--Q", "1,10,1,1", "--R", "0.1", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    control = document["control"]
    assert control["kind"] == "lqr" and control["inputs"] == ["F"]
    assert all(re < 0 for re, _ in control["closed_loop_eigenvalues"])
    final = document["final_state"]
    assert final["theta"] == pytest.approx(np.pi, abs=1e-3)
    assert final["x"] == pytest.approx(0.0, abs=1e-2)
    text = cli("simulate", "cart_pendulum", "--t-end", "1", "--control", "computed-torque",
               "--about", "x=0.3", "--kp", "25", "--kd", "10")
    assert text.code == 0, text.err
    assert "controller: computed torque on x, theta; closed-loop eigenvalues (1/s): -5" in text.out


@pytest.mark.parametrize("flags, message", [
    (["--control", "pid"], "error: --control: unknown controller 'pid'"),
    (["--Q", "3"], "error: --control: --Q is not used by a run without --control"),
    (["--control", "lqr", "--about", "theta=pi"], "error: --inputs: --control lqr needs --inputs"),
    (["--control", "lqr", "--about", "theta=pi", "--inputs", "F", "--R", "0"],
     "error: --R: the matrix must be positive definite"),
    (["--control", "lqr", "--about", "theta=pi", "--inputs", "F", "--Q", "1,2"],
     "error: --Q: expected a number, 4 diagonal entries or a 4 x 4 matrix"),
    (["--control", "lqr", "--about", "theta=pi", "--inputs", "F", "--R", "a"],
     "error: --R: expected a number or comma-separated numbers"),
    # weights whose squares overflow: refused by size, not a LinAlgError traceback
    (["--control", "lqr", "--about", "theta=pi", "--inputs", "F", "--Q", "1e308"],
     "error: --Q: an entry of 1e+308 is too large (at most 1e+100"),
    (["--control", "lqr", "--about", "theta=pi", "--inputs", "F", "--Q", "1e99"],
     "error: --Q: no stabilizing Riccati solution"),
    (["--control", "computed-torque", "--kp", "1e200"],
     "error: --kp: an entry of 1e+200 is too large"),
])
def test_bad_control_flags_are_one_line_errors(cli, flags, message):
    result = cli("simulate", "cart_pendulum", "--t-end", "1", *flags)
    assert result.code == 2
    assert result.err.strip().startswith(message), result.err
    assert len(result.err.strip().splitlines()) == 1


def test_linearize_along_from_the_command_line_is_the_pendulum_closed_form(cli):
    """x = (theta, theta_dot): A(t) = [[0, 1], [-g/L cos theta(t), 0]], B = [[0], [1/(m L^2)]]."""
    result = cli("simulate", "pendulum", "--t-end", "1", "--initial", "theta=1.0",
                 "--samples", "11", "--linearize-along", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    along = document["linearize_along"]
    assert along["states"] == ["theta", "theta_dot"] and along["inputs"] == ["theta"]
    A, B = np.array(along["A"]), np.array(along["B"])
    assert A.shape == (11, 2, 2) and B.shape == (11, 2, 1) and len(along["t"]) == 11
    import lagrangian

    theta = lagrangian.load("pendulum").simulate(1, initial={"theta": 1.0}, samples=11).q[:, 0]
    m, L, g = 1.0, 0.5, 9.81
    np.testing.assert_allclose(A[:, 1, 0], -g / L * np.cos(theta), rtol=1e-6)
    assert A[0, 1, 0] == pytest.approx(-g / L * np.cos(1.0), rel=1e-9)
    np.testing.assert_allclose(B[:, 1, 0], 1 / (m * L**2), rtol=1e-12)
    text = cli("simulate", "pendulum", "--t-end", "1", "--linearize-along")
    assert text.code == 0 and "linearized along the run: A(t) 2 x 2, B(t) 2 x 1" in text.out
    # a constrained model's through its multipliers: at the bottom, d x_ddot/dx = -g/L
    constrained = cli("simulate", "cartesian_pendulum", "--t-end", "1", "--initial",
                      "x=0,y=-0.5", "--samples", "3", "--linearize-along", "--json")
    assert constrained.code == 0, constrained.err
    A = np.array(json.loads(constrained.out)["linearize_along"]["A"])
    assert A.shape == (3, 4, 4) and A[0, 2, 0] == pytest.approx(-9.81 / 0.5, rel=1e-9)
