"""Gravity as a vector: a model under uniform gravity g = (g_x, g_y, g_z) in world axes (m/s^2),
for a wall- or ceiling-mounted arm or a robot on a slope.

The model keeps its gravity parameter (a URDF's ``g``) as the magnitude |g| and takes the
direction g/|g|; a URDF tree's direction follows, so its recursive dynamics see the same vector
(the generated module is keyed by the tree's numbers: a new direction is a new build, cached).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import sympy as sp

from ..errors import InputError
from .model import Gravity, Model


def gravity_vector(values: Sequence[object], field: str = "gravity") -> tuple[float, float, float]:
    """Three finite numbers (m/s^2, world axes), or an InputError naming ``field``."""
    if isinstance(values, str | bytes) or not hasattr(values, "__len__") or len(values) != 3:
        raise InputError("gravity is a vector of three numbers g_x, g_y, g_z (m/s^2)", field=field)
    try:
        numbers = tuple(float(x) for x in values)
    except (TypeError, ValueError):
        raise InputError(f"gravity {list(values)!r} is not three numbers", field=field) from None
    if not all(math.isfinite(x) for x in numbers):
        raise InputError("gravity's components must be finite", field=field)
    return numbers  # type: ignore[return-value]


def with_gravity(model: Model, values: Sequence[object], field: str = "gravity") -> Model:
    """The model under gravity ``values`` (m/s^2, world axes): its gravity parameter set to the
    magnitude, its direction (and its URDF tree's) to the unit vector; a zero vector keeps the
    direction with magnitude 0."""
    vector = gravity_vector(values, field)
    gravity = model.gravity
    if gravity is None:
        raise InputError(f"the model '{model.name}' declares no gravity to turn", field=field)
    magnitude = [p for p in model.parameters if p.symbol == gravity.magnitude]
    if not magnitude:
        raise InputError("the model's gravity magnitude is an expression "
                         f"({gravity.magnitude}), not one parameter: set its parameters instead",
                         field=field)
    length = math.hypot(*vector)
    direction = gravity.direction
    if length > 0:
        # numbers, an integer where within round-off of one ((0, 0, -9.81) -> (0, 0, -1))
        direction = tuple(sp.Integer(round(c)) if abs(c - round(c)) < 1e-15 else sp.Float(c)
                          for c in (x / length for x in vector))
    name = magnitude[0].name
    parameters = tuple(replace(p, value=length) if p.name == name else p for p in model.parameters)
    tree = model.kinematic_tree
    if tree is not None and tree.gravity_parameter == name:
        tree = replace(tree, gravity_direction=tuple(float(d) for d in direction))
    return replace(model, parameters=parameters, gravity=Gravity(gravity.magnitude, direction),
                   kinematic_tree=tree)


__all__ = ["gravity_vector", "with_gravity"]
