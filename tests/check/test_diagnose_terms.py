"""Sharper diagnoses: each with a wrong answer that triggers it and a right one that does not.

- the small-angle equation is named a linearization, and no phrase divides by a fraction;
- a load left out of an equation, or projected wrongly, is named by its share of the virtual
  work, with its generalized force stated with one sign;
- a sign error in any single term of V is potential_sign naming its body or spring.
"""

from __future__ import annotations

import functools
import re

import pytest
from check_helpers import check_text, finding

from lagrangian import SystemBuilder
from lagrangian.model.answer import parse_answer

# -- (a) the small-angle form -------------------------------------------------------------


def test_small_angle_pendulum_is_a_linearization_and_the_full_equation_is_not():
    wrong = finding(check_text("pendulum", '[equations]\ntheta = "theta_ddot + g/L*theta = 0"\n'),
                    "equation[theta]")
    assert wrong.code == "equation_linearized"
    assert "small-angle" in wrong.message and "about theta = 0" in wrong.message
    right = check_text("pendulum", '[equations]\ntheta = "theta_ddot + g/L*sin(theta) = 0"\n')
    assert right.verdict == "correct"
    assert finding(right, "equation[theta]").code == "equation_equivalent"


def test_small_angle_double_pendulum_is_a_linearization():
    text = """
[equations]
theta1 = "(m1 + m2)*l1^2*theta1_ddot + m2*l1*l2*theta2_ddot + (m1 + m2)*g*l1*theta1 = 0"
theta2 = "m2*l1*l2*theta1_ddot + m2*l2^2*theta2_ddot + m2*g*l2*theta2 = 0"
"""
    report = check_text("double_pendulum", text)
    assert report.codes() == ["equation_linearized", "equation_linearized"], report
    assert "theta1 = 0, theta2 = 0" in finding(report, "equation[theta1]").message


def test_a_wrong_linear_coefficient_is_not_a_linearization():
    # g*L for g/L: wrong, and not the small-angle form of ours
    f = finding(check_text("pendulum", '[equations]\ntheta = "theta_ddot + g*L*theta = 0"\n'),
                "equation[theta]")
    assert f.code == "equation_wrong"


def _no_division_by_a_fraction(message: str) -> None:
    for divisor in re.findall(r"dividing yours by (\S+?)\)", message):
        assert "/" not in divisor, message


@pytest.mark.parametrize(("model", "equation", "multiplier"), [
    ("pendulum", "theta_ddot + g/L*theta^3 = 0", "L**2*m"),
    ("virtual_work_link", "theta_ddot = 3*F/(m*L)*cos(theta) + theta", "L**2*m/3"),
])
def test_a_rescaled_wrong_equation_is_multiplied_never_divided_by_a_fraction(model, equation,
                                                                              multiplier):
    f = finding(check_text(model, f'[equations]\ntheta = "{equation}"\n'), "equation[theta]")
    assert f.status == "wrong"
    assert f"after multiplying yours by {multiplier}" in f.message
    _no_division_by_a_fraction(f.message)


def test_an_integer_scale_may_still_be_divided_by():
    f = finding(check_text("pendulum", '[equations]\ntheta = "2*m*L^2*theta_ddot = 0"\n'),
                "equation[theta]")
    assert "after dividing yours by 2)" in f.message


# -- (b) a load traced by its share of the virtual work ------------------------------------


def test_load_left_out_of_the_equation_is_named_with_one_sign():
    # worked example 2: the tip force F does dW = F L cos(theta) dtheta
    f = finding(check_text("virtual_work_link", '[equations]\ntheta = "m*L^2/3*theta_ddot = 0"\n'),
                "equation[theta]")
    assert f.code == "generalized_force_missing"
    assert "the load 'F'" in f.message
    assert "Q[theta] = F*L*cos(theta)" in f.message
    assert "-F*L*cos(theta)" not in f.message  # one sign within the finding
    right = check_text("virtual_work_link",
                       '[equations]\ntheta = "m*L^2/3*theta_ddot = F*L*cos(theta)"\n')
    assert right.verdict == "correct"


