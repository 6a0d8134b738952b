"""`lagrangian conserved`, `derive --routh` and `derive --hamilton` on model files (issue 40)."""

from __future__ import annotations

import json

import pytest
import sympy

from conserved_models import CENTRAL_WELL, SPHERICAL_PENDULUM
from lagrangian.model.expressions import parse_expression


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("conserved_cli")
    paths = {}
    for name, text in (("spherical", SPHERICAL_PENDULUM), ("central", CENTRAL_WELL)):
        paths[name] = folder / f"{name}.toml"
        paths[name].write_text(text)
    return paths


def test_conserved_lists_the_cyclic_momentum_in_the_modules_notation(cli, files):
    result = cli("conserved", str(files["spherical"]))
    assert result.code == 0, result.err
    assert "p_phi = m φ̇ l² sin²θ" in result.out
    assert "equal to T + V" in result.out
    document = json.loads(cli("conserved", str(files["central"]), "--json").out)
    kinds = {q["kind"]: q for q in document["conserved"]}
    assert set(kinds) == {"jacobi", "noether"}
    assert kinds["noether"]["expression"] == "m*(x*y_dot - x_dot*y)"


def test_conserved_on_the_hoop_says_t_plus_v_is_not_conserved(cli):
    document = json.loads(cli("conserved", "bead_on_hoop", "--set", "Omega=5", "--json").out)
    assert [(q["kind"], q["equals_energy"]) for q in document["conserved"]] == [("jacobi", False)]


def test_derive_routh_gives_the_effective_potential(cli, files):
    result = cli("derive", str(files["spherical"]), "--routh", "phi", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["coordinates"] == ["theta"]
    routh = document["routhian"]
    assert "p_phi" in routh["parameters"] and "R = sum p_k q_dot_k - L" in routh["convention"]
    assert routh["effective_potential"] == \
        "-g*l*m*cos(theta) + p_phi**2/(2*l**2*m*sin(theta)**2)"
    bad = cli("derive", str(files["spherical"]), "--routh", "theta")
    assert bad.code == 2 and bad.err.count("\n") == 1 and "not cyclic" in bad.err


def test_derive_hamilton_prints_h_and_the_momenta(cli):
    result = cli("derive", "pendulum", "--hamilton", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["momenta"] == {"p_theta": "L**2*m*theta_dot"}
    assert document["q_dot"] == {"theta": "p_theta/(L**2*m)"}
    text = cli("derive", "pendulum", "--hamilton").out
    assert "H = " in text
    # p_dot = -dH/dtheta = -m g L sin(theta), written out where it is short
    assert "p_theta_dot = -dH/dtheta = -L*g*m*sin(theta)" in text
    # the hoop: p_dot = m R^2 Omega^2 sin cos - m g R sin (the drive's centrifugal term)
    hoop = cli("derive", "bead_on_hoop", "--hamilton", "--json").out
    p_dot = json.loads(hoop)["p_dot"]["p_theta"]
    m, R, g, Omega, theta = sympy.symbols("m R g Omega theta")
    names = {"m": m, "R": R, "g": g, "Omega": Omega, "theta": theta}
    assert sympy.simplify(parse_expression(p_dot, names) - (
        m * R**2 * Omega**2 * sympy.sin(theta) * sympy.cos(theta) - m * g * R * sympy.sin(theta))) == 0
    assert f"p_theta_dot = -dH/dtheta = {p_dot}" in cli("derive", "bead_on_hoop", "--hamilton").out
    # too long for a line (the double pendulum's): named, and given in --json
    assert "p_theta1_dot = -dH/dtheta1 (written out in --json)" in \
        cli("derive", "double_pendulum", "--hamilton").out
    bad = cli("derive", "cartesian_pendulum", "--hamilton")
    assert bad.code == 2 and "unconstrained" in bad.err


def test_conserved_on_a_robots_tree_is_refused_in_one_line(cli):
    bad = cli("conserved", "two_link_arm")
    assert bad.code == 2 and bad.err.count("\n") == 1
    assert "conserved:" in bad.err and "kinematic tree (URDF, MJCF) is not searched" in bad.err
