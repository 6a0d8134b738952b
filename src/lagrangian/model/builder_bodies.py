"""ModelBuilder's rigid bodies in space: bodies on joints or rotation sequences, moments on
them, points fixed in them (a mixin of builder.ModelBuilder, sharing its declarations)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Self

import sympy as sp

from ..errors import did_you_mean
from ..kinds import JointKind
from .rotations import (
    GROUND,
    BodyJoint,
    Frame,
    Moment,
    RigidBody,
    RotationReader,
)
from .vector import Vector


def _elementary_rotations(joint: object) -> int:
    """Elementary rotations a joint (or a body's own rotation sequence) adds: 1 for a revolute
    joint, the length of a spherical or fixed joint's sequence, 0 for a prismatic one."""
    if not isinstance(joint, Mapping):
        return 0
    if joint.get("type") == "revolute":
        return 1
    sequence = joint.get("rotation")
    return len(sequence) if isinstance(sequence, Sequence) and not isinstance(sequence, str) \
        else 0


class RigidBodiesMixin:
    """add_rigid_body, add_moment, body_point."""

    def add_rigid_body(
        self, name: str, mass: object, inertia: object, *, position: Sequence[object] | None = None,
        rotation: Sequence | None = None, origin: Sequence[object] | None = None,
        center: Sequence[object] | None = None, parent: str | None = None,
        joint: dict | None = None, field: str | None = None,
    ) -> Self:
        """A rigid body in space: mass (kg), inertia about its centre of mass in body axes
        (kg m^2; [Ixx, Iyy, Izz] or a symmetric 3x3), oriented by a body-fixed ``rotation``
        sequence [[axis, angle], ...] or by a ``joint`` on its ``parent`` (or on the ground).

        Where: ``position`` (its centre of mass, world, m), or ``origin`` (its body frame, world)
        with ``center`` (the centre of mass from the origin, body axes); a body on a joint has
        its origin at the joint and may give ``center``.
        """
        field = field or f"body '{name}'"
        self._component(name, field)
        self._vectors.append((field, 3, "rigid body"))
        self._check_dimensions()
        reader = self._rotation_reader()
        given = {k for k, v in (("position", position), ("rotation", rotation),
                                ("origin", origin), ("center", center), ("joint", joint))
                 if v is not None}
        if parent is not None:
            if parent == name:
                raise self._error(f"body '{name}' is its own parent (a cycle)", f"{field}.parent")
            frame = self._frames.get(parent)
            if frame is None:
                names = list(self._frames)
                raise self._error(f"no body '{parent}' to attach to (declare the parent first)"
                                  f"{did_you_mean(parent, names)}", f"{field}.parent")
            if joint is None:
                raise self._error("a body with a parent needs a 'joint'", f"{field}.joint")
            for key in sorted(given & {"position", "rotation", "origin"}):
                raise self._error(f"'{key}' comes from the joint on '{parent}': give the joint "
                                  "instead", f"{field}.{key}")
        else:
            frame = GROUND
            if joint is not None:
                for key in sorted(given & {"position", "rotation", "origin"}):
                    raise self._error(f"'{key}' comes from the joint (on the ground): give one "
                                      "or the other", f"{field}.{key}")
            elif (position is None) == (origin is None):
                raise self._error("give the centre of mass 'position' or the body's 'origin' "
                                  "(with 'center')", field)
            if position is not None and center is not None:
                raise self._error("'center' is measured from 'origin': give 'origin' with it, "
                                  "or 'position' alone", f"{field}.center")
        own = _elementary_rotations(joint if joint is not None else {"rotation": rotation})
        rotations = own + (self._rotations.get(parent, 0) if parent is not None else 0)
        # A chain deeper than MAX_CHAIN_ROTATIONS is refused by derive (its symbolic equations
        # take minutes), not here: its dynamics, simulation and modes go down the tree.
        self._rotations[name] = rotations
        if joint is not None:
            frame = reader.joint(frame, joint, f"{field}.joint")
        else:
            start = position if position is not None else origin
            key = "position" if position is not None else "origin"
            frame = Frame(self.vector(start, f"{field}.{key}", velocities=False,
                                      places="rigid body"), frame.rotation,
                          frame.angular_velocity, (), frame.world_angular_velocity)
            if rotation is not None:
                frame = reader.sequence(frame, rotation, f"{field}.rotation")
        offset = (self.vector(center, f"{field}.center", velocities=False)
                  if center is not None else (sp.S.Zero,) * 3)
        values = {p.symbol: p.value for p in self._parameters if p.value is not None}
        body = RigidBody(
            name,
            self.expression(mass, f"{field}.mass", velocities=False),
            reader.inertia(inertia, f"{field}.inertia", values),
            # zero offsets skipped: 0 * (a deep rotation product) makes sympy ask is_finite
            # of the whole tree (a tenth of a second per body down a chain)
            tuple(o + sum((r * c for r, c in zip(row, offset, strict=True) if c != 0),
                          sp.S.Zero)
                  for o, row in zip(frame.origin, frame.rotation, strict=True)),
            frame.rotation, frame.origin, frame.angular_velocity, parent, frame.singularities,
            self._body_joint(reader, joint, offset, f"{field}.joint"), rotations,
        )
        self._frames[name] = frame
        self._rigid_bodies.append(body)
        return self

    def add_moment(
        self, name: str, body: str, moment: Sequence[object], *, axes: str = "world",
        field: str | None = None,
    ) -> Self:
        """A moment (N m) on a rigid body, in world or body axes; Q_i = M . d omega/d q_dot_i."""
        field = field or f"load '{name}'"
        self._component(name, field)
        target = next((b for b in self._rigid_bodies if b.name == body), None)
        if target is None:
            raise self._error(f"'{body}' is not a 3D body (declare it before use)"
                              f"{did_you_mean(str(body), [b.name for b in self._rigid_bodies])}",
                              f"{field}.body")
        if axes not in ("world", "body"):
            raise self._error(f"axes must be 'world' or 'body', not {axes!r}", f"{field}.axes")
        omega = (target.world_angular_velocity() if axes == "world"
                 else target.angular_velocity)
        self._require_coordinate_dependence(
            [e for row in target.rotation for e in row], name, f"{field}.body", "rotation")
        self._loads.append(Moment(name, body, self.vector(moment, f"{field}.moment"), axes, omega))
        return self

    def _body_joint(self, reader: RotationReader, joint: Mapping | None, center: Vector,
                    field: str) -> BodyJoint | None:
        """A revolute or prismatic joint as read (already checked by reader.joint), for the
        body's tree; None for any other way of placing a body."""
        if joint is None or joint.get("type") not in (JointKind.REVOLUTE, JointKind.PRISMATIC):
            return None
        kind = JointKind(joint["type"])
        at = (self.vector(joint["at"], f"{field}.at", velocities=False) if "at" in joint
              else (sp.S.Zero,) * 3)
        key = "angle" if kind == JointKind.REVOLUTE else "distance"
        return BodyJoint(kind, at, reader.axis(joint["axis"], f"{field}.axis"),
                         self.expression(joint[key], f"{field}.{key}", velocities=False),
                         tuple(center))

    def _rotation_reader(self) -> RotationReader:
        def angle(value, field):
            return self.expression(value, field, velocities=False)

        def vector(value, field):
            return self.vector(value, field, velocities=False)

        return RotationReader(angle, vector, self._time_derivative, self.source)

    def body_point(
        self, body: str, offset: Sequence[object], *, field: str = "point"
    ) -> Vector:
        """The point fixed in a body at ``offset`` (m, in the body's axes; from a planar body's
        centre of mass, from a 3D body's origin)."""
        for candidate in self._rigid_bodies:
            if candidate.name == body:
                offset = (0, 0, 0) if offset is None else offset
                return candidate.point(self.vector(offset, f"{field}.offset", velocities=False))
        offset = (0, 0) if offset is None else offset
        for candidate in self._bodies:
            if candidate.name == body:
                dx, dy, dz = self.vector(offset, f"{field}.offset", velocities=False)
                c, s = sp.cos(candidate.angle), sp.sin(candidate.angle)
                x, y, z = candidate.position
                return (x + c * dx - s * dy, y + s * dx + c * dy, z + dz)
        raise self._error(f"'{body}' is not a body (declare it before use)", f"{field}.body")
