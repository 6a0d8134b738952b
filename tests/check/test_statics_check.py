"""check on a mechanism without inertia (statics by virtual work): a massless slider-crank held by
a crank torque tau and a piston force P through two loop constraints."""

from __future__ import annotations

import pytest

from lagrangian.cli import main
from statics_models import SLIDER_CRANK as CRANK

# By hand: Q = (tau, 0, P) from delta W = tau delta theta + P delta x, and Phi_q^T lambda with
# Phi_q = [[r cos(theta), -l cos(phi), 0], [r sin(theta), l sin(phi), 1]]; no inertia, so
# Phi_q^T lambda = Q.
RIGHT = """
[equations]
theta = "lambda_loop_y*r*cos(theta) + lambda_loop_x*r*sin(theta) - tau = 0"
phi = "-lambda_loop_y*l*cos(phi) + lambda_loop_x*l*sin(phi) = 0"
x = "lambda_loop_x - P = 0"
[multipliers]
count = 2
"""


def run(tmp_path, answer: str, capsys) -> tuple[int, str]:
    model = tmp_path / "crank.toml"
    model.write_text(CRANK)
    path = tmp_path / "answer.toml"
    path.write_text(answer)
    with pytest.raises(SystemExit) as stop:
        main(["check", str(model), str(path)])
    return stop.value.code, capsys.readouterr().out


def test_a_right_hand_derivation_of_a_massless_mechanism_is_accepted(tmp_path, capsys):
    code, out = run(tmp_path, RIGHT, capsys)
    assert code == 0 and "verdict: correct" in out


def test_a_sign_error_in_a_load_of_a_massless_mechanism_is_found(tmp_path, capsys):
    code, out = run(tmp_path, RIGHT.replace("lambda_loop_x - P", "lambda_loop_x + P"), capsys)
    assert code != 0 and "verdict: incorrect" in out
    assert "equation[x]" in out


def test_generalized_forces_of_a_massless_mechanism(tmp_path, capsys):
    code, out = run(tmp_path, '[generalized_forces]\ntheta = "tau"\nphi = "0"\nx = "P"\n', capsys)
    assert code == 0 and "verdict: correct" in out
    code, out = run(tmp_path, '[generalized_forces]\ntheta = "tau"\nphi = "0"\nx = "0"\n', capsys)
    assert code != 0 and "verdict: incorrect" in out
