"""The public JSON contracts of derive and forces, and LaTeX output."""

import json

import pytest
import sympy as sp

import lagrangian
from lagrangian.model.expressions import parse_expression
from lagrangian.output.derivation import derivation_document, derivation_latex
from lagrangian.output.forces import forces_document

DERIVE_KEYS = {"name", "convention", "coordinates", "parameters", "kinetic_energy",
               "potential_energy", "dissipation", "lagrangian", "generalized_forces",
               "load_contributions", "mass_matrix", "forcing", "equations", "accelerations",
               "accelerations_note"}


def is_zero(expression):
    """Exactly zero: the printed forms apply the angle-sum identities, so compare with the
    trig functions of sums expanded (still an exact symbolic identity, not a numeric one)."""
    return sp.expand(sp.expand_trig(expression)) == 0


def names_of(eom):
    model = eom.model
    names = {p.name: p.symbol for p in model.parameters}
    for c in model.coordinates:
        names.update({c.name: c.symbol, c.velocity.name: c.velocity,
                      c.acceleration.name: c.acceleration})
    names.update({str(s): s for s in eom.multipliers})
    names["t"] = sp.Symbol("t")
    return names


@pytest.mark.parametrize("name", ["pendulum", "cartesian_pendulum", "slider_crank",
                                  "damped_oscillator", "support_pendulum"])
def test_derive_document_keys_and_expressions_read_back(name):
    eom = lagrangian.load(name).equations_of_motion()
    document = json.loads(json.dumps(derivation_document(eom)))
    expected = DERIVE_KEYS | ({"constraints"} if eom.model.constraints else set())
    assert set(document) == expected
    assert document["convention"] == "M q_ddot + Phi_q^T lambda = forcing"
    names = names_of(eom)

    def back(text):
        return parse_expression(text, names)

    assert is_zero(back(document["lagrangian"]) - eom.lagrangian)
    for i, c in enumerate(eom.model.coordinates):
        assert is_zero(back(document["equations"][c.name]) - eom.equations[i])
        assert is_zero(back(document["forcing"][i]) - eom.forcing[i])
        for j in range(len(eom.model.coordinates)):
            assert is_zero(back(document["mass_matrix"][i][j]) - eom.mass_matrix[i, j])
    if eom.model.constraints:
        constraints = document["constraints"]
        assert set(constraints) >= {"names", "multipliers", "jacobian", "acceleration_rhs"}
        assert len(constraints["multipliers"]) == len(constraints["names"])
        assert constraints["multipliers"] == [f"lambda_{n}" for n in constraints["names"]]


def test_large_models_report_null_accelerations():
    document = derivation_document(lagrangian.load("slider_crank").equations_of_motion())
    assert document["accelerations"] == {"theta": None, "phi": None, "x": None}
    assert document["accelerations_note"] == (
        "not solved symbolically: 5 unknowns (more than 3); the equations are given in the "
        "implicit form M q_ddot = f")


def test_forces_document_contract():
    system = lagrangian.load("virtual_work_link")
    document = forces_document(system.generalized_forces_at({"theta": 0.5235987755982988}))
    assert set(document) == {"configuration", "generalized_forces", "contributions", "units"}
    assert document["generalized_forces"]["theta"] == pytest.approx(43.30127, rel=1e-6)
    assert document["contributions"] == [
        {"load": "F", "coordinate": "theta", "value": pytest.approx(43.30127, rel=1e-6)}]
    assert document["units"] == {"theta": "N*m"}


def test_force_units_follow_the_coordinate():
    report = lagrangian.load("cart_pendulum").generalized_forces_at({}, {"F": 5.0})
    assert report.units == {"x": "N", "theta": "N*m"}
    assert report.generalized_forces == {"x": 5.0, "theta": 0.0}


def test_latex_uses_dots_and_multipliers():
    text = derivation_latex(lagrangian.load("cartesian_pendulum").equations_of_motion())
    assert r"\ddot{x}" in text and r"\lambda_{\mathrm{rod}}" in text
    assert text.count(r"\begin{align}") == 1 and text.count(r"\end{align}") == 1


def test_jupyter_display_is_latex():
    system = lagrangian.load("pendulum")
    assert system._repr_latex_().startswith("$L = ")
    latex = system.equations_of_motion()._repr_latex_()
    assert latex.startswith("$") and r"\ddot{\theta}" in latex


def test_jupyter_display_of_modes_and_forces():
    modes = lagrangian.load("two_mass").modes()._repr_latex_()
    assert modes.startswith("$\\begin{array}") and modes.endswith("$")
    assert "1 & 1 & 0.159155 & 0 & 0 & 1 & 1" in modes  # omega = 1 rad/s, shape (1, 1)
    assert "2 & 1.73205" in modes and "& 1 & -1" in modes
    forces = lagrangian.load("virtual_work_link").generalized_forces_at(
        {"theta": 0.5235987755982988})._repr_latex_()
    assert "Q_{\\theta} &= 43.3013" in forces and "\\mathrm{N\\,m}" in forces
