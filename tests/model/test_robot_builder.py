"""lagrangian.RobotBuilder: a robot's tree built in Python (model/robot_builder.py). The
documented block gives a screw's and a universal wrist's closed forms; a universal joint alone
gives the Cardan body's M; Lagrange's equations over the builder's symbolic bodies equal the
tree's recursions (two derivations); bad input is one line naming the link or joint and field."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
import sympy as sp
from tests.docs_blocks import block

import lagrangian
from lagrangian.errors import ModelError


@pytest.fixture(scope="module")
def documented():
    code = re.search(r"```python\n(.*?)```", block("robot-builder"), re.S).group(1)
    namespace: dict = {}
    exec(code, namespace)  # noqa: S102 - the page's own example
    return namespace


def test_the_documented_screw_arm(documented):
    """The nut rises 1 cm per rad: gravity's share on the screw is (2 + 1) kg g 0.01 m/rad; the
    arm's centre 0.3 m out along x drops as wrist_2 turns about y: -1 kg g 0.3 m; about the
    screw the nut and arm turn (Izz + m r^2) and rise (m p^2)."""
    g, p = 9.81, 0.01
    assert documented["names"] == ("lead", "wrist_1", "wrist_2")
    np.testing.assert_allclose(documented["g"], [3.0 * g * p, 0.0, -1.0 * g * 0.3], atol=1e-12)
    M = documented["M"]
    assert M[0, 0] == pytest.approx(0.04 + 2.0 * p**2 + 0.01 + 1.0 * 0.3**2 + 1.0 * p**2,
                                    rel=1e-12)
    J = documented["J"]  # the wrist's frame, 0.1 m above the nut: the screw lifts it p per rad
    np.testing.assert_allclose(J[:, 0], [0.0, 0.0, p, 0.0, 0.0, 1.0], atol=1e-12)
    assert documented["system"].joint_limits["wrist_1"] == (-1.5, 1.5)


def test_the_screw_arm_keeps_its_energy(documented):
    """No friction, no drive: T + V stays while the screw trades its spin for height and the
    wrist swings (a run on the compiled engine, DOP853 at 1e-9)."""
    run = documented["system"].simulate(1.0, initial={"wrist_2": 0.3, "lead_dot": 1.0,
                                                       "wrist_1_dot": 2.0})
    energy = np.asarray(run.energy)
    assert np.abs(energy - energy[0]).max() <= 1e-7 * np.abs(energy).max()
    assert np.ptp(np.asarray(run.q)[:, 0]) > 0.05  # the screw turned and rose


def test_a_universal_joint_is_a_cardan_suspension():
    """A body centred on the joint, axes z then y (R = Rz(q1) Ry(q2)): omega in body axes is
    q1_dot Ry(q2)^T z + q2_dot y, so M = diag(Ix sin^2 q2 + Iz cos^2 q2, Iy)."""
    b = lagrangian.RobotBuilder("cardan").link("frame")
    b.link("body", mass=3.0, inertia=(0.1, 0.2, 0.4))
    b.joint("cross", "universal", "frame", "body", axis=(0, 0, 1), axis2=(0, 1, 0))
    f = b.build().dynamics()
    assert f.coordinates == ("cross_1", "cross_2")
    for q2 in (0.0, 0.4, 1.2):
        expected = np.diag([0.1 * math.sin(q2) ** 2 + 0.4 * math.cos(q2) ** 2, 0.2])
        np.testing.assert_allclose(f.mass_matrix([0.7, q2]), expected, atol=1e-14)
    assert "cross" in f.frames and "cross_link" in f.frames


def test_the_derived_equations_equal_the_tree_recursions():
    """Lagrange's equations over the builder's symbolic bodies (a screw turning and sliding,
    then a universal joint, off-axis origins) against the recursions on the tree's numbers."""
    robot = lagrangian.RobotBuilder("screw_arm")
    robot.link("base")
    robot.link("nut", mass=2.0, com=(0.01, 0.02, 0.0), inertia=(0.02, 0.03, 0.04))
    robot.link("arm", mass=1.0, com=(0.3, 0.05, -0.02), inertia=(0.001, 0.01, 0.012))
    robot.joint("lead", "helical", "base", "nut", xyz=(0.1, 0, 0.2), rpy=(0.2, 0.1, 0),
                axis=(0, 0.3, 1), pitch=0.01)
    robot.joint("wrist", "universal", "nut", "arm", xyz=(0, 0, 0.1), rpy=(0.1, -0.2, 0.3),
                axis=(0, 0, 1), axis2=(0, 1, 0))
    system = robot.build()
    eom, model = system.equations_of_motion(), system.model
    q, v = np.array([0.3, -0.4, 0.5]), np.array([0.2, 0.7, -0.1])
    values = {c.symbol: x for c, x in zip(model.coordinates, q, strict=True)}
    values |= {c.velocity: x for c, x in zip(model.coordinates, v, strict=True)}
    values |= {p.symbol: p.value for p in model.parameters}
    M = np.array(sp.Matrix(eom.mass_matrix).xreplace(values).evalf(), dtype=float)
    f = np.array(sp.Matrix(eom.forcing).xreplace(values).evalf(), dtype=float).ravel()
    tree = system.dynamics()
    np.testing.assert_allclose(M, tree.mass_matrix(q), atol=1e-12)
    np.testing.assert_allclose(f, -tree.bias_forces(q, v), atol=1e-12)


