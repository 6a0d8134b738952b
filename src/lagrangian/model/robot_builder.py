"""A robot's kinematic tree described in Python, as a URDF would describe it: links with their
inertials, joints between them, read into the same model a URDF gives (model/urdf.py), so every
backend moves it. Besides URDF's revolute, prismatic and fixed joints it has

- ``helical``: a screw about and along its axis u, theta (rad) turning the child and sliding it
  pitch * theta (m, pitch in m/rad) along u: S = (u, pitch u), Pinocchio's
  JointModelHelicalUnaligned; one coordinate named after the joint;
- ``universal``: two perpendicular axes u1 (``axis``) and u2 (``axis2``, in the joint's frame),
  R = Rot(u1, q1) Rot(u2, q2), Pinocchio's JointModelUniversal; expanded, as a URDF planar
  joint is, into the revolute joints ``<joint>_1`` (about u1) and ``<joint>_2`` (about u2)
  through a massless link ``<joint>_link``: coordinates ``<joint>_1``, ``<joint>_2`` (rad),
  rates their time derivatives; the joint's own name is its child link's frame.

A joint's origin is URDF's: ``xyz`` (m) and ``rpy`` (rad, R = Rz(yaw) Ry(pitch) Rx(roll)) of
the joint's frame in its parent link's; a link's inertial is its mass (kg), centre of mass
``com`` (m, link axes) and inertia tensor about the centre of mass (kg m^2, link axes: a 3 x 3
matrix or the principal moments (ixx, iyy, izz)). Gravity is g = 9.81 m/s^2 along -z; each
coordinate's actuator is tau_<coordinate> (N m or N), as for a URDF robot. Bad input is refused
in one line naming the link or joint and the field (ModelError).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
import sympy as sp

from ..errors import ModelError, did_you_mean
from .builder import ModelBuilder
from .lazy_bodies import LAZY_ABOVE, LazyBodies
from .model import Model
from .rotations import (
    GROUND,
    Frame,
    RigidBody,
    apply,
    apply_transpose,
    compose,
    rotate,
    translate,
)
from .urdf_tree import HELICAL, carries_nothing, numeric_tree

GRAVITY = 9.81  # m/s^2, along -z
KINDS = ("revolute", "prismatic", HELICAL, "universal", "fixed")
_MOVING = ("revolute", "prismatic", HELICAL)


@dataclass(frozen=True)
class _Inertial:  # what urdf_tree.numeric_tree reads of a link's inertial
    mass: float
    origin: np.ndarray  # 4 x 4: the centre of mass in link axes (the inertial's axes the link's)
    inertia: np.ndarray  # about the centre of mass, link axes (kg m^2)


@dataclass(frozen=True)
class _Link:
    name: str
    inertial: _Inertial | None


@dataclass(frozen=True)
class _Joint:  # a URDF joint's fields, and a helical joint's pitch (m/rad)
    name: str
    type: str
    parent: str
    child: str
    origin: np.ndarray  # 4 x 4: the joint's frame in its parent link's
    axis: np.ndarray
    pitch: float = 0.0
    limit: tuple[float, float] | None = None
    mimic: None = None


@dataclass(eq=False)
class RobotTree:
    """A robot's links and joints as given (``link``, ``joint``), read into a Model by
    ``build_model`` (the URDF reader's model, with its kinematic tree)."""

    name: str = "robot"
    links: dict[str, _Link] = field(default_factory=dict)
    joints: list[_Joint] = field(default_factory=list)

    def link(self, name: str, mass: float = 0.0, com: Sequence[float] = (0.0, 0.0, 0.0),
             inertia=((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))) -> RobotTree:
        """Add a link: ``mass`` (kg), centre of mass ``com`` (m, link axes), ``inertia`` about
        the centre of mass (kg m^2, link axes: 3 x 3, or principal (ixx, iyy, izz))."""
        where = f"link '{name}'"
        self._name(name, where)
        if name in self.links:
            raise ModelError(f"a second link named '{name}' (each link needs a name of its own)",
                             field=where)
        mass = _finite(mass, f"{where}.mass", ())
        if mass < 0:
            raise ModelError(f"the mass {mass:g} kg is negative", field=f"{where}.mass")
        com = _finite(com, f"{where}.com", (3,))
        tensor = np.asarray(_finite(inertia, f"{where}.inertia", None), dtype=float)
        if tensor.shape == (3,):
            tensor = np.diag(tensor)
        if tensor.shape != (3, 3):
            raise ModelError("an inertia is a 3 x 3 tensor or three principal moments (ixx, iyy, "
                             f"izz), not of shape {tensor.shape}", field=f"{where}.inertia")
        if not np.allclose(tensor, tensor.T, rtol=0.0, atol=1e-12 * max(1.0, abs(tensor).max())):
            raise ModelError("the inertia tensor is not symmetric", field=f"{where}.inertia")
        tensor = 0.5 * (tensor + tensor.T)
        if np.linalg.eigvalsh(tensor)[0] < -1e-12 * max(1.0, float(abs(tensor).max())):
            raise ModelError("the inertia tensor is not positive semidefinite",
                             field=f"{where}.inertia")
        origin = np.eye(4)
        origin[:3, 3] = com
        self.links[name] = _Link(name, _Inertial(mass, origin, tensor))
        return self

    def joint(self, name: str, kind: str, parent: str, child: str,
              xyz: Sequence[float] = (0.0, 0.0, 0.0), rpy: Sequence[float] = (0.0, 0.0, 0.0),
              axis: Sequence[float] = (0.0, 0.0, 1.0), pitch: float = 0.0,
              axis2: Sequence[float] | None = None,
              limits: tuple[float, float] | None = None) -> RobotTree:
        """Add a joint of ``kind`` (KINDS) from link ``parent`` to link ``child``, its frame at
        ``xyz`` (m), ``rpy`` (rad) in the parent's; ``axis`` (joint axes, made unit), a helical
        joint's ``pitch`` (m/rad), a universal joint's second axis ``axis2`` (perpendicular to
        ``axis``); ``limits`` (lower, upper) of its coordinate (rad or m; a universal joint's
        two coordinates each)."""
        where = f"joint '{name}'"
        self._name(name, where)
        if name in {j.name for j in self.joints} | {j.name for j in self._universal}:
            raise ModelError(f"a second joint named '{name}' (each joint needs a name of its "
                             "own)", field=where)
        if kind not in KINDS:
            raise ModelError(f"unknown joint kind {kind!r} (use {', '.join(KINDS)})"
                             f"{did_you_mean(str(kind), KINDS)}", field=f"{where}.kind")
        origin = np.eye(4)
        origin[:3, :3] = _rpy(_finite(rpy, f"{where}.rpy", (3,)))
        origin[:3, 3] = _finite(xyz, f"{where}.xyz", (3,))
        u = _unit(axis, f"{where}.axis")
        pitch = _finite(pitch, f"{where}.pitch", ())
        if pitch and kind != HELICAL:
            raise ModelError(f"a {kind} joint has no pitch (a helical joint's)",
                             field=f"{where}.pitch")
        if limits is not None:
            limits = tuple(_finite(limits, f"{where}.limits", (2,)))
            if not limits[0] < limits[1]:
                raise ModelError(f"the limits ({limits[0]:g}, {limits[1]:g}): lower must be "
                                 "below upper", field=f"{where}.limits")
        if kind != "universal":
            if axis2 is not None:
                raise ModelError(f"a {kind} joint has one axis (axis2 is a universal joint's)",
                                 field=f"{where}.axis2")
            self.joints.append(_Joint(name, kind, parent, child, origin, u, pitch, limits))
            return self
        if axis2 is None:
            raise ModelError("a universal joint needs its second axis, axis2",
                             field=f"{where}.axis2")
        u2 = _unit(axis2, f"{where}.axis2")
        if abs(float(u @ u2)) > 1e-12:
            raise ModelError(f"a universal joint's axes must be perpendicular (axis . axis2 = "
                             f"{float(u @ u2):.3g})", field=f"{where}.axis2")
        middle = f"{name}_link"
        while middle in self.links:
            middle += "_"
        for half in (f"{name}_1", f"{name}_2"):
            if half in {j.name for j in self.joints}:
                raise ModelError(f"joint '{half}' exists: a universal joint '{name}' expands "
                                 f"into joints '{name}_1' and '{name}_2'", field=where)
        self.links[middle] = _Link(middle, None)
        self.joints += [_Joint(f"{name}_1", "revolute", parent, middle, origin, u, 0.0, limits),
                        _Joint(f"{name}_2", "revolute", middle, child, np.eye(4), u2, 0.0,
                               limits)]
        self._universal.append(_Joint(name, "universal", parent, child, origin, u))
        return self

    def __post_init__(self):
        self._universal: list[_Joint] = []  # each universal joint as given (its frame's name)

    def __repr__(self) -> str:
        joints = [f"{j.name} ({j.type})" for j in self.joints]
        return (f"{type(self).__name__}({self.name!r}, links={list(self.links)}, "
                f"joints={joints})")

    def _name(self, name, where: str) -> None:
        if not isinstance(name, str) or not name:
            raise ModelError("a link or joint is named by a non-empty string", field=where)

    def _order(self) -> tuple[str, list[_Joint]]:
        """The root link and the joints from it down, depth first in the order given."""
        if not self.links:
            raise ModelError("a robot needs links (link(...)) and joints between them",
                             field="links")
        parent_of: dict[str, _Joint] = {}
        children: dict[str, list[_Joint]] = {}
        for joint in self.joints:
            where = f"joint '{joint.name}'"
            for role, link in (("parent", joint.parent), ("child", joint.child)):
                if link not in self.links:
                    raise ModelError(f"no link '{link}' for its {role}"
                                     f"{did_you_mean(str(link), list(self.links))}", field=where)
            if joint.child in parent_of:
                raise ModelError(f"link '{joint.child}' is the child of joints "
                                 f"'{parent_of[joint.child].name}' and '{joint.name}': a closed "
                                 "loop (a robot here is a tree)", field=where)
            parent_of[joint.child] = joint
            children.setdefault(joint.parent, []).append(joint)
        roots = [name for name in self.links if name not in parent_of]
        if len(roots) != 1:
            raise ModelError("every link is the child of a joint: a closed loop" if not roots else
                             f"the links form {len(roots)} separate trees (roots "
                             f"{', '.join(repr(r) for r in roots)}); a robot has one root link",
                             field="joints")
        order, stack = [], list(reversed(children.get(roots[0], [])))
        while stack:
            joint = stack.pop()
            order.append(joint)
            stack += list(reversed(children.get(joint.child, [])))
        if len(order) != len(self.joints):
            lost = next(j for j in self.joints if j not in order)
            raise ModelError(f"its links form a closed loop, unreachable from the root link "
                             f"'{roots[0]}'", field=f"joint '{lost.name}'")
        return roots[0], order

    def build_model(self, floating_base: bool = False) -> Model:
        """The robot as a model with its kinematic tree (as model/urdf.py reads a URDF), the
        root link fixed to the world unless ``floating_base`` (a free flyer carries it)."""
        from .urdf import identifier

        root, order = self._order()
        builder = ModelBuilder(self.name, f"Robot '{self.name}' built in Python "
                               f"({len(order)} joints, {len(self.links)} links).",
                               source="<RobotBuilder>")
        g = builder.parameter("g", GRAVITY, "m/s^2")
        builder.set_gravity(g, (0, 0, -1))
        names: dict[str, str] = {}
        taken = {"g"}
        for joint in order:
            if joint.type not in _MOVING:
                continue
            name = identifier(joint.name)
            while name in taken or f"tau_{name}" in taken:
                name += "_"
            taken |= {name, f"tau_{name}"}
            names[joint.name] = name
            unit = "m" if joint.type == "prismatic" else "rad"
            span = joint.limit
            initial = 0.0 if span is None or span[0] <= 0.0 <= span[1] else 0.5 * sum(span)
            field_ = f"joint '{joint.name}'"
            builder.coordinate(name, unit, initial=initial, rate=0.0, range=span, field=field_)
            tau = builder.parameter(f"tau_{name}", 0.0, "N" if unit == "m" else "N*m",
                                    field=field_)
            builder.add_generalized_force(name, tau, field=field_)
        if not names:
            raise ModelError("no joint to move: a robot needs at least one revolute, prismatic, "
                             "helical or universal joint", field="joints")
        symbols = {joint: (sp.Symbol(name), sp.Symbol(f"{name}_dot"))
                   for joint, name in names.items()}

        def position(joint):
            return symbols[joint.name]

        model = builder.build_model()
        moves = {root: False}
        for joint in order:
            moves[joint.child] = moves[joint.parent] or joint.type in _MOVING
        count = sum(moves[name] and not carries_nothing(link.inertial)
                    for name, link in self.links.items())
        if len(names) > LAZY_ABOVE:  # a long chain: its symbolic bodies when first asked for
            bodies = LazyBodies(lambda: _bodies(self.links, root, order, position), count)
        else:
            bodies = tuple(_bodies(self.links, root, order, position))
        tree = numeric_tree(self.links, root, order, position, names, bodies, floating_base)
        if self._universal:  # a universal joint's own name: its frame, its child link's
            by_link = {f.name: f for f in tree.frames}
            tree = replace(tree, frames=tree.frames + tuple(
                replace(by_link[j.child], name=j.name) for j in self._universal
                if j.name not in by_link))
        return replace(model, rigid_bodies=bodies, kinematic_tree=tree,
                       source_names=tuple((name, joint) for joint, name in names.items()),
                       source_ratings=tuple((name, None, None) for name in names.values()),
                       source_dynamics=tuple((name, 0.0, 0.0) for name in names.values()))


def _bodies(links, root: str, order, position) -> list[RigidBody]:
    """The moving links as symbolic rigid bodies (model/urdf.py's, with the helical screw)."""
    frames: dict[str, Frame] = {root: GROUND}
    parents: dict[str, str | None] = {root: None}
    moves = {root: False}  # fixed to the ground: no kinetic energy, a constant potential
    for joint in order:
        moves[joint.child] = moves[joint.parent] or joint.type in _MOVING
        frame = translate(frames[joint.parent], _vector(joint.origin[:3, 3]))
        turn = _matrix(joint.origin[:3, :3])
        frame = Frame(frame.origin, compose(frame.rotation, turn),
                      apply_transpose(turn, frame.angular_velocity), frame.singularities)
        if joint.type in _MOVING:
            axis = _vector(joint.axis)
            angle, rate = position(joint)
            if joint.type != "prismatic":
                frame = rotate(frame, axis, angle, rate)
            if joint.type != "revolute":  # along the axis (unmoved by a turn about it)
                lead = angle if joint.type == "prismatic" else _number(joint.pitch) * angle
                frame = translate(frame, tuple(lead * a for a in axis))
        frames[joint.child] = frame
        parents[joint.child] = joint.parent
    bodies = []
    for name, frame in frames.items():
        inertial = links[name].inertial
        if not moves[name] or carries_nothing(inertial):
            continue
        center = apply(frame.rotation, _vector(inertial.origin[:3, 3]))
        bodies.append(RigidBody(name, _number(inertial.mass), _matrix(inertial.inertia),
                                tuple(o + c for o, c in zip(frame.origin, center, strict=True)),
                                frame.rotation, frame.origin, frame.angular_velocity,
                                parents[name]))
    return bodies


def _finite(value, where: str, shape):
    """``value`` as finite float(s) of ``shape`` (None: any), else one line naming ``where``."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"not a number: {value!r}", field=where) from None
    if shape is not None and array.shape != shape:
        what = "a number" if shape == () else f"{shape[0]} numbers"
        raise ModelError(f"expected {what}, got {value!r}", field=where)
    if not np.all(np.isfinite(array)):
        raise ModelError("a number that is not finite", field=where)
    return float(array) if shape == () else array


def _unit(axis, where: str) -> np.ndarray:
    u = _finite(axis, where, (3,))
    norm = float(np.linalg.norm(u))
    if norm == 0.0:
        raise ModelError("the axis has zero length", field=where)
    return u / norm


def _rpy(angles) -> np.ndarray:
    """URDF's rpy: Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = (float(a) for a in angles)
    cr, sr, cp, sp_, cy, sy = (math.cos(r), math.sin(r), math.cos(p), math.sin(p),
                               math.cos(y), math.sin(y))
    return np.array([[cy * cp, cy * sp_ * sr - sy * cr, cy * sp_ * cr + sy * sr],
                     [sy * cp, sy * sp_ * sr + cy * cr, sy * sp_ * cr - cy * sr],
                     [-sp_, cp * sr, cp * cr]])


def _number(x: float) -> sp.Expr:
    from .urdf import _number as number  # the URDF reader's exact short decimals

    return number(x)


def _vector(a) -> tuple:
    return tuple(_number(v) for v in np.asarray(a, dtype=float))


def _matrix(a) -> tuple:
    return tuple(tuple(_number(v) for v in row) for row in np.asarray(a, dtype=float))


__all__ = ["KINDS", "RobotTree"]
