"""Newton-Euler with Euler's equations for bodies in space, against the Lagrange derivation."""

from dataclasses import replace

import pytest
import sympy as sp

import lagrangian
from lagrangian.check.newton_euler import crosscheck
from lagrangian.model.builder import ModelBuilder


def _loaded_arm():
    """Two bodies on revolute joints (a spatial chain) with products of inertia, a moment in
    body axes, one in world axes, a force at a body point and a spring to the ground."""
    b = ModelBuilder("loaded arm")
    for name in ("q1", "q2"):
        b.coordinate(name, "rad")
    for name, value in (("g", 9.81), ("M1", 0.3), ("M2", -0.2), ("F", 1.5), ("k", 20.0)):
        b.parameter(name, value)
    b.set_gravity("g", (0, 0, -1))
    b.add_rigid_body("upper", 1.0, [[0.02, 0.001, 0], [0.001, 0.08, 0.002], [0, 0.002, 0.08]],
                     joint={"type": "revolute", "axis": "z", "angle": "q1"}, center=[0.5, 0, 0])
    b.add_rigid_body("lower", 0.5, [0.002, 0.02, 0.021], parent="upper", center=[0.4, 0, 0.1],
                     joint={"type": "revolute", "axis": [0, 1, 1], "angle": "q2", "at": [1, 0, 0]})
    b.add_moment("motor", "lower", [0, "M1", 0], axes="body")
    b.add_moment("wind", "upper", [0, "M2", "M2"])
    b.add_force("push", {"body": "lower", "offset": [0.8, 0.1, 0]}, ["F", 0, "F"])
    b.add_spring("tie", "k", 0.5, between=[{"body": "lower", "offset": [0.8, 0, 0]}, [1, 1, 0]])
    return lagrangian.System(b.build_model())


def test_tops_agree_with_lagrange():
    for name in ("heavy_top", "torque_free_body"):
        report = lagrangian.load(name).crosscheck()
        assert report.agree, (name, report)
        assert any("Euler's equations" in note for note in report.notes)


@pytest.mark.slow
def test_a_loaded_spatial_arm_agrees_with_lagrange():
    report = _loaded_arm().crosscheck()
    assert report.agree, report


def test_a_wrong_equation_is_caught():
    top = lagrangian.load("heavy_top").equations_of_motion()
    g, A = sp.Symbol("g"), sp.Symbol("A")
    wrong = replace(top, forcing=top.forcing + sp.Matrix([0, g / 100, 0]))
    report = crosscheck(wrong)
    assert [c.coordinate for c in report.coordinates if not c.agree] == ["theta"]
    # and a wrong inertia (a transverse moment added to the precession)
    wrong = replace(top, mass_matrix=top.mass_matrix + sp.diag(A, 0, 0))
    assert not crosscheck(wrong).agree