def _arm():
    b = lagrangian.RobotBuilder("arm").link("base").link("upper", mass=1.0, inertia=(1, 1, 1))
    return b


@pytest.mark.parametrize(("make", "field", "words"), [
    (lambda b: b.joint("j", "helix", "base", "upper"), "joint 'j'.kind", "did you mean 'helical'"),
    (lambda b: b.joint("j", "revolute", "base", "fore").build(), "joint 'j'", "no link 'fore'"),
    (lambda b: b.joint("j", "revolute", "base", "upper", pitch=0.1), "joint 'j'.pitch",
     "no pitch"),
    (lambda b: b.joint("j", "universal", "base", "upper", axis=(0, 0, 1), axis2=(0, 1, 1)),
     "joint 'j'.axis2", "perpendicular"),
    (lambda b: b.joint("j", "universal", "base", "upper"), "joint 'j'.axis2", "second axis"),
    (lambda b: b.joint("j", "revolute", "base", "upper", axis=(0, 0, 0)), "joint 'j'.axis",
     "zero length"),
    (lambda b: b.joint("j", "revolute", "base", "upper", xyz=(0, math.nan, 0)),
     "joint 'j'.xyz", "not finite"),
    (lambda b: b.joint("j", "revolute", "base", "upper", limits=(1, -1)), "joint 'j'.limits",
     "below upper"),
    (lambda b: b.link("fore", mass=-1.0), "link 'fore'.mass", "negative"),
    (lambda b: b.link("fore", mass=1.0, inertia=(1.0, 1.0, -1.0)), "link 'fore'.inertia",
     "positive semidefinite"),
    (lambda b: b.link("fore", inertia=((1, 0.5, 0), (0, 1, 0), (0, 0, 1))),
     "link 'fore'.inertia", "symmetric"),
    (lambda b: b.link("upper"), "link 'upper'", "second link"),
    (lambda b: b.link("tip").joint("j", "revolute", "base", "upper").build(), "joints",
     "separate trees"),
    (lambda b: b.joint("j", "fixed", "base", "upper").build(), "joints", "no joint to move"),
    (lambda b: b.joint("j", "revolute", "base", "upper").joint("j", "revolute", "upper",
                                                               "base"), "joint 'j'", "second"),
])
def test_bad_input_is_one_line_naming_its_field(make, field, words):
    with pytest.raises(ModelError, match=words) as error:
        make(_arm())
    assert error.value.field == field
    assert "\n" not in str(error.value)


def test_a_floating_screw_and_the_builder_repr():
    """A free flyer carries the root link: nq = 7 + 1, nv = 6 + 1; the builder says what it
    holds."""
    b = lagrangian.RobotBuilder("nut").link("bolt", mass=2.0, inertia=(0.1, 0.1, 0.05))
    b.link("nut", mass=0.5, inertia=(0.01, 0.01, 0.02))
    b.joint("thread", "helical", "bolt", "nut", pitch=0.02)
    assert repr(b) == "RobotBuilder('nut', links=['bolt', 'nut'], joints=['thread (helical)'])"
    f = b.build(floating_base=True).dynamics()
    assert (f.nq, f.nv) == (8, 7)
    q = np.zeros(8)
    q[6] = 1.0
    np.linalg.cholesky(f.mass_matrix(q))  # the bolt and the nut each carry mass
