"""--hints-only keeps each finding's specific hint and drops only the answer (issue 40)."""

from __future__ import annotations

import re

from check_helpers import check_text, finding

from lagrangian.check.conserved_answers import MECHANICS_CODES
from lagrangian.check.diagnose import CODES
from lagrangian.check.final_answers import FINAL_CODES
from lagrangian.check.hints import GENERAL, HINTS, hinted


def _hint(model: str, text: str, item: str):
    return finding(hinted(check_text(model, text)), item)


def test_a_frequency_in_hz_and_a_linearized_equation_get_different_specific_hints():
    hz = _hint("pendulum", '[frequencies]\nomega = ["0.705 rad/s"]\n', "omega[1]")
    linear = _hint("pendulum", '[equations]\ntheta = "m*L^2*theta_ddot + m*g*L*theta = 0"\n',
                   "equation[theta]")
    general = f"{GENERAL.question} {GENERAL.correction}"
    assert hz.message != linear.message and general not in (hz.message, linear.message)
    assert "Hz" in hz.message and "small-angle" in linear.message
    for f in (hz, linear):
        assert f.expected is None and not re.search(r"\d\.\d", f.message)  # no value shown


def test_omega_squared_and_a_misspelled_name_keep_their_own_hints():
    squared = _hint("ladder_spring_mass", '[frequencies]\nomega = ["25 rad/s"]\n', "omega[1]")
    assert "omega^2" in squared.message and "25" not in squared.message
    name = _hint("pendulum", '[energy]\nT = "1/2*m*l^2*theta_dot^2"\n', "T")
    assert "did you mean L" in name.message and name.expected is None


def test_the_springs_sign_question_survives_hints_only():
    V = _hint("two_mass", '[energy]\nV = "1/2*k*x1^2 - 1/2*k_c*(x1 - x2)^2 + 1/2*k*x2^2"\n', "V")
    assert V.code == "potential_sign" and "spring" in V.message and "rises" not in V.message
    assert "k_c*" not in V.message  # the term itself is not shown


def test_every_code_has_its_own_question():
    missing = [code for code in (*CODES, *FINAL_CODES, *MECHANICS_CODES) if code not in HINTS]
    assert missing == []
