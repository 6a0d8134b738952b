"""Rigid bodies in space: rotation sequences, joints, inertia tensors, and their validation.

A body's orientation is the rotation matrix R (body axes -> world axes, so the columns of R are
the body axes written in the world). It comes from a body-fixed rotation sequence of named axes
(z-x-z Euler angles: R = Rz(phi) Rx(theta) Rz(psi)) or from a joint on a parent body
(R = R_parent R_joint). The angular velocity is composed along the same chain, exactly as
omega~ = R^T R_dot in body axes (rad/s), without differentiating R:

    omega_child = R_step^T omega_parent + alpha_dot u      (one rotation by alpha about u)

which keeps the components short (no sin^2 + cos^2 left to cancel).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import sympy as sp

from ..errors import ModelError, did_you_mean
from ..kinds import JointKind
from .structure import same_structure
from .vector import Vector

Matrix3 = tuple[Vector, Vector, Vector]

AXES: dict[str, Vector] = {
    "x": (sp.S.One, sp.S.Zero, sp.S.Zero),
    "y": (sp.S.Zero, sp.S.One, sp.S.Zero),
    "z": (sp.S.Zero, sp.S.Zero, sp.S.One),
}
# each compares equal to its word in a model file (a free flyer is a URDF robot's base only)
JOINT_TYPES = tuple(k for k in JointKind
                    if k not in (JointKind.FREE_FLYER, JointKind.HELICAL, JointKind.FREE))
JOINT_KEYS = {  # the required and optional keys of each kind's table
    JointKind.REVOLUTE: ({"type", "axis", "angle"}, {"at"}),
    JointKind.PRISMATIC: ({"type", "axis", "distance"}, {"at"}),
    JointKind.SPHERICAL: ({"type", "rotation"}, {"at"}),
    JointKind.FIXED: ({"type"}, {"at", "rotation"}),
    JointKind.FREE_FLYER: ({"type"}, set()),  # refused by JOINT_TYPES before its keys are read
    JointKind.HELICAL: ({"type"}, set()),  # a tree builder's only (model/robot_builder.py): refused
    JointKind.FREE: ({"type"}, set()),  # an MJCF robot's only (model/mjcf_free.py): refused
}
# Exact numbers up to this size (numerator and denominator) stay exact in a unit vector; others
# are taken as floats: the exact length of (1e-290, 0, -1) cost 5-30 s of factoring.
SMALL_EXACT = 10**6
_IDENTITY: Matrix3 = (AXES["x"], AXES["y"], AXES["z"])
_ZERO: Vector = (sp.S.Zero, sp.S.Zero, sp.S.Zero)


@dataclass(frozen=True)
class BodyJoint:
    """The one-degree-of-freedom joint that carries a body (a model file's revolute or prismatic
    ``joint``), kept beside the frames it made so that the body's tree can be read in numbers
    (model/tree.body_tree): origin ``at`` (m, parent axes), unit ``axis`` (joint axes = parent
    axes), the joint ``variable`` (rad or m, an expression in q), and the body's centre of mass
    ``center`` (m, body axes, from the joint)."""

    kind: JointKind
    at: Vector
    axis: Vector
    variable: sp.Expr
    center: Vector


@dataclass(frozen=True)
class RigidBody:
    """A rigid body in space: mass (kg), inertia tensor about its centre of mass in body axes
    (kg m^2), centre of mass r (m, world axes), rotation R (body -> world), origin of its body
    frame (m, world) and angular velocity omega in body axes (rad/s, linear in q_dot)."""

    name: str
    mass: sp.Expr
    inertia: Matrix3
    position: Vector
    rotation: Matrix3
    origin: Vector
    angular_velocity: Vector
    parent: str | None = None
    # Each three-angle sequence on the way to this body: (its description, the angle names, the
    # determinant of the map from the angle rates to omega, zero at gimbal lock).
    singularities: tuple[tuple[str, tuple[str, ...], sp.Expr], ...] = ()
    # The revolute or prismatic joint that carries it (None: a rotation sequence, a fixed or
    # spherical joint, a URDF link), and its elementary rotations from the ground.
    joint: BodyJoint | None = None
    depth: int = 0

    def __eq__(self, other) -> bool:
        # field by field with shared nodes compared once (structure.py): sympy's == on a deep
        # chain's positions compares them written out
        if not isinstance(other, RigidBody):
            return NotImplemented
        return same_structure(self, other)

    def world_angular_velocity(self) -> Vector:
        """omega in world axes, R omega_body (rad/s)."""
        return apply(self.rotation, self.angular_velocity)

    def point(self, offset: Vector) -> Vector:
        """The point fixed at ``offset`` (body axes, from the body's origin), in the world (m)."""
        return add(self.origin, apply(self.rotation, offset))


@dataclass(frozen=True)
class Moment:
    """A moment M (N m) on a rigid body; virtual work M . delta(phi), so Q_i = M . d omega/d q_dot_i
    with omega in the axes M is given in (``axes``: "world" or "body")."""

    name: str
    body: str
    moment: Vector
    axes: str
    angular_velocity: Vector


# -- small 3-vector algebra on sympy expressions ----------------------------------------------

def apply(matrix: Matrix3, vector: Vector) -> Vector:
    return tuple(sp.Add(*(a * v for a, v in zip(row, vector, strict=True) if a != 0 and v != 0))
                 for row in matrix)


def apply_transpose(matrix: Matrix3, vector: Vector) -> Vector:
    return apply(transpose(matrix), vector)


def transpose(matrix: Matrix3) -> Matrix3:
    return tuple(tuple(matrix[i][j] for i in range(3)) for j in range(3))


def compose(a: Matrix3, b: Matrix3) -> Matrix3:
    columns = [apply(a, tuple(b[i][j] for i in range(3))) for j in range(3)]
    return tuple(tuple(columns[j][i] for j in range(3)) for i in range(3))


def add(a: Vector, b: Vector) -> Vector:
    return tuple(x + y for x, y in zip(a, b, strict=True))


# Checked before any derivation (docs/robustness.md): the cost grows with the products of
# sines and cosines. Measured: a sequence of 6 elementary rotations derives in 3 s, of 12 in over
# two minutes; a chain of 20 revolute bodies in 4 s, of 24 in 13 s, of 30 in over 100 s.
MAX_SEQUENCE_ROTATIONS = 6
MAX_CHAIN_ROTATIONS = 24


def axis_rotation(axis: Vector, angle: sp.Expr) -> Matrix3:
    """The rotation by ``angle`` about the unit vector ``axis`` (Rodrigues)."""
    c, s = sp.cos(angle), sp.sin(angle)
    named = next((k for k, v in AXES.items() if v == tuple(axis)), None)
    if named == "x":
        return ((1, 0, 0), (0, c, -s), (0, s, c))
    if named == "y":
        return ((c, 0, s), (0, 1, 0), (-s, 0, c))
    if named == "z":
        return ((c, -s, 0), (s, c, 0), (0, 0, 1))
    x, y, z = axis
    v = 1 - c
    return ((c + x * x * v, x * y * v - z * s, x * z * v + y * s),
            (y * x * v + z * s, c + y * y * v, y * z * v - x * s),
            (z * x * v - y * s, z * y * v + x * s, c + z * z * v))


def floated(expr: sp.Expr) -> sp.Expr:
    """``expr`` with each exact number that is not small (numerator or denominator of
    SMALL_EXACT or more) taken as a float."""
    big = {r: sp.Float(r) for r in expr.atoms(sp.Rational)
           if abs(r.p) >= SMALL_EXACT or r.q >= SMALL_EXACT}
    return expr.xreplace(big) if big else expr


def unit_vector(vector: Vector) -> Vector | None:
    """A vector of numbers over its length; None where it has none (zero, or not finite).
    Small exact numbers stay exact ((3, 0, 4) -> (3/5, 0, 4/5)); others are taken as floats, a
    component within round-off of an integer made that integer."""
    if all(floated(c) == c for c in vector):
        squared = sp.Add(*(c**2 for c in vector))
        return None if squared == 0 else tuple(c / sp.sqrt(squared) for c in vector)
    numbers = [float(c) for c in vector]
    length = math.hypot(*numbers)
    if not math.isfinite(length) or length == 0:
        return None
    unit = [c / length for c in numbers]
    return tuple(sp.Integer(round(c)) if abs(c - round(c)) < 1e-15 else sp.Float(c)
                 for c in unit)


@dataclass(frozen=True)
class Frame:
    """A body frame on the way down a tree: origin (world), R (body -> world), omega (body)."""

    origin: Vector
    rotation: Matrix3
    angular_velocity: Vector
    singularities: tuple[tuple[str, tuple[str, ...], sp.Expr], ...] = ()
    # omega in world axes, composed step by step (omega_parent + alpha_dot R u) so that no
    # sin^2 + cos^2 of a spin angle is left to cancel, as R omega_body would leave (rolling
    # contacts use it); None where it was not followed.
    world_angular_velocity: Vector | None = None


GROUND = Frame(_ZERO, _IDENTITY, _ZERO, (), _ZERO)


def rotate(frame: Frame, axis: Vector, angle: sp.Expr, rate: sp.Expr) -> Frame:
    """The frame turned by ``angle`` about its own ``axis`` (body-fixed); rate = d(angle)/dt."""
    step = axis_rotation(axis, angle)
    omega = add(apply_transpose(step, frame.angular_velocity),
                tuple(rate * a for a in axis))
    world = None
    if frame.world_angular_velocity is not None:
        world = add(frame.world_angular_velocity,
                    tuple(rate * a for a in apply(frame.rotation, axis)))
    return Frame(frame.origin, compose(frame.rotation, step), omega, frame.singularities, world)


def translate(frame: Frame, offset: Vector) -> Frame:
    """The frame moved by ``offset`` given in its own axes."""
    return Frame(add(frame.origin, apply(frame.rotation, offset)), frame.rotation,
                 frame.angular_velocity, frame.singularities, frame.world_angular_velocity)


# -- reading the user's description -----------------------------------------------------------

class RotationReader:
    """Turns the user's rotation sequences, joints and inertia into frames, naming each field.

    ``expression(value, field)`` parses an angle or length in q and t (no velocities);
    ``vector(value, field)`` a 3-vector; ``rate(expr)`` is d/dt along the motion.
    """

    def __init__(self, expression: Callable, vector: Callable, rate: Callable,
                 source: str | None):
        self.expression, self.vector, self.rate, self.source = expression, vector, rate, source

    def error(self, message: str, field: str) -> ModelError:
        return ModelError(message, field=field, source=self.source)

    def axis(self, value: object, field: str) -> Vector:
        """A named axis ('x', 'y', 'z', '-x', ...) or a 3-vector (normalized); never zero."""
        if isinstance(value, str):
            name = value.strip().lower()
            sign = -1 if name.startswith("-") else 1
            name = name.lstrip("+-")
            if name not in AXES:
                raise self.error(f"unknown axis '{value}': use x, y or z (or a 3-component "
                                 f"vector){did_you_mean(name, list(AXES))}", field)
            return tuple(sign * a for a in AXES[name])
        if not isinstance(value, Sequence):
            raise self.error(f"an axis is x, y or z (or -x, ...) or a 3-component vector, not "
                             f"{value!r}", field)
        vector = self.vector(value, field)
        if not any(c.free_symbols for c in vector):
            unit = unit_vector(vector)
            if unit is None:
                raise self.error("the axis has zero length", field)
            return unit
        vector = tuple(floated(c) for c in vector)
        squared = sp.Add(*(c**2 for c in vector))
        if squared.free_symbols:
            # parameters only (a steering axis tilted by an angle lambda): fixed in the parent
            if any(self.rate(c) != 0 for c in vector):
                raise self.error("a joint axis must be fixed in the parent (numbers or "
                                 "parameters, not coordinates or time)", field)
            squared = sp.trigsimp(squared)  # sin(a)^2 + cos(a)^2: short, parameters only
        if squared == 0:
            raise self.error("the axis has zero length", field)
        norm = sp.sqrt(squared)
        return tuple(c / norm for c in vector)

    def sequence(self, frame: Frame, value: object, field: str) -> Frame:
        """Apply a body-fixed rotation sequence [[axis, angle], ...] to ``frame``."""
        if isinstance(value, str) or not isinstance(value, Sequence) or not value:
            raise self.error('a rotation is a list of [axis, angle] pairs, e.g. '
                             '[["z", "phi"], ["x", "theta"], ["z", "psi"]]', field)
        if len(value) > MAX_SEQUENCE_ROTATIONS:
            raise self.error(f"{len(value)} rotations in one sequence (at most "
                             f"{MAX_SEQUENCE_ROTATIONS}: the products of their sines and cosines "
                             "make the derivation cost minutes; three angles orient a body)",
                             field)
        previous = None
        steps = []
        for k, step in enumerate(value):
            where = f"{field}[{k}]"
            if isinstance(step, str) or not isinstance(step, Sequence) or len(step) != 2:
                raise self.error('each rotation step is a pair [axis, angle], e.g. ["z", "phi"]',
                                 where)
            axis = self.axis(step[0], f"{where}[0]")
            if previous is not None and (axis == previous
                                         or axis == tuple(-a for a in previous)):
                raise self.error(
                    f"two rotations about the same axis in a row ({step[0]} after "
                    f"{value[k - 1][0]}) are one rotation: a sequence needs a different axis "
                    "next (z-x-z, z-y-x, ...)", where)
            previous = axis
            angle = self.expression(step[1], f"{where}[1]")
            steps.append((str(step[0]), axis, angle))
            frame = rotate(frame, axis, angle, self.rate(angle))
        if len(steps) == 3:
            # omega = R3^T R2^T u1 a1' + R3^T u2 a2' + u3 a3': the rates are lost where
            # det[R2(a2)^T u1, u2, u3] = 0 (sin a2 for z-x-z, cos a2 for z-y-x).
            (n1, u1, _), (n2, u2, a2), (n3, u3, _) = steps
            first = apply_transpose(axis_rotation(u2, a2), u1)
            cross = (u2[1] * u3[2] - u2[2] * u3[1], u2[2] * u3[0] - u2[0] * u3[2],
                     u2[0] * u3[1] - u2[1] * u3[0])
            determinant = sp.expand(sp.Add(*(a * b for a, b in zip(first, cross, strict=True))))
            names = tuple(str(a) for _, _, a in steps)
            frame = Frame(frame.origin, frame.rotation, frame.angular_velocity,
                          (*frame.singularities, (f"{n1}-{n2}-{n3}", names, determinant)),
                          frame.world_angular_velocity)
        return frame

    def joint(self, parent: Frame, value: object, field: str) -> Frame:
        """The child frame of a joint on ``parent`` (``at``: the joint in parent axes)."""
        if not isinstance(value, Mapping):
            raise self.error('a joint is a table {type = "revolute", axis = "z", angle = "q"}',
                             field)
        kind = value.get("type")
        if not isinstance(kind, str) or kind not in JOINT_TYPES:
            raise self.error(f"unknown joint type {kind!r}: use one of "
                             f"{', '.join(JOINT_TYPES)}{did_you_mean(str(kind), JOINT_TYPES)}",
                             f"{field}.type")
        kind = JointKind(kind)
        required, optional = JOINT_KEYS[kind]
        for key in value:
            if key not in required | optional:
                raise self.error(f"unknown key '{key}' for a {kind} joint"
                                 f"{did_you_mean(key, sorted(required | optional))}",
                                 f"{field}.{key}")
        for key in sorted(required - set(value)):
            raise self.error(f"missing key '{key}' for a {kind} joint", field)
        frame = parent
        if "at" in value:
            frame = translate(frame, self.vector(value["at"], f"{field}.at"))
        return self._JOINT_FRAMES[kind](self, frame, value, field)

    def _revolute(self, frame: Frame, value: Mapping, field: str) -> Frame:
        axis = self.axis(value["axis"], f"{field}.axis")
        angle = self.expression(value["angle"], f"{field}.angle")
        return rotate(frame, axis, angle, self.rate(angle))

    def _prismatic(self, frame: Frame, value: Mapping, field: str) -> Frame:
        axis = self.axis(value["axis"], f"{field}.axis")
        distance = self.expression(value["distance"], f"{field}.distance")
        return translate(frame, tuple(distance * a for a in axis))

    def _turned(self, frame: Frame, value: Mapping, field: str) -> Frame:
        """A spherical joint's rotation sequence, or a fixed joint's optional one."""
        if "rotation" not in value:
            return frame
        return self.sequence(frame, value["rotation"], f"{field}.rotation")

    def _free(self, frame: Frame, value: Mapping, field: str) -> Frame:
        raise self.error("a free_flyer joint is a URDF robot's floating base "
                         "(load(path, floating_base=True)); a body of a model file moves by its "
                         "coordinates", f"{field}.type")

    # one entry per JointKind (tests/model/test_component_tables.py checks none is missing)
    _JOINT_FRAMES = {JointKind.REVOLUTE: _revolute, JointKind.PRISMATIC: _prismatic,
                     JointKind.SPHERICAL: _turned, JointKind.FIXED: _turned,
                     JointKind.FREE_FLYER: _free, JointKind.HELICAL: _free,
                     JointKind.FREE: _free}

    def inertia(self, value: object, field: str, values: Mapping[sp.Symbol, float]) -> Matrix3:
        """Principal [Ixx, Iyy, Izz] or a symmetric 3x3 tensor (kg m^2), about the centre of mass
        in body axes; positive definite with each principal moment at most the sum of the
        other two, checked wherever the parameters have values."""
        if isinstance(value, str) or not isinstance(value, Sequence) or len(value) != 3:
            raise self.error("the inertia of a 3D body is [Ixx, Iyy, Izz] (principal) or a "
                             "3x3 table of rows [[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], "
                             "[Ixz, Iyz, Izz]]", field)
        rows = [isinstance(v, Sequence) and not isinstance(v, str) for v in value]
        if not any(rows):
            diagonal = [self.expression(v, f"{field}[{i}]") for i, v in enumerate(value)]
            tensor = tuple(tuple(diagonal[i] if i == j else sp.S.Zero for j in range(3))
                           for i in range(3))
        else:
            if not all(rows) or any(len(v) != 3 for v in value):
                raise self.error("a full inertia tensor has 3 rows of 3 entries", field)
            tensor = tuple(tuple(self.expression(v, f"{field}[{i}][{j}]")
                                 for j, v in enumerate(row)) for i, row in enumerate(value))
            for i in range(3):
                for j in range(i + 1, 3):
                    if sp.expand(tensor[i][j] - tensor[j][i]) != 0:
                        raise self.error(
                            f"the inertia tensor is not symmetric: entry [{i}][{j}] = "
                            f"{tensor[i][j]} but [{j}][{i}] = {tensor[j][i]}", field)
        self._check_inertia_values(tensor, field, values)
        return tensor

    def _check_inertia_values(self, tensor: Matrix3, field: str,
                              values: Mapping[sp.Symbol, float]) -> None:
        numbers = []
        for row in tensor:
            for entry in row:
                if not entry.free_symbols <= set(values):
                    return  # symbolic: decided only where every parameter has a value
                try:
                    numbers.append(float(entry.xreplace(dict(values))))
                except (TypeError, ValueError):
                    return
        import numpy as np

        matrix = np.array(numbers).reshape(3, 3)
        moments = np.linalg.eigvalsh(matrix)
        if not all(math.isfinite(m) for m in moments) or moments[0] <= 0:
            raise self.error(
                "the inertia tensor is not positive definite (principal moments "
                f"{', '.join(f'{m:.6g}' for m in moments)} kg m^2; each must be > 0)", field)
        tolerance = 1e-9 * float(moments[-1])
        if moments[0] + moments[1] < moments[2] - tolerance:
            raise self.error(
                "the principal moments break the triangle inequality I1 + I2 >= I3 "
                f"({moments[0]:.6g} + {moments[1]:.6g} < {moments[2]:.6g} kg m^2): no body "
                "has this inertia", field)


def gimbal_lock(bodies: Sequence[RigidBody], point: Mapping[sp.Symbol, float],
                tolerance: float = 1e-3) -> str | None:
    """A sentence naming the rotation sequence at (or within ``tolerance`` of) its singular
    configuration at ``point`` (values of q and the parameters), None where there is none."""
    seen = set()
    for body in bodies:
        for label, names, determinant in body.singularities:
            if (label, names) in seen:
                continue
            seen.add((label, names))
            try:
                value = float(determinant.xreplace(dict(point)))
            except (TypeError, ValueError):
                continue
            if abs(value) < tolerance:
                angles = ", ".join(names)
                where = ", ".join(f"{s} = {float(v):.6g}" for s, v in point.items()
                                  if s in determinant.free_symbols)
                return (f"gimbal lock: the {label} angles ({angles}) of body '{body.name}' are at "
                        f"their singular configuration ({where}, where {determinant} = 0: the "
                        "first and last axes line up and the rates are lost); choose a rotation "
                        "sequence whose singular configuration the motion avoids")
    return None


__all__ = ["AXES", "GROUND", "BodyJoint", "MAX_CHAIN_ROTATIONS", "MAX_SEQUENCE_ROTATIONS", "Frame", "Moment",
           "RigidBody", "RotationReader", "apply", "gimbal_lock", "axis_rotation", "compose",
           "rotate", "translate", "transpose"]
