"""derive's text labels its lines so that a parameter never reads as a label: a length L beside
"L = T - V", a cart mass M beside "Mass matrix M" (issue 12)."""

from __future__ import annotations

import sympy as sp

import lagrangian
from lagrangian.output.derivation import derivation_text


def _text(name: str) -> list[str]:
    return derivation_text(lagrangian.load(name).equations_of_motion()).splitlines()


def test_a_parameter_L_is_not_taken_for_the_lagrangian():
    lines = _text("pendulum")
    assert not any(line.startswith("L = ") for line in lines)
    (line,) = [line for line in lines if line.startswith("Lagrangian T - V = ")]
    m, g, L, theta, theta_dot = sp.symbols("m g L theta theta_dot")
    printed = sp.sympify(line.split(" = ", 1)[1], locals={"L": L})
    # L = T - V = m L^2 theta_dot^2 / 2 + m g L cos(theta), the length L inside it
    assert sp.simplify(printed - (m * L**2 * theta_dot**2 / 2 + m * g * L * sp.cos(theta))) == 0


def test_a_parameter_M_is_not_taken_for_the_mass_matrix():
    lines = _text("cart_pendulum")
    assert "Mass matrix:" in lines and "Mass matrix M:" not in lines
    assert "Convention: (mass matrix) q_ddot + Phi_q^T lambda = (forcing)" in lines
    assert any(line.startswith("L = T - V = ") for line in lines)  # no L, T or V here


def test_without_a_clash_the_letters_stay():
    lines = _text("double_pendulum")
    assert "Mass matrix M:" in lines and "Forcing f:" in lines
    assert any(line.startswith("L = T - V = ") for line in lines)
    assert lines[-1] == "Convention: M q_ddot + Phi_q^T lambda = f"
