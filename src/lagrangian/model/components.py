"""The kinds of component a model is built from, grouped by what they contribute. Each stage that
treats components one kind at a time keeps a table keyed by these types (functools.singledispatch);
tests/model/test_component_tables.py walks every kind through every table."""

from __future__ import annotations

from .contacts import RollingContact
from .model import Body, Constraint, Damper, Particle, PointForce, Spring, Torque
from .rotations import Moment, RigidBody

MASS_KINDS = (Particle, Body, RigidBody)  # carry mass: T, M, weight in V
ELEMENT_KINDS = (Spring, Damper)  # two-point elements: V (spring), D (damper)
LOAD_KINDS = (PointForce, Torque, Moment)  # applied loads: Q by virtual work
CONSTRAINT_KINDS = (Constraint, RollingContact)  # Phi_q^T lambda
COMPONENT_KINDS = MASS_KINDS + ELEMENT_KINDS + LOAD_KINDS + CONSTRAINT_KINDS
