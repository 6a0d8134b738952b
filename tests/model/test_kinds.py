"""Kinds and states are string enums (issue 26): every constraint, tree joint, invariant and
run status the package makes is a member, and each still reads and prints as its word."""

from __future__ import annotations

import json

import lagrangian
from lagrangian import ConstraintKind, InvariantKind, JointKind, RunStatus
from lagrangian.model.examples import example_names


def test_every_example_uses_the_enums():
    for name in example_names():
        system = lagrangian.load(name)
        for constraint in system.model.constraints:
            assert isinstance(constraint.kind, ConstraintKind)
        tree = system.model.kinematic_tree
        for joint in tree.joints if tree is not None else ():
            assert isinstance(joint.kind, JointKind)


def test_the_words_are_unchanged():
    assert json.dumps([ConstraintKind.HOLONOMIC, JointKind.PRISMATIC]) == \
        '["holonomic", "prismatic"]'
    assert f"{RunStatus.STOPPED}" == "stopped" and RunStatus("failed") is RunStatus.FAILED


def test_runs_and_invariants_are_members():
    """The pendulum keeps T + V; a stop condition ends its run as 'stopped'."""
    pendulum = lagrangian.load("pendulum")
    assert pendulum.equations_of_motion().invariant_kind is InvariantKind.ENERGY
    run = pendulum.simulate(2.0, stop_when="theta < 0")
    assert run.status is RunStatus.STOPPED
    assert pendulum.simulate(0.1).status is RunStatus.FINISHED
