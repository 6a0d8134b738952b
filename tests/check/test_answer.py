"""Reading ANSWER.toml: the model grammar, foreign names kept, errors naming file and key."""

from __future__ import annotations

import pytest
import sympy as sp
from check_helpers import ANSWERS, system

from lagrangian import ModelError
from lagrangian.model.answer import parse_answer, read_answer


def pendulum():
    return system("pendulum").model


def test_equation_forms_and_foreign_names():
    answer = parse_answer("""
[equations]
theta = "m*L^2*theta_ddot = T_rod*L - m*g*L*sin(theta)"
""", pendulum(), source="a.toml")
    (name, value), = answer.equations
    m, L, g, T_rod = sp.symbols("m L g T_rod")
    theta, theta_ddot = sp.symbols("theta theta_ddot")
    assert name == "theta"
    assert sp.expand(value - (m * L**2 * theta_ddot - T_rod * L + m * g * L * sp.sin(theta))) == 0
    assert answer.foreign_symbols("equation[theta]") == {T_rod}


def test_multipliers_by_count_or_names():
    model = system("cartesian_pendulum").model
    assert parse_answer("[multipliers]\ncount = 1\n", model).multiplier_count == 1
    assert parse_answer('[multipliers]\nnames = ["T_rod"]\n', model).multiplier_names == ("T_rod",)


@pytest.mark.parametrize(("text", "message"), [
    ("[energies]\nT = 1\n", "a.toml: energies: unknown key 'energies'; did you mean 'energy'?"),
    ("[energy]\nU = \"m*g\"\n", "a.toml: energy.U: unknown key 'U'"),
    ("[equations]\nphi = \"theta_ddot\"\n", "a.toml: equations.phi: unknown coordinate 'phi'"),
    ("[energy]\nV = \"__import__('os').system('true')\"\n", "a.toml: energy.V: "),
    ("[energy]\nV = \"__import__\"\n", "a.toml: energy.V: '__import__' is not a valid name"),
    ("[equations]\ntheta = \"a = b = c\"\n", "a.toml: equations.theta: an equation is"),
    ("[multipliers]\ncount = -1\n", "a.toml: multipliers.count: expected a whole number"),
    ("[energy\n", "a.toml: invalid TOML"),
])
def test_bad_answers_name_file_and_key(text, message):
    with pytest.raises(ModelError) as error:
        parse_answer(text, pendulum(), source="a.toml")
    assert str(error.value).startswith(message)


def test_import_is_never_evaluated(tmp_path):
    marker = tmp_path / "pwned"
    with pytest.raises(ModelError, match="can be called"):
        parse_answer(f"[energy]\nV = \"__import__('os').system('touch {marker}')\"\n",
                     pendulum(), source="a.toml")
    with pytest.raises(ModelError, match="unknown function '__import__'"):
        parse_answer("[energy]\nV = \"__import__('os')\"\n", pendulum(), source="a.toml")
    assert not marker.exists()


def test_unreadable_file(tmp_path):
    with pytest.raises(ModelError, match="no such file"):
        read_answer(tmp_path / "missing.toml", pendulum())


def test_shipped_answers_parse():
    for path in ANSWERS.glob("*.toml"):
        model_name = {"link": "virtual_work_link"}.get(path.stem.split("_")[0])
        assert path.read_text().strip(), path
        if model_name:
            read_answer(path, system(model_name).model)
