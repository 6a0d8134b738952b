"""Rolling contact: a knife-edge wheel rolling without slipping on a ground plane.

A wheel of radius r (m) is a rigid body whose origin is the wheel's centre G and whose axle is
the unit vector a (body axes; R a in the world). On a ground plane through the world origin with
unit normal n (pointing out of the ground, towards the wheel) the wheel touches the ground at

    r_C = r_G + r d,    d = -(n - (n.a) a) / |n - (n.a) a|

(d: the unit vector in the wheel's plane pointing down to the ground). Rolling without slipping
is the material point at C at rest along the two ground tangents t1, t2:

    (v_G + omega x (r d)) . t_k = 0      (velocity constraints; multipliers lambda_k),

with the force of the ground on the wheel along t_k equal to -lambda_k (the friction). Where the
contact height r_C . n is not identically zero in the chosen coordinates, the holonomic
constraint r_C . n = 0 keeps the wheel on the ground (the normal force is -lambda_normal).
The constraints enter by multipliers only: they are never substituted into L.
"""

from __future__ import annotations

import random
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import sympy as sp

from .rotations import apply
from .vector import Vector

# Simplification of the wheel-plane direction is tried only on expressions this small (op
# count): trigsimp of a short sin^2 + cos^2 is cheap, of a long expression it is not.
SIMPLIFY_LIMIT = 60
# The contact height is judged identically zero when it is below this (relative) at random
# states, the probabilistic identity test of derivation/regularity.py.
ZERO_TOLERANCE = 1e-10
_TANGENT_NAMES = {0: ("y", "z"), 1: ("z", "x"), 2: ("x", "y")}


@dataclass(frozen=True)
class RollingContact:
    """A wheel of ``radius`` (m) on ``body`` rolling without slipping on the plane r . n = 0.

    ``constraints`` names the constraints it added: the two tangential ones (friction along
    ``tangents``) and, where the contact height is not identically zero, the normal one.
    """

    name: str
    body: str
    radius: sp.Expr
    axle: Vector  # body axes, unit
    normal: Vector  # world, unit
    tangents: tuple[Vector, Vector]
    contact_point: Vector  # r_C in the world (m)
    constraints: tuple[str, ...]
    holonomic: bool  # True: the normal constraint r_C . n = 0 was added


def ground_tangents(normal: Sequence[float]) -> tuple[tuple[Vector, Vector], tuple[str, str]]:
    """Two unit tangents (t1, t2, n right-handed) of the plane with the numeric unit normal n,
    with their names: the world axes where n is along one (x, y for n = +-z)."""
    import numpy as np

    n = np.array([float(c) for c in normal])
    axis = int(np.argmax(np.abs(n)))
    if abs(abs(n[axis]) - 1.0) < 1e-14:
        first, second = _TANGENT_NAMES[axis]
        t1 = [sp.S.Zero] * 3
        t2 = [sp.S.Zero] * 3
        t1["xyz".index(first)] = sp.S.One
        t2["xyz".index(second)] = sp.S.One
        return (tuple(t1), tuple(t2)), (first, second)
    helper = np.eye(3)[int(np.argmin(np.abs(n)))]
    t1 = helper - (helper @ n) * n
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    return (tuple(sp.Float(c) for c in t1), tuple(sp.Float(c) for c in t2)), ("t1", "t2")


def wheel_down_direction(a: Vector, n: Vector, reference: Mapping[sp.Symbol, float]) -> Vector:
    """d = -(n - (n.a) a)/|n - (n.a) a|: the unit vector in the wheel plane towards the ground.

    |n - (n.a) a|^2 = 1 - (n.a)^2 (a and n are unit). Where that is a perfect square of a short
    expression (cos(lean)^2 for a wheel leaned by a roll angle), its root is taken as that
    expression, with the sign that is positive at ``reference`` (the coordinates' initial
    values): no square root, and d is exact as long as the wheel does not lie flat.
    """
    along = sp.Add(*(x * y for x, y in zip(n, a, strict=True)))
    w = tuple(x - along * y for x, y in zip(n, a, strict=True))
    squared = 1 - along**2
    norm = None
    if sp.count_ops(squared) <= SIMPLIFY_LIMIT:
        simpler = sp.factor(sp.trigsimp(squared))
        root = _square_root(simpler)
        if root is not None:
            value = _value(root, reference)
            if value is not None and value != 0:
                norm = root if value > 0 else -root
    if norm is None:
        return tuple(-c / sp.sqrt(squared) for c in w)
    down = []
    for c in w:
        component = -c / norm
        if sp.count_ops(component) <= SIMPLIFY_LIMIT:
            component = sp.trigsimp(sp.cancel(component))
        down.append(component)
    return tuple(down)


def _square_root(expr: sp.Expr) -> sp.Expr | None:
    """e where expr = e^2 (a product of even powers), else None."""
    factors = sp.Mul.make_args(expr)
    root = []
    for factor in factors:
        base, exponent = factor.as_base_exp()
        if factor.is_Number and factor.is_positive:
            root.append(sp.sqrt(factor))
        elif exponent.is_Integer and exponent % 2 == 0:
            root.append(base ** (exponent // 2))
        else:
            return None
    return sp.Mul(*root)


def _value(expr: sp.Expr, point: Mapping[sp.Symbol, float]) -> float | None:
    try:
        return float(expr.xreplace({k: sp.Float(v) for k, v in point.items()}))
    except (TypeError, ValueError):
        return None


def identically_zero(expr: sp.Expr, coordinates: Sequence[sp.Symbol],
                     parameters: Mapping[sp.Symbol, float | None], samples: int = 5) -> bool:
    """expr == 0 for every configuration: symbolically (expanded), else numerically at random
    configurations (|q| < 1, parameters at their values or random in (0.5, 2)), a probabilistic
    identity test as derivation/regularity.py's ``vanishes``."""
    expr = sp.expand(expr)
    if expr == 0:
        return True
    rng = random.Random(4321)
    for _ in range(samples):
        point = {s: rng.uniform(-1.0, 1.0) for s in coordinates}
        point |= {s: (v if v is not None else rng.uniform(0.5, 2.0))
                  for s, v in parameters.items()}
        scale = max([1.0, *(abs(v) for v in point.values())])
        others = expr.free_symbols - set(point)
        point |= {s: rng.uniform(0.5, 2.0) for s in others}
        value = _value(expr, point)
        if value is None or abs(value) > ZERO_TOLERANCE * scale:
            return False
    return True


def contact_velocity(centre_velocity: Vector, omega: Vector, arm: Vector) -> Vector:
    """v_G + omega x arm (m/s): the velocity of the material point at G + arm."""
    cross = (omega[1] * arm[2] - omega[2] * arm[1], omega[2] * arm[0] - omega[0] * arm[2],
             omega[0] * arm[1] - omega[1] * arm[0])
    return tuple(v + c for v, c in zip(centre_velocity, cross, strict=True))


def dot(a: Vector, b: Vector) -> sp.Expr:
    return sp.Add(*(x * y for x, y in zip(a, b, strict=True) if x != 0 and y != 0))


__all__ = ["RollingContact", "apply", "contact_velocity", "dot", "ground_tangents",
           "identically_zero", "wheel_down_direction"]
