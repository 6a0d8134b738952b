"""Answers written as the course module prints them (issue 40): [energy] L checked as T - V,
symbolic frequencies in the model's parameters, implicit products, cosθ, √, ½, −; a prime gets
the spelling to use."""

from __future__ import annotations

import pytest
from check_helpers import check_text, finding

from lagrangian.errors import ModelError

LADDER_3 = '''
[energy]
L = "½ m ẋ² − ½ k x²"
[equations]
x = "m ẍ + k x = 0"
[frequencies]
omega = ["sqrt(k/m)"]
'''

# Worked example 1 exactly as the module prints its model, equation and result.
WORKED_EXAMPLE_1 = '''
[energy]
T = "½ m L² θ̇²"
V = "−m g L cosθ"
[equations]
theta = "θ̈ = −(g/L) sinθ"
[frequencies]
omega = ["√(g/L)"]
'''


def test_ladder_3_with_the_lagrangian_and_a_symbolic_frequency_is_correct():
    report = check_text("ladder_spring_mass", LADDER_3)
    assert report.correct, report
    assert finding(report, "L").status == "correct"
    assert "parameter values" in finding(report, "omega[1]").message


def test_worked_example_1_typed_as_the_module_prints_it_is_correct():
    report = check_text("pendulum", WORKED_EXAMPLE_1)
    assert report.correct, report
    assert {f.item for f in report.findings} >= {"T", "V", "equation[theta]", "omega[1]"}


@pytest.mark.parametrize(("lagrangian", "code", "words"), [
    ("½ m ẋ² + ½ k x²", "potential_sign", "T + V"),
    ("m ẋ² − ½ k x²", "kinetic_factor", "forgotten 1/2"),
    ("½ m ẋ² − k x²", "potential_term", "the potential energy in your L"),
])
def test_a_wrong_lagrangian_is_diagnosed_by_its_part(lagrangian, code, words):
    report = check_text("ladder_spring_mass", f'[energy]\nL = "{lagrangian}"\n')
    L = finding(report, "L")
    assert L.status == "wrong" and L.code == code, L
    assert words in L.message


def test_a_symbolic_frequency_that_is_wrong_is_wrong_and_a_state_is_refused():
    report = check_text("ladder_spring_mass", '[frequencies]\nomega = ["sqrt(m/k)"]\n')
    assert finding(report, "omega[1]").code == "frequency_wrong"
    with pytest.raises(ModelError, match="parameters only, not x"):
        check_text("ladder_spring_mass", '[frequencies]\nomega = ["sqrt(k/x)"]\n')


@pytest.mark.parametrize("written", ["theta'", "θ'", "θ′"])
def test_a_prime_gets_the_spelling_hint(written):
    with pytest.raises(ModelError, match="a prime is not read: write theta_dot") as error:
        check_text("pendulum", f'[energy]\nT = "1/2*m*L^2*{written}^2"\n')
    assert error.value.field == "energy.T"


def test_implicit_products_read_as_the_module_means_them():
    text = '[energy]\nT = "½ m L² θ̇²"\nV = "m g L (1 − cos θ)"\n'
    report = check_text("pendulum", text)
    assert finding(report, "T").status == "correct"
    assert finding(report, "V").status == "equivalent"  # another datum
    with pytest.raises(ModelError, match="energy.T"):  # still refused: nothing to read
        check_text("pendulum", '[energy]\nT = "½ m L² θ̇² +"\n')


@pytest.mark.parametrize("model", ["pendulum", "two_mass", "double_pendulum", "bead_on_hoop"])
def test_what_conserved_prints_in_the_modules_notation_reads_back(model):
    """The printer (output/module_notation.py) and the answer reader agree: T and V printed as
    the module writes them are checked correct."""
    from check_helpers import system

    from lagrangian.output.module_notation import module_notation

    eom = system(model).equations_of_motion()
    T, V = module_notation(eom.kinetic_energy), module_notation(eom.potential_energy)
    report = check_text(model, f'[energy]\nT = "{T}"\nV = "{V}"\n')
    assert report.correct, (T, V, report)


