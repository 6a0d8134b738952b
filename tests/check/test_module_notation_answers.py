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