def test_load_left_out_of_a_rescaled_equation_is_named():
    f = finding(check_text("virtual_work_link", '[equations]\ntheta = "theta_ddot = 0"\n'),
                "equation[theta]")
    assert f.code == "generalized_force_missing" and "'F'" in f.message
    _no_division_by_a_fraction(f.message)


def test_load_projected_with_sin_for_cos_is_named():
    f = finding(check_text("virtual_work_link",
                           '[equations]\ntheta = "theta_ddot = 3*F/(m*L)*sin(theta)"\n'),
                "equation[theta]")
    assert f.code == "generalized_force_projection"
    assert "'F'" in f.message and "F*L*cos(theta)" in f.message and "F*L*sin(theta)" in f.message
    assert "after multiplying yours by L**2*m/3" in f.message


def test_push_on_the_cart_left_out_of_its_equation_is_named():
    text = """
[equations]
x = "(M + m)*x_ddot + m*l*cos(theta)*theta_ddot - m*l*sin(theta)*theta_dot^2 = 0"
theta = "m*l*cos(theta)*x_ddot + m*l^2*theta_ddot + m*g*l*sin(theta) = 0"
"""
    report = check_text("cart_pendulum", text)
    assert finding(report, "equation[theta]").status == "correct"
    x = finding(report, "equation[x]")
    assert x.code == "generalized_force_missing" and "the load 'push'" in x.message
    right = check_text("cart_pendulum", text.replace("theta_dot^2 = 0", "theta_dot^2 = F"))
    assert right.verdict == "correct", right


@functools.cache
def _link_with_two_loads():
    """A link of length L pinned at one end, a horizontal force F at its tip and a torque tau."""
    b = SystemBuilder("Link with two loads")
    theta = b.coordinate("theta", unit="rad")
    m, L, F, tau = (b.parameter(n, v, u) for n, v, u in
                    (("m", 2.0, "kg"), ("L", 0.5, "m"), ("F", 100.0, "N"), ("tau", 3.0, "N*m")))
    import sympy as sp

    b.add_body("link", m, m * L**2 / 12, (L / 2 * sp.sin(theta), -L / 2 * sp.cos(theta)), theta)
    b.add_force("tip", (L * sp.sin(theta), -L * sp.cos(theta)), (F, 0))
    b.add_torque("motor", tau, theta)
    return b.build()


def _check(system, text):
    return system.check(parse_answer(text, system.model, source="<test>"))


@pytest.mark.parametrize(("rhs", "code", "load"), [
    ("tau", "generalized_force_missing", "'tip'"),
    ("F*L*cos(theta)", "generalized_force_missing", "'motor'"),
    ("F*L*sin(theta) + tau", "generalized_force_projection", "'tip'"),
])
def test_of_two_loads_the_one_that_differs_is_named(rhs, code, load):
    s = _link_with_two_loads()
    f = finding(_check(s, f'[equations]\ntheta = "m*L^2/3*theta_ddot = {rhs}"\n'),
                "equation[theta]")
    assert (f.code, load in f.message) == (code, True), f
    other = "'motor'" if load == "'tip'" else "'tip'"
    assert other not in f.message
    right = _check(s, '[equations]\ntheta = "m*L^2/3*theta_ddot = F*L*cos(theta) + tau"\n')
    assert right.verdict == "correct", right


def test_a_wrong_mass_term_is_not_blamed_on_a_load():
    f = finding(check_text("virtual_work_link",
                           '[equations]\ntheta = "m*L^2/3*theta_ddot + m*theta = F*L*cos(theta)"\n'),
                "equation[theta]")
    assert f.code == "equation_wrong"
    assert "has the extra term L**2*m*theta" not in f.message  # scaled like ours: m*theta


# -- (c) one term of V with the wrong sign ------------------------------------------------