# Lagrange's equation as the module writes it, d/dt(dL/dq_dot) - dL/dq = 0, d/dt read as the
# total time derivative (sum dE/dq q_dot + dE/dq_dot q_ddot).
@pytest.mark.parametrize(("model", "coordinate", "equation"), [
    ("pendulum", "theta", "d/dt(m L² θ̇) + m g L sinθ = 0"),
    ("pendulum", "theta", "d/dt(m*L^2*theta_dot) = -m*g*L*sin(theta)"),
    ("ladder_spring_mass", "x", "d/dt(m ẋ) + k x = 0"),
    # the double pendulum's p_theta1 depends on theta1 - theta2: the product rule's terms
    ("double_pendulum", "theta1", "d/dt((m₁ + m₂) l₁² θ̇₁ + m₂ l₁ l₂ θ̇₂ cos(θ₁ − θ₂)) "
                                  "+ m₂ l₁ l₂ θ̇₁ θ̇₂ sin(θ₁ − θ₂) + (m₁ + m₂) g l₁ sinθ₁ = 0"),
])
def test_the_modules_lagrange_equation_with_d_dt_is_read(model, coordinate, equation):
    report = check_text(model, f'[equations]\n{coordinate} = "{equation}"\n')
    assert finding(report, f"equation[{coordinate}]").status == "correct", report


def test_a_d_dt_equation_with_a_slip_is_wrong_and_of_an_acceleration_refused():
    # d/dt(p) + dL/dq: the sign of the gravity term flipped
    report = check_text("pendulum", '[equations]\ntheta = "d/dt(m L² θ̇) − m g L sinθ = 0"\n')
    assert finding(report, "equation[theta]").status == "wrong"
    # the cross term's q-dependence left out: d/dt taken as if cos(θ1 − θ2) were constant
    wrong = ("(m₁ + m₂) l₁² θ̈₁ + m₂ l₁ l₂ θ̈₂ cos(θ₁ − θ₂) "
             "+ m₂ l₁ l₂ θ̇₁ θ̇₂ sin(θ₁ − θ₂) + (m₁ + m₂) g l₁ sinθ₁ = 0")
    right = ("d/dt((m₁ + m₂) l₁² θ̇₁ + m₂ l₁ l₂ θ̇₂ cos(θ₁ − θ₂)) "
             "+ m₂ l₁ l₂ θ̇₁ θ̇₂ sin(θ₁ − θ₂) + (m₁ + m₂) g l₁ sinθ₁ = 0")
    assert finding(check_text("double_pendulum", f'[equations]\ntheta1 = "{wrong}"\n'),
                   "equation[theta1]").status == "wrong"
    assert finding(check_text("double_pendulum", f'[equations]\ntheta1 = "{right}"\n'),
                   "equation[theta1]").status == "correct"
    with pytest.raises(ModelError, match="of an acceleration is not read") as error:
        check_text("pendulum", '[equations]\ntheta = "d/dt(m L² θ̈) = 0"\n')
    assert error.value.field == "equations.theta"


def test_a_period_with_2_pi_glued_and_shapes_in_roots_as_the_module_writes_them():
    # period 2 pi sqrt(m/k) = 1.2566 s (m = 2 kg, k = 50 N/m); 2π √(k/m) is 31.4, wrong
    assert finding(check_text("ladder_spring_mass", '[frequencies]\nperiod = ["2π √(m/k)"]\n'),
                   "period[1]").status == "correct"
    assert finding(check_text("ladder_spring_mass", '[frequencies]\nperiod = ["2π √(k/m)"]\n'),
                   "period[1]").code == "frequency_wrong"
    # sin 2θ is sin(2θ) = 2 sinθ cosθ (not sin(2) θ): this T is ½ m L² θ̇²
    text = '[energy]\nT = "½ m L² θ̇² (2 − 2 sinθ cosθ/sin 2θ)"\n'
    assert finding(check_text("pendulum", text), "T").status == "correct"
    # the double pendulum (equal masses and lengths): theta2/theta1 = +-sqrt(2)
    report = check_text("double_pendulum", '[mode_shapes]\nshapes = [[1, "√2"], [1, "−√2"]]\n')
    assert report.correct, report
    report = check_text("double_pendulum", '[mode_shapes]\nshapes = [[1, "√3"], [1, "−√2"]]\n')
    assert finding(report, "shape[1]").status == "wrong"
    # in the model's parameters (l1 = l2 = 1 m): taken at their values, and said so
    report = check_text("double_pendulum", '[mode_shapes]\nshapes = [[1, "√2 l₁/l₂"], [1, "−√2"]]\n')
    assert "at the model's parameter values" in finding(report, "shape[1]").message
    assert finding(report, "shape[1]").status == "correct"
    # a unit glued after a number is still a unit: 2 µs is 2e-6 s, not the period
    assert finding(check_text("ladder_spring_mass", '[frequencies]\nperiod = ["2 µs"]\n'),
                   "period[1]").code == "frequency_wrong"
