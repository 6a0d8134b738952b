"""One seam per stage for component kinds (issue 26): every stage that treats components one kind
at a time keeps a table keyed by the kind, and no kind is missing from any table. A new kind (a
torsion spring, a helical joint) fails here until each stage knows it."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import lagrangian
from lagrangian import JointKind
from lagrangian.check.diagnose_terms import projection_explanation
from lagrangian.check.free_bodies import _AppliedForces, free_body
from lagrangian.check.units import unit_items
from lagrangian.derivation.energies import dissipation_terms, potential_terms
from lagrangian.derivation.inertia import add_rotation, add_translation
from lagrangian.derivation.steps import load_working
from lagrangian.derivation.virtual_work import load_projection
from lagrangian.dynamics.tree.joint_models import JOINT_MODELS, joint_model
from lagrangian.kinds import LoadStepKind
from lagrangian.model.components import (
    COMPONENT_KINDS,
    CONSTRAINT_KINDS,
    ELEMENT_KINDS,
    LOAD_KINDS,
    MASS_KINDS,
)
from lagrangian.model.rotations import JOINT_KEYS, RotationReader
from lagrangian.output.drawing import NOT_DRAWN, draw
from lagrangian.output.steps import LOAD_LATEX, LOAD_TEXT

TABLES = {
    "kinetic energy, M and f, first pass (derivation)": (add_translation.registry, MASS_KINDS),
    "kinetic energy, M and f, second pass (derivation)": (add_rotation.registry, MASS_KINDS),
    "potential energy (derivation)": (potential_terms.registry, MASS_KINDS + ELEMENT_KINDS),
    "dissipation (derivation)": (dissipation_terms.registry, MASS_KINDS + ELEMENT_KINDS),
    "virtual work (derivation)": (load_projection.registry, LOAD_KINDS),
    "units (check)": (unit_items.registry, MASS_KINDS + ELEMENT_KINDS + LOAD_KINDS),
    "free bodies (Newton-Euler check)": (_AppliedForces.__dict__["add_load"].dispatcher.registry, LOAD_KINDS),
    "free bodies of masses (Newton-Euler check)": (free_body.registry, MASS_KINDS),
    "free-body forces of elements (Newton-Euler check)": (
        _AppliedForces.__dict__["add_element"].dispatcher.registry, ELEMENT_KINDS),
    "diagnosis of a mis-projected load (check)": (projection_explanation.registry,
                                                  LOAD_KINDS + ELEMENT_KINDS[1:]),
    "drawing (output)": (draw.registry, COMPONENT_KINDS),
    "virtual work step by step (derive --steps)": (load_working.registry,
                                                   LOAD_KINDS + ELEMENT_KINDS[1:]),
}


@pytest.mark.parametrize("table", sorted(TABLES))
def test_every_kind_has_its_entry(table):
    registry, kinds = TABLES[table]
    missing = [kind.__name__ for kind in kinds if kind not in registry]
    assert not missing, f"{table} has no entry for {missing}"


def test_only_kinds_without_a_position_are_drawn_by_nothing():
    """A kind is drawn unless it is deliberately listed as not drawn: loads and constraints,
    which have no position of their own (a rolling contact draws its wheel)."""
    assert set(NOT_DRAWN) == set(LOAD_KINDS) | set(CONSTRAINT_KINDS[:1])
    drawn = [kind for kind in COMPONENT_KINDS if kind not in NOT_DRAWN]
    assert set(drawn) == set(MASS_KINDS + ELEMENT_KINDS + CONSTRAINT_KINDS[1:])


@pytest.mark.parametrize("table", [LOAD_TEXT, LOAD_LATEX], ids=["text", "LaTeX"])
def test_every_kind_of_load_step_is_written(table):
    """derive --steps writes each load's virtual work by a table keyed by the kind of load."""
    missing = [str(kind) for kind in LoadStepKind if kind not in table]
    assert not missing, f"derive --steps writes no {missing}"


def test_every_kind_of_result_is_written():
    """The tables the output keys by a kind enum name every member: a new status or kind is
    written, not dropped to a default."""
    from lagrangian.kinds import CrossingKind, FindingStatus, FreeBodyKind
    from lagrangian.output.check import _MARK
    from lagrangian.output.crosscheck_steps import _INERTIAL_SHARE
    from lagrangian.output.speed_form import _NAMES

    for table, kinds in ((_MARK, FindingStatus), (_INERTIAL_SHARE, FreeBodyKind),
                         (_NAMES, CrossingKind)):
        assert set(table) == set(kinds)


