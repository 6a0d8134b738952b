"""Generalized forces by virtual work: delta W = Q . delta q, reported load by load."""

from __future__ import annotations

from dataclasses import dataclass
from functools import singledispatch

import sympy as sp

from ..model.model import Damper, Model, PointForce, Torque
from ..model.rotations import Moment
from .kinematics import jacobian_row
from .rigid_bodies import moment_projection

DISSIPATION_LOAD = "dissipation"
GIVEN_LOAD = "generalized_forces"


@dataclass(frozen=True)
class LoadContribution:
    """What one load gives to one coordinate's generalized force (N or N m)."""

    load: str
    coordinate: str
    expression: sp.Expr


def load_contributions(model: Model) -> list[LoadContribution]:
    """Every non-potential load's contribution to every coordinate it does virtual work on."""
    q, q_dot = model.q, model.q_dot
    names = [c.name for c in model.coordinates]
    contributions: list[LoadContribution] = []

    def add(load: str, values: list[sp.Expr]) -> None:
        for name, value in zip(names, values, strict=True):
            if value != 0:
                contributions.append(LoadContribution(load, name, value))

    for load in model.loads:
        add(load.name, load_projection(load, q, q_dot))
    for damper in model.dampers:
        add(damper.name, damper_forces(damper, q_dot))
    if model.dissipation != 0:
        add(DISSIPATION_LOAD, [-d for d in jacobian_row(model.dissipation, q_dot)])
    given = dict(model.generalized_forces)
    if given:
        add(GIVEN_LOAD, [given.get(name, sp.S.Zero) for name in names])
    return contributions


@singledispatch
def load_projection(load, q, q_dot) -> list[sp.Expr]:
    """Q_i of one applied load, from its virtual work delta W = Q . delta q: one table entry
    per load kind (tests/model/test_component_tables.py walks every kind)."""
    raise TypeError(f"no virtual work for a load of kind {type(load).__name__}")


@load_projection.register
def _(load: PointForce, q, q_dot) -> list[sp.Expr]:
    return point_force_projection(load, q)


@load_projection.register
def _(load: Torque, q, q_dot) -> list[sp.Expr]:
    """Q_i = tau d(theta)/dq_i."""
    return [load.torque * d for d in jacobian_row(load.angle, q)]


@load_projection.register
def _(load: Moment, q, q_dot) -> list[sp.Expr]:
    return moment_projection(load, q_dot)


def point_force_projection(load: PointForce, q) -> list[sp.Expr]:
    """Q_i = F . dr/dq_i for a force F at point r(q, t)."""
    rows = [jacobian_row(component, q) for component in load.point]
    return [
        sp.Add(*(f * rows[axis][i] for axis, f in enumerate(load.force) if rows[axis][i] != 0))
        for i in range(len(q))
    ]


def damper_forces(damper: Damper, q_dot) -> list[sp.Expr]:
    """Q_i = -dD/dq_dot_i = -c rate d(rate)/dq_dot_i with D = 1/2 c rate^2."""
    # rate * d(rate) first: for a rate (a - b).(a_dot - b_dot)/|a - b| the two 1/|a - b|
    # factors then meet and cancel against (a - b)^2 (c * rate * d leaves the quotient).
    return [-damper.coefficient * (damper.rate * d) for d in jacobian_row(damper.rate, q_dot)]


def generalized_forces(model: Model, contributions: list[LoadContribution]) -> list[sp.Expr]:
    """Total generalized force on each coordinate (sum of the contributions)."""
    totals: dict[str, list[sp.Expr]] = {c.name: [] for c in model.coordinates}
    for contribution in contributions:
        totals[contribution.coordinate].append(contribution.expression)
    return [sp.Add(*totals[c.name]) for c in model.coordinates]