def test_one_flipped_term_of_the_double_pendulums_V_names_its_bob():
    wrong = check_text("double_pendulum",
                       '[energy]\nV = "-(m1 + m2)*g*l1*cos(theta1) + m2*g*l2*cos(theta2)"\n')
    v = finding(wrong, "V")
    assert v.code == "potential_sign", wrong
    assert "'bob2'" in v.message and "'bob1'" not in v.message
    assert "Does V increase as the body rises?" in v.message
    right = check_text("double_pendulum",
                       '[energy]\nV = "-(m1 + m2)*g*l1*cos(theta1) - m2*g*l2*cos(theta2)"\n')
    assert finding(right, "V").status == "correct"


def test_the_shared_term_of_both_bobs_flipped_names_both():
    v = finding(check_text("double_pendulum",
                           '[energy]\nV = "(m1 + m2)*g*l1*cos(theta1) - m2*g*l2*cos(theta2)"\n'),
                "V")
    assert v.code == "potential_sign"
    assert "'bob1'" in v.message and "'bob2'" in v.message


def test_one_flipped_term_with_another_datum_is_still_a_sign_error():
    v = finding(check_text("double_pendulum",
                           '[energy]\nV = "7 - (m1 + m2)*g*l1*cos(theta1) + m2*g*l2*cos(theta2)"\n'),
                "V")
    assert v.code == "potential_sign" and "'bob2'" in v.message


def test_a_spring_of_the_wrong_sign_is_named():
    b = SystemBuilder("Two springs")
    x = b.coordinate("x", unit="m")
    m, k1, k2, g = (b.parameter(n, v, u) for n, v, u in
                    (("m", 1.0, "kg"), ("k1", 40.0, "N/m"), ("k2", 30.0, "N/m"),
                     ("g", 9.81, "m/s^2")))
    b.set_gravity(g, (0, -1)).add_particle("mass", m, (0, x))
    b.add_spring("upper", k1, 0, length=x)
    b.add_spring("lower", k2, 0, length=x)
    s = b.build()
    v = finding(_check(s, '[energy]\nV = "m*g*x + 1/2*k1*x^2 - 1/2*k2*x^2"\n'), "V")
    assert v.code == "potential_sign" and "'lower'" in v.message and "'upper'" not in v.message
    assert "Does the spring store 1/2 k s^2 >= 0" in v.message
    assert finding(_check(s, '[energy]\nV = "m*g*x + 1/2*k1*x^2 + 1/2*k2*x^2"\n'),
                   "V").status == "correct"


def test_a_missing_term_of_V_is_not_a_sign_error():
    v = finding(check_text("double_pendulum", '[energy]\nV = "-(m1 + m2)*g*l1*cos(theta1)"\n'),
                "V")
    assert v.code == "potential_term" and "missing" in v.message


def test_a_potential_force_left_out_of_an_equation_names_its_body():
    text = ('[equations]\ntheta2 = "m2*l1*l2*theta1_ddot*cos(theta1 - theta2) + m2*l2^2*theta2_ddot'
            ' - m2*l1*l2*theta1_dot^2*sin(theta1 - theta2) = 0"\n')
    f = finding(check_text("double_pendulum", text), "equation[theta2]")
    assert f.code == "equation_wrong"
    assert "lacks the term -g*l2*m2*sin(theta2)" in f.message
    assert "-dV/dtheta2 = -g*l2*m2*sin(theta2) of the gravity potential of 'bob2', left out" \
        in f.message
    right = check_text("double_pendulum", text.replace("= 0", "= -m2*g*l2*sin(theta2)"))
    assert right.verdict == "correct", right


def test_a_potential_force_with_the_wrong_sign_is_said_so():
    f = finding(check_text("pendulum", '[equations]\ntheta = "m*L^2*theta_ddot = m*g*L*sin(theta)"\n'),
                "equation[theta]")
    assert "yours has L*g*m*sin(theta) where ours has -L*g*m*sin(theta)" in f.message
    assert "with the wrong sign" in f.message
