"""crosscheck never agrees with what it cannot check: masses and inertias that change with q
or t, and T given as an expression, are refused (exit 2) with the reason."""

from __future__ import annotations

import pytest

from variable_models import ROTOR_WITH_BEAD

SKATER = """
name = "Figure skater"
[coordinates]
phi = "rad"
[parameters]
I0 = 3.0
[[bodies]]
name = "skater"
mass = 60
inertia = "I0*(1 + t/10)"
position = [0, 0]
angle = "phi"
"""

BUCKET = """
name = "Leaking bucket"
[coordinates]
y = "m"
[parameters]
m0 = 2.0
[gravity]
g = 9.81
[[particles]]
name = "bucket"
mass = "m0*(1 - t/20)"
position = [0, "y"]
"""


@pytest.mark.parametrize("text, message", [
    (ROTOR_WITH_BEAD, "error: Newton-Euler (F = m a, M = I alpha) does not model inertia that changes "
            "with r: the inertia of body 'rotor' is I0 + m*r**2, so crosscheck cannot check this "
            "model (derive gives its Euler-Lagrange equations)\n"),
    (SKATER, "error: Newton-Euler (F = m a, M = I alpha) does not model inertia that changes "
             "with t: the inertia of body 'skater' is I0*(t/10 + 1), so crosscheck cannot check "
             "this model (derive gives its Euler-Lagrange equations)\n"),
    (BUCKET, "error: Newton-Euler (F = m a, M = I alpha) does not model mass that changes with "
             "t: the mass of particle 'bucket' is m0*(1 - t/20), so crosscheck cannot check this "
             "model (derive gives its Euler-Lagrange equations)\n"),
])
def test_crosscheck_refuses_changing_mass_and_inertia(cli, tmp_path, text, message):
    path = tmp_path / "model.toml"
    path.write_text(text)
    assert tuple(cli("crosscheck", str(path))) == (2, "", message)


def test_crosscheck_refuses_t_given_as_an_expression(cli):
    code, out, err = cli("crosscheck", "bead_on_hoop")
    assert (code, out) == (2, "")
    assert err.startswith("error: Newton-Euler needs the inertia as particles and bodies, but "
                          "this model gives T as an expression")


def test_crosscheck_still_runs_on_constant_masses(cli):
    code, out, _ = cli("crosscheck", "double_pendulum")
    assert code == 0
    assert "theta1: agree" in out and "theta2: agree" in out
