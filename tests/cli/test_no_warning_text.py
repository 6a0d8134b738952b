"""Odd numbers on the command line (1e308, inf, nan, 1e-320, 1e300 in --set, --Q, --kp, ...):
each answer or refusal comes without numpy's RuntimeWarning text around it, a refusal in one
line (issue 39: 13 refusals were several lines long). Found by fuzzing the CLI with these
numbers in --set, --initial, --q, --v, --Q, --R, --kp, --t-end, --about and --at."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest

ARM = Path(__file__).resolve().parents[2] / "src/lagrangian/model/examples/two_link_arm.urdf"
CART = ["cart_pendulum", "--t-end", "0.2", "--samples", "3", "--about", "theta=pi"]


def _quiet(cli, *args):
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")  # each warning shown, not once per place
        result = cli(*args)
    leaked = [str(w.message) for w in seen if issubclass(w.category, RuntimeWarning)]
    assert not leaked, leaked
    assert "Warning" not in result.err and "Traceback" not in result.err
    return result


@pytest.mark.parametrize(("args", "message"), [
    # m L^2 of L = 1e300 overflows: M is inf (was scipy's "array must not contain infs")
    (("modes", "pendulum", "--set", "L=1e300"), "error: the mass matrix M is not finite"),
    # M, K finite, M^-1 K = g/L = 2e308 not (was overflow and NaN warnings, then a NaN residual)
    (("modes", "pendulum", "--set", "g=1e308"), "error: the state matrix A = [0 I; -M^-1 K"),
    # Y holds m a = inf (was printed, after numpy's overflow warning in tau = Y pi)
    (("regressor", str(ARM), "--q", "0,0", "--v", "0,0", "--a", "1e308,1"),
     "error: the regressor Y is not finite at this state"),
    # J_dot q_dot goes as q_dot^2: 1e200 rad/s overflows (was -inf after numpy's warning)
    (("kinematics", str(ARM), "--v", "1e200,1"),
     "error: J_dot q_dot is not finite at this state"),
    (("simulate", *CART, "--control", "lqr", "--inputs", "F", "--Q", "inf"),
     "error: --Q: entries must be finite numbers"),
    (("simulate", *CART, "--control", "lqr", "--inputs", "F", "--R", "nan"),
     "error: --R: entries must be finite numbers"),
    (("simulate", *CART, "--control", "computed-torque", "--kp", "inf"),
     "error: --kp: entries must be finite numbers"),
    # Kp (x_d - x) = 100 * 1e308 overflows (was numpy's warning before the refusal)
    (("simulate", *CART[:-1], "x=1e308", "--control", "computed-torque"),
     "error: --control: the controller returned a value that is not finite at t = 0 s"),
])
def test_a_refusal_is_one_line_without_warnings(cli, args, message):
    result = _quiet(cli, *args)
    assert result.code == 2
    assert len(result.err.strip().splitlines()) == 1 and result.err.startswith(message)


def test_a_failed_run_of_a_huge_mass_says_why_without_warnings(cli):
    # m = 1e308: T overflows at the first step; simulate's verdict (exit 1) with the reason
    result = _quiet(cli, "simulate", "pendulum", "--t-end", "1", "--set", "m=1e308")
    assert result.code == 1
    assert "too large to integrate" in result.err


def test_a_huge_file_value_of_the_input_is_trimmed_quietly(cli):
    # the push F = 1e308 N in the file: the trim takes it off (F = 0 holds the upright); it
    # was taken as the trim, the 1e308 N residual judged against a scale that overflowed
    result = _quiet(cli, "modes", "cart_pendulum", "--about", "x=0,theta=pi", "--inputs", "F",
                    "--set", "F=1e308")
    assert result.code == 0, result.err
    assert "trim (the inputs' values that hold the equilibrium, SI): F = 0" in result.out
    result = _quiet(cli, "modes", "cart_pendulum", "--about", "x=0,theta=pi", "--set", "F=1e308")
    assert result.code == 2
    assert result.err.strip() == ("error: --about: not an equilibrium: the forces at rest do not "
                                  "balance (residual 1e+308 on x)")


def test_weights_of_text_or_below_double_range_are_one_line():
    # found by tests/fuzz/fuzz_trust.py: R = "abc" was numpy's ValueError; a subnormal R
    # overflowed K = R^-1 B^T S with a RuntimeWarning
    import math

    import lagrangian

    upright = lagrangian.load("cart_pendulum").linearize({"x": 0, "theta": math.pi},
                                                         inputs=["F"])
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        for R, message in (("abc", "expected a number, 1 diagonal entries or a 1 x 1 matrix of "
                                   "real numbers, got str"),
                           ([[1, 2], [3]], "matrix of real numbers, got list"),
                           (1j, "matrix of real numbers, got complex"),
                           (2.2e-309, "its smallest eigenvalue 2.2e-309 is too small")):
            with pytest.raises(lagrangian.InputError, match=re.escape(message)):
                lagrangian.lqr(upright, 1, R)


def test_a_run_through_impacts_with_an_energy_past_double_range_is_quiet(cli):
    # a ball started 1e308 m below its floor: V = m g y is -inf, T + V NaN, quietly (was
    # numpy's 'invalid value encountered in subtract' around the run's lines); it falls freely
    result = _quiet(cli, "simulate", "bouncing_ball", "--t-end", "0.5", "--initial", "y=-1e308",
                    "--samples", "3")
    assert result.code == 0, result.err
    assert "y_dot = -4.905" in result.out  # -g t, g = 9.81 m/s^2


def test_a_compiler_that_fails_is_one_warning_line(cli, tmp_path, monkeypatch):
    """A compiler that is there but fails: numpy runs (the same pendulum), and the CLI says so
    in one line `warning: C backend unavailable, ...` with the compiler's words, not Python's
    file:line, the message over three lines and the source line."""
    broken = tmp_path / "cc"
    broken.write_text("#!/bin/sh\necho 'cc1: out of memory' >&2\nexit 1\n")
    broken.chmod(0o755)
    monkeypatch.setenv("CC", str(broken))
    monkeypatch.setenv("LAGRANGIAN_CACHE", str(tmp_path / "cache"))
    from lagrangian.model.examples import example_text

    model = tmp_path / "pendulum.toml"  # its own equations: nothing compiled in this process
    model.write_text(example_text("pendulum").replace("theta", "phi_cc"))
    result = cli("simulate", str(model), "--t-end", "1", "--json")
    assert result.code == 0, result.err
    lines = result.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: C backend unavailable, using numpy")
    assert "cc1: out of memory" in lines[0]
    import json

    assert json.loads(result.out)["final_state"]["phi_cc"] == pytest.approx(-0.0910577687,
                                                                           abs=1e-8)
