"""A robot's kinematic tree in numbers, kept beside its symbolic rigid bodies.

Each moving body hangs from its parent body (or the ground) by one revolute or prismatic joint:

    R = R_0 Rot(u, theta),  p = t_0           (revolute: child axes -> parent axes, origin in parent)
    R = R_0,                p = t_0 + R_0 u theta   (prismatic)

with theta = k q[c] + offset (k = 1, offset = 0 except for a mimic joint). Fixed and locked
joints are folded into R_0, t_0 of the next joint down, and the links they carry into the
inertia of the moving body above them. A body's inertia is (m, h = m c, J_O): mass (kg), first
moment about its frame's origin (kg m) and inertia tensor about that origin (kg m^2), in its
own axes: additive, so the links fixed to one body simply sum. Recursive algorithms (composite
rigid body, Newton-Euler) run on this tree without the expanded equations.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..kinds import JointKind

Vector3 = tuple[float, float, float]
Matrix3x3 = tuple[Vector3, Vector3, Vector3]


@dataclass(frozen=True)
class TreeJoint:
    """One moving body and the joint that carries it (numbers in SI, parent-first order)."""

    name: str
    parent: int  # index of the parent body in the tree, -1 for the ground
    kind: JointKind
    rotation: Matrix3x3  # R_0: joint axes -> parent body axes
    translation: Vector3  # t_0: the joint's origin in the parent body (m)
    axis: Vector3  # unit axis u in joint axes
    coordinate: int  # index of the generalized coordinate that drives it
    multiplier: float  # theta = multiplier * q[coordinate] + offset
    offset: float
    mass: float  # kg
    first_moment: Vector3  # h = m c about the joint's origin, body axes (kg m)
    inertia: Matrix3x3  # J_O about the joint's origin, body axes (kg m^2)

    def __post_init__(self):
        object.__setattr__(self, "kind", JointKind(self.kind))


@dataclass(frozen=True)
class TreeFrame:
    """A named frame (a URDF link, or the joint whose child it is) fixed to a body of the tree:
    its axes are ``rotation`` (frame -> body axes) and its origin ``translation`` (m, in the
    body's axes) relative to the body's own frame; ``body`` -1 is the ground."""

    name: str
    body: int
    rotation: Matrix3x3
    translation: Vector3


@dataclass(frozen=True)
class KinematicTree:
    """The moving bodies of a robot, gravity g along ``gravity_direction`` (world axes, unit),
    and for each coordinate the parameter whose value is its actuator force (tau_<joint>)."""

    joints: tuple[TreeJoint, ...]
    coordinates: tuple[str, ...]
    gravity_parameter: str
    gravity_direction: Vector3
    actuators: tuple[str, ...]  # one parameter name per coordinate
    # The model's rigid bodies built from the same joints: a model whose bodies are not these
    # (edited after reading) is not described by this tree.
    rigid_bodies: tuple = field(default=(), compare=False, repr=False)
    # Every link and joint frame, for placements and Jacobians (dynamics/frames.py); not part of
    # the tree's identity (the dynamics, and the compiled module's key, do not depend on them).
    frames: tuple[TreeFrame, ...] = field(default=(), compare=False, repr=False)


__all__ = ["KinematicTree", "TreeFrame", "TreeJoint"]
