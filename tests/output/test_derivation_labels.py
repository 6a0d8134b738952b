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


LENGTH_L_MASS_M = """
name = "Cart with a pendulum of length L"
[coordinates]
x = "m"
theta = "rad"
[parameters]
M = 2.0
m = 0.5
L = 0.6
g = 9.81
[gravity]
g = "g"
direction = [0, -1]
[[particles]]
name = "cart"
mass = "M"
position = ["x", 0]
[[particles]]
name = "bob"
mass = "m"
position = ["x + L*sin(theta)", "-L*cos(theta)"]
"""


def test_lagranges_equations_do_not_name_a_parameter_L():
    eom = lagrangian.System(lagrangian.parse_model(LENGTH_L_MASS_M)).equations_of_motion()
    lines = derivation_text(eom).splitlines()
    assert "Equations of motion, d/dt(d(T - V)/dq_dot) - d(T - V)/dq = Q:" in lines
    assert not any("dL/dq" in line for line in lines)
    assert "Mass matrix:" in lines


def test_latex_sets_clashing_letters_apart():
    from lagrangian.output.derivation import derivation_latex

    eom = lagrangian.System(lagrangian.parse_model(LENGTH_L_MASS_M)).equations_of_motion()
    latex = derivation_latex(eom)
    assert r"\mathcal{L} &= T - V = " in latex and "\nL &=" not in latex
    assert r"\mathbf{M} &= " in latex and "\nM &=" not in latex
    plain = derivation_latex(lagrangian.load("double_pendulum").equations_of_motion())
    assert "\nL &= T - V = " in plain and "\nM &= " in plain


def test_modes_drop_a_matrix_letter_a_coordinate_uses():
    from lagrangian.output.modes import modes_text

    model = LENGTH_L_MASS_M.replace('x = "m"', 'K = "m"').replace('"x', '"K').replace(
        'position = ["K", 0]', 'position = ["K", 0]')
    text = modes_text(lagrangian.System(lagrangian.parse_model(model + """
[[springs]]
name = "s"
stiffness = 10
rest_length = 0
length = "K"
""")).modes())
    assert "Stiffness matrix:" in text and "Stiffness matrix K" not in text
    assert "Mass matrix M:" in text  # modes prints no parameter: only numbers follow "M"