def test_a_misspelled_status_or_kind_is_an_error():
    from lagrangian.analysis.study import Distribution
    from lagrangian.check.diagnose import Finding

    assert Finding("V", "correct", None, "V matches.").status == "correct"
    with pytest.raises(ValueError, match="corect"):
        Finding("V", "corect", None, "V matches.")
    with pytest.raises(ValueError, match="gaussian"):
        Distribution("gaussian", 0.0, 1.0)
    from lagrangian.analysis.speed_form import SpeedSweep

    sweep = SpeedSweep(np.zeros(0), np.zeros((0, 0)), (), ())
    assert sweep.speed_of("oscillatory") is None
    with pytest.raises(lagrangian.InputError, match="oscillatory, real, got 'weave'") as error:
        sweep.speed_of("weave")
    assert error.value.field == "kind"


def test_the_kinds_are_each_named_once():
    assert len(set(COMPONENT_KINDS)) == len(COMPONENT_KINDS)


def test_every_joint_kind_is_read_from_a_model_file_and_moved_by_a_tree_or_refused():
    assert set(JOINT_KEYS) == set(JointKind) == set(RotationReader._JOINT_FRAMES)
    for kind in JointKind:
        if kind in JOINT_MODELS:
            assert joint_model(kind).kind is kind
        else:
            with pytest.raises(lagrangian.ModelError, match="one-degree-of-freedom"):
                joint_model(kind)


def test_the_tables_give_the_textbook_energies():
    """A pendulum bob at (L sin q, -L cos q) under g along -y has V = -m g L cos q; a spring
    stretched by x - l0 stores k (x - l0)^2 / 2; a damper dissipates c x_dot^2 / 2."""
    m, g, L, k, l0, c, q, x, x_dot = sp.symbols("m g L k l0 c q x x_dot")
    from lagrangian.model.model import Damper, Gravity, Particle, Spring

    bob = Particle("bob", m, (L * sp.sin(q), -L * sp.cos(q), sp.S.Zero))
    gravity = Gravity(g, (sp.S.Zero, -sp.S.One, sp.S.Zero))
    assert sp.simplify(sum(potential_terms(bob, gravity)) + m * g * L * sp.cos(q)) == 0
    assert potential_terms(bob, None) == []
    spring = Spring("s", k, l0, x)
    assert sp.expand(sum(potential_terms(spring, gravity)) - k * (x - l0) ** 2 / 2) == 0
    assert sp.expand(sum(dissipation_terms(Damper("d", c, x_dot))) - c * x_dot**2 / 2) == 0


def test_a_load_of_each_kind_does_its_virtual_work():
    """delta W = Q delta q: a force F x-wards at (L sin q, -L cos q) gives F L cos q; a torque
    tau through 2 q gives 2 tau."""
    F, L, tau, q, q_dot = sp.symbols("F L tau q q_dot")
    from lagrangian.model.model import PointForce, Torque

    push = PointForce("push", (L * sp.sin(q), -L * sp.cos(q), sp.S.Zero), (F, sp.S.Zero, sp.S.Zero))
    assert load_projection(push, (q,), (q_dot,)) == [F * L * sp.cos(q)]
    assert load_projection(Torque("motor", tau, 2 * q), (q,), (q_dot,)) == [2 * tau]
    with pytest.raises(TypeError, match="no virtual work"):
        load_projection(object(), (q,), (q_dot,))


def test_each_kind_explains_its_own_projection():
    """The diagnosis names what a load's virtual work is made of, kind by kind."""
    from lagrangian.model.model import Damper, PointForce, Torque
    from lagrangian.model.rotations import Moment

    F, L, tau, c, q, x_dot = sp.symbols("F L tau c q x_dot")
    zero = sp.S.Zero
    push = PointForce("push", (L * sp.sin(q), -L * sp.cos(q), zero), (F, zero, zero))
    assert "dr = dr/dq dq = (L*cos(q), L*sin(q)) dq" in projection_explanation(push, "q", q, "")
    assert "turns through d(angle) = (2) dq" in projection_explanation(
        Torque("motor", tau, 2 * q), "q", q, "")
    assert "the moment 'spin' is projected wrongly" in projection_explanation(
        Moment("spin", "top", (zero, zero, tau), "world", (zero, zero, x_dot)), "q", q, "")
    assert "Q = -c (rate) d(rate)/dq_dot" in projection_explanation(
        Damper("d", c, x_dot), "q", q, "")
