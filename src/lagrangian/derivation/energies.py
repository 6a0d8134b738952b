"""Each component's share of the potential energy V (J) and of Rayleigh's dissipation D (W),
one table entry per component kind (tests/model/test_component_tables.py walks every kind)."""

from __future__ import annotations

from functools import singledispatch

import sympy as sp

from ..model.model import Body, Damper, Gravity, Particle, Spring
from ..model.rotations import RigidBody


@singledispatch
def potential_terms(component, gravity: Gravity | None) -> list[sp.Expr]:
    """The terms ``component`` adds to V (J); none for a kind that stores no energy."""
    raise TypeError(f"no potential energy for a component of kind {type(component).__name__}")


def _weight(component, gravity: Gravity | None) -> list[sp.Expr]:
    """V = -m g d . r: the weight's potential, d the unit direction of gravity."""
    if gravity is None:
        return []
    height = sp.Add(*(d * r for d, r in zip(gravity.direction, component.position, strict=True)
                      if d != 0))
    return [-component.mass * gravity.magnitude * height]


for _kind in (Particle, Body, RigidBody):
    potential_terms.register(_kind, _weight)


@potential_terms.register
def _(spring: Spring, gravity: Gravity | None) -> list[sp.Expr]:
    """V = 1/2 k (length - rest length)^2."""
    return [sp.Rational(1, 2) * spring.stiffness * (spring.length - spring.rest_length) ** 2]


@potential_terms.register
def _(damper: Damper, gravity: Gravity | None) -> list[sp.Expr]:
    return []


@singledispatch
def dissipation_terms(component) -> list[sp.Expr]:
    """The terms ``component`` adds to Rayleigh's dissipation function D (W)."""
    raise TypeError(f"no dissipation for a component of kind {type(component).__name__}")


@dissipation_terms.register
def _(damper: Damper) -> list[sp.Expr]:
    """D = 1/2 c rate^2."""
    return [sp.Rational(1, 2) * damper.coefficient * damper.rate**2]


for _kind in (Particle, Body, RigidBody, Spring):
    dissipation_terms.register(_kind, lambda component: [])
