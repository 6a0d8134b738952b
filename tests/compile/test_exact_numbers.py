"""Exact numbers past double's exact range reach no printer and no numpy ufunc as they are
(compile/exact.py): a rational below double range (10^-600) and an integer past int64
(cos(10^24)) give answers, on the compiled and the numpy paths and in codegen; a number past
double range is refused in one line."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

import lagrangian
from lagrangian.compile.exact import machine_numbers
from lagrangian.errors import ModelError

MODEL = """name = "exact"
[coordinates]
theta = {{ unit = "rad", initial = 0.3, rate = 0.0 }}
[parameters]
m = {{ value = 1.0, unit = "kg*m^2" }}
k = {{ value = 1.0, unit = "N*m" }}
[energy]
T = "1/2*m*theta_dot^2"
V = "{V}"
"""


def model(tmp_path, V: str):
    path = tmp_path / "exact.toml"
    path.write_text(MODEL.format(V=V))
    return path


def test_the_nearest_doubles():
    x = sp.Symbol("x")
    assert machine_numbers(sp.Rational(10**600 + 1, 10**600) * x) == 1.0 * x
    assert machine_numbers(sp.Rational(1, 10**600) * x) == 0
    assert float(machine_numbers(sp.cos(sp.Integer(10**24)))) == pytest.approx(math.cos(1e24),
                                                                              rel=1e-15)
    assert machine_numbers(sp.Rational(1, 3) * x) == sp.Rational(1, 3) * x  # exact stays
    with pytest.raises(ModelError, match="1.00000E\\+400 is beyond double precision's range"):
        machine_numbers(sp.Integer(10**400) * x)


@pytest.mark.parametrize("V, stiffness", [
    ("k*(1 + 1e-300*1e-300)*theta^2/2", 1.0),        # (10^600 + 1) / 10^600: p, q past double
    ("k*(2 + cos(1e24))*theta^2/2", 2.0 + math.cos(1e24)),  # an integer past int64
])
def test_a_model_with_such_numbers_runs_on_every_path(tmp_path, cli, V, stiffness):
    path = model(tmp_path, V)
    system = lagrangian.load(path)
    numpy_system = system.numeric(backend="numpy")
    np.testing.assert_allclose(numpy_system.forcing([0.3], [0.0]), [-stiffness * 0.3], rtol=1e-12)
    run = system.simulate(t_end=1.0)
    period_phase = math.sqrt(stiffness) * 1.0  # theta = 0.3 cos(omega t), m = k = 1
    assert run.q[-1, 0] == pytest.approx(0.3 * math.cos(period_phase), abs=1e-6)
    code, out, err = cli("codegen", str(path), "--lang", "c", "--out", str(tmp_path / "c"))
    assert code == 0, err
    assert "Traceback" not in err
