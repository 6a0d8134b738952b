"""What students type: Unicode spellings (θ, θ̇, θ̈, ½, ², ·, −, ...) read as the grammar's ASCII
names and operators, or refused with the ASCII spelling to use (issue 20, item 7)."""

from __future__ import annotations

import pytest
import sympy as sp

from lagrangian.errors import ModelError
from lagrangian.model.expressions import parse_expression

NAMES = {name: sp.Symbol(name) for name in (
    "theta", "theta_dot", "theta_ddot", "phi", "omega", "omega_n", "lambda_rod", "x1", "x1_dot",
    "x1_ddot", "theta1_dot", "m", "L", "g", "k", "mu", "Omega")}


def read(text: str) -> sp.Expr:
    return parse_expression(text, NAMES, field="energy.T", source="answer.toml")


@pytest.mark.parametrize(("typed", "ascii_spelling"), [
    ("½·m·L²·θ̇²", "1/2*m*L**2*theta_dot**2"),             # the seed's T of worked example 1
    ("−m·g·L·cos(θ)", "-m*g*L*cos(theta)"),                # its V, with a typographic minus
    ("θ̈ + g/L·θ", "theta_ddot + g/L*theta"),               # the small-angle equation
    ("φ × ω", "phi*omega"),
    ("λ_rod", "lambda_rod"),
    ("ωₙ", "omega_n"),
    ("μ·Ω", "mu*Omega"),
    ("ẋ₁²", "x1_dot**2"),                                  # precomposed x with dot, subscript 1
    ("ẍ₁", "x1_ddot"),
    ("θ̇₁", "theta1_dot"),
    ("L⁻¹", "L**(-1)"),
    ("(θ + 1)²", "(theta + 1)**2"),
    ("k·x1³", "k*x1**3"),
    ("m ÷ k", "m/k"),
    ("m ∗ g", "m*g"),
    ("¼·k", "1/4*k"),
    ("π·θ", "pi*theta"),
    ("𝜃 + ｍ", "theta + m"),                               # mathematical italic, fullwidth
])
def test_unicode_spelling_reads_as_its_ascii_name(typed, ascii_spelling):
    assert sp.simplify(read(typed) - read(ascii_spelling)) == 0


@pytest.mark.parametrize(("typed", "hint"), [
    ("θ′", "write theta_dot for a rate"),
    ("θ″", "write theta_ddot"),
    ("√g", "write sqrt(...)"),
    ("30°", "30*pi/180"),
    ("x̂", "accents are not read"),
    ("é", "accents are not read"),
    ("λ", "lambda_<constraint>"),
    ("½m", "write 1/2*... to multiply"),
    ("L²m", "write * to multiply"),
    ("2½", "write 2 + 1/2"),
    ("θ⃛", "accents are not read"),
    ("m ⊗ g", "names are ASCII letters"),
    ("mа", "names are ASCII letters"),                     # a Cyrillic a: a look-alike is refused
])
def test_unreadable_spelling_is_refused_with_the_ascii_spelling(typed, hint):
    with pytest.raises(ModelError) as info:
        read(typed)
    message = str(info.value)
    assert message.startswith("answer.toml: energy.T: ") and hint in message
    assert "\n" not in message


def test_unknown_greek_name_gets_did_you_mean():
    with pytest.raises(ModelError, match="unknown name 'thet'; did you mean 'theta'"):
        read("thet + θ")
    with pytest.raises(ModelError, match="unknown name 'psi'"):
        read("ψ")


def test_did_you_mean_ignores_case_for_close_names():
    from lagrangian.errors import closest_name, did_you_mean

    assert did_you_mean("L1", ["l1", "l2", "m1"]) == "; did you mean 'l1'?"
    assert closest_name("THETA1", ["theta1", "theta2"]) == "theta1"
    assert closest_name("Thta", ["theta", "phi"]) == "theta"
    assert closest_name("N", ["m", "L", "g", "theta"]) is None


def test_a_unicode_answer_is_checked_like_its_ascii_twin():
    """Worked example 1 typed as the module prints it: T, V and the equation of motion."""
    import lagrangian

    system = lagrangian.load("pendulum")
    report = system.check({"energy": {"T": "½·m·L²·θ̇²", "V": "−m·g·L·cos(θ)"},
                           "equations": {"theta": "m·L²·θ̈ + m·g·L·sin(θ) = 0"}})
    assert report.verdict == "correct"
    assert [f.status for f in report.findings] == ["correct"] * 3
    flipped = system.check({"energy": {"V": "m·g·L·cos(θ)"}})
    assert flipped.codes("V") == ["potential_sign"]


def test_an_undeclared_name_in_an_answer_gets_did_you_mean_not_a_reaction():
    import lagrangian

    system = lagrangian.load("double_pendulum")
    report = system.check({"equations": {
        "theta2": "m2*L2^2*theta2_ddot + m2*l1*l2*theta1_ddot*cos(theta1 - theta2) "
                  "- m2*l1*l2*theta1_dot^2*sin(theta1 - theta2) + m2*g*l2*sin(theta2) = 0"}})
    finding = report.findings[0]
    assert finding.code == "equation_wrong"
    assert "did you mean l2?" in finding.message
    # a real reaction (a rod tension) is still a reaction
    pendulum = lagrangian.load("pendulum")
    tension = pendulum.check({"equations": {
        "theta": "m*L^2*theta_ddot + m*g*L*sin(theta) = T_rod*L"}})
    assert tension.codes() == ["reaction_in_minimal_coordinates"]
