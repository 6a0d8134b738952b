"""A model whose M and f hold no symbols at all (T = 3 x_dot^2 / 2): every command derives it
(a regression of issue 21: max() of a single 0 raised TypeError in the symbolic solve)."""

from __future__ import annotations

import json

import pytest

import lagrangian

MODEL = """
[coordinates]
x = { initial = 0.5, rate = 0.0 }
[energy]
T = "3*x_dot^2/2"
V = "2*x^2"
"""


@pytest.fixture
def model_file(tmp_path):
    path = tmp_path / "plain.toml"
    path.write_text(MODEL)
    return path


def test_the_accelerations_of_a_numbers_only_model(model_file):
    """3 x_ddot + 4 x = 0: x_ddot = -4/3 x; omega = sqrt(4/3)."""
    system = lagrangian.load(model_file)
    eom = system.equations_of_motion()
    x = system.symbol("x")
    assert (eom.accelerations[0] + 4 * x / 3).expand() == 0
    assert system.modes().natural_frequencies[0] == pytest.approx((4 / 3) ** 0.5, rel=1e-12)


def test_derive_prints_it(cli, model_file):
    result = cli("derive", str(model_file), "--json")
    assert result.code == 0, result.err
    assert json.loads(result.out)["mass_matrix"] == [["3"]]
