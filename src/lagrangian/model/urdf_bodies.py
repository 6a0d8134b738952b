"""A URDF robot's symbolic rigid bodies (model/urdf.py reads and checks the file): each link's
frame down the joints, R_child = R_parent R_origin(rpy) R_axis(angle) and x_child = x_parent +
R_parent xyz (+ d axis), and its inertial turned into link axes, I = R I' R^T (kg m^2). A
floating joint between two links moves its child by its six coordinates: x, y, z (m) along the
joint frame's axes, then yaw, pitch and roll (rad) as the URDF's rpy, R = Rz(yaw) Ry(pitch)
Rx(roll); the kinematic tree holds the same joint as a free flyer with a quaternion
(urdf_tree.py)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import sympy as sp

from ..errors import ModelWarning
from .lazy_bodies import LazyBodies
from .rotations import GROUND, Frame, RigidBody, apply, apply_transpose, compose, rotate, translate
from .tree import KinematicTree
from .urdf_tree import FREE_SLIDES, FREE_TURNS, MOVABLE, SNAP, carries_nothing


def _number(x: float) -> sp.Expr:
    x = float(x)
    if not math.isfinite(x):
        raise ValueError(x)
    if abs(x) < SNAP:
        return sp.S.Zero
    if abs(x - round(x)) < SNAP and abs(x) < 1e6:
        return sp.Integer(round(x))
    text = repr(x)
    if len(text) <= 8 and "e" not in text:
        # the short decimal the file wrote (0.4 -> 2/5): exact, and printed equations stay short
        return sp.Rational(text)
    return sp.Float(x)


def _matrix(a) -> tuple:
    return tuple(tuple(_number(v) for v in row) for row in np.asarray(a, dtype=float))


def _vector(a) -> tuple:
    return tuple(_number(v) for v in np.asarray(a, dtype=float))


class SymbolicBodies:
    """The rigid bodies of a URDF tree (urdf._Tree's: its links, error and free joints)."""

    free: dict[str, str]  # a floating joint between two links -> its coordinates' stem

    def _bodies(self, root: str, order, position) -> list[RigidBody]:
        frames: dict[str, Frame] = {root: GROUND}
        parents: dict[str, str | None] = {root: None}
        # whether a link moves: some joint above it has a coordinate in its position (asked of
        # the joints, never of the frames: free_symbols walks a deep chain's shared subtrees
        # as a tree, minutes at 30 links)
        moves: dict[str, bool] = {root: False}
        for joint in order:
            frame = frames[joint.parent]
            if joint.origin is not None:
                origin = np.asarray(joint.origin, dtype=float)
                frame = translate(frame, _vector(origin[:3, 3]))
                frame = _turned(frame, _matrix(origin[:3, :3]))
            if joint.name in self.free:  # x, y, z along the joint frame, then rpy
                base = self.free[joint.name]
                frame = translate(frame, tuple(sp.Symbol(f"{base}_{k}") for k in FREE_SLIDES))
                for k, axis in zip(reversed(FREE_TURNS), ((0, 0, 1), (0, 1, 0), (1, 0, 0)),
                                   strict=True):
                    frame = rotate(frame, axis, sp.Symbol(f"{base}_{k}"),
                                   sp.Symbol(f"{base}_{k}_dot"))
            elif joint.type in MOVABLE:
                axis = np.asarray(joint.axis if joint.axis is not None else (1, 0, 0), float)
                norm = float(np.linalg.norm(axis))
                if not math.isfinite(norm) or norm == 0:
                    raise self.error("the axis has zero length", f"joint '{joint.name}'.axis")
                axis = _vector(axis / norm)
                angle, rate = position(joint)
                if joint.type == "prismatic":
                    frame = translate(frame, tuple(angle * a for a in axis))
                else:
                    frame = rotate(frame, axis, angle, rate)
            frames[joint.child] = frame
            parents[joint.child] = joint.parent
            moves[joint.child] = moves[joint.parent] or joint.name in self.free or (
                joint.type in MOVABLE and bool(position(joint)[0].free_symbols))
        bodies = []
        for name, frame in frames.items():
            link = self.links[name]
            inertial = link.inertial
            if carries_nothing(inertial):
                continue
            mass, tensor, where = self._inertial(name, fixed=not moves[name])
            center = apply(frame.rotation, _vector(where[:3, 3]))
            position_ = tuple(o + c for o, c in zip(frame.origin, center, strict=True))
            if not moves[name]:
                continue  # fixed to the ground: no kinetic energy, a constant potential
            bodies.append(RigidBody(name, _number(mass), _matrix(0.5 * (tensor + tensor.T)),
                                    position_, frame.rotation, frame.origin,
                                    frame.angular_velocity, parents[name]))
        return bodies


    def _inertial(self, name: str, fixed: bool = False):
        """A link's mass (kg), inertia tensor about its centre of mass in link axes (kg m^2)
        and inertial origin (4 x 4), checked; ``fixed``: the link is welded to a fixed root,
        where an unphysical tensor changes no dynamics (TIAGo's antennas): a ModelWarning."""
        inertial = self.links[name].inertial
        field = f"link '{name}'.inertial"
        mass = float(inertial.mass or 0.0)
        tensor = np.asarray(inertial.inertia if inertial.inertia is not None
                            else np.zeros((3, 3)), dtype=float)
        if not math.isfinite(mass) or mass < 0:
            raise self.error(f"the mass {mass} is negative or not finite", field)
        if not np.all(np.isfinite(tensor)):
            raise self.error("the inertia tensor has an entry that is not finite", field)
        where = np.asarray(inertial.origin if inertial.origin is not None else np.eye(4),
                           dtype=float)
        turn = where[:3, :3]
        tensor = turn @ tensor @ turn.T  # about the centre of mass, in link axes
        if np.linalg.eigvalsh(0.5 * (tensor + tensor.T))[0] < -1e-12 * max(
                1.0, float(np.abs(tensor).max())):
            if not fixed:
                raise self.error("the inertia tensor is not positive semidefinite", field)
            warnings.warn(ModelWarning(
                f"{self.source}: {field}: the inertia tensor is not positive semidefinite; "
                "ignored, since the link is fixed to the root and changes no dynamics"),
                stacklevel=2)
        return mass, tensor, where

    def _lazy_bodies(self, root: str, order, position, tree: KinematicTree) -> LazyBodies:
        """The symbolic bodies of a large tree, built when first read (model/lazy_bodies.py),
        every check of _bodies made now."""
        for joint in order:
            if joint.type in MOVABLE:
                axis = np.asarray(joint.axis if joint.axis is not None else (1, 0, 0), float)
                norm = float(np.linalg.norm(axis))
                if not math.isfinite(norm) or norm == 0:
                    raise self.error("the axis has zero length", f"joint '{joint.name}'.axis")
        count = 0
        for link in tree.links:
            if not carries_nothing(self.links[link.name].inertial):
                self._inertial(link.name, fixed=link.body < 0)
                count += link.body >= 0
        return LazyBodies(lambda: self._bodies(root, order, position), count)


def _turned(frame: Frame, rotation) -> Frame:
    """The frame turned by a constant rotation (given in its own axes)."""
    return Frame(frame.origin, compose(frame.rotation, rotation),
                 apply_transpose(rotation, frame.angular_velocity), frame.singularities)



__all__ = ["SymbolicBodies"]
