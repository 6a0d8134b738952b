"""Robots from MuJoCo's MJCF: bodies, hinge and slide joints, inertials (diaginertia or
fullinertia, or inferred from geoms by MuJoCo's rules), default classes and the compiler's angle
and eulerseq, read into the same robot description as a URDF (model/urdf.py). The body tree is
written as the URDF it is, with our own numbers and names (a body's link frame sits at its
joint's anchor, several joints in one body chain through massless links), and read by the URDF
reader, so an MJCF robot enters the same engine. Each joint is a coordinate in MuJoCo's qpos
order (depth first in document order) with MuJoCo's sign and zero, so a state moves between
MuJoCo and us unchanged; a ball joint is the tree's spherical joint, its quaternion w x y z and
angular velocity in the child's axes as MuJoCo's (model/mjcf_ball.py); a free joint is three
slides along the world's axes and a ball, MuJoCo's layout exactly (model/mjcf_free.py), or with
``floating_base`` the tree's free flyer (Pinocchio's layout: model/mjcf_state.py converts). A
joint equality with a linear polycoef is a mimic joint (model/mjcf_equality.py). A joint's
damping, frictionloss and armature are kept (Model.source_dynamics, source_armature) for
dynamics(actuators=True). What would change the dynamics and is not modelled (tendons, other
equalities, actuators with dynamics, a joint's ref or stiffness, ...) is refused in one line
naming the file, element and fault.
Units SI (MJCF's lengths in m, masses in kg; angles by the compiler, degrees by default).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ElementTree
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..errors import ModelError, did_you_mean, require_extra
from ..kinds import JointKind
from .mjcf_ball import ball_joint, with_ball_joints
from .mjcf_equality import check_mimics, folded_losses, read_equalities
from .mjcf_free import free_joint, with_free_joints
from .mjcf_geometry import (
    DENSITY,
    axis_angle_matrix,
    check_geom,
    combined_inertia,
    euler_matrix,
    geom_volume_and_inertia,
    quaternion_matrix,
    rpy,
    xy_axes_matrix,
    z_axis_matrix,
)
from .model import Model
from .reader import read_text_file

MAX_MJCF_NUMBER = 1e30  # as a URDF's numbers (model/urdf.py)
# Elements that change the dynamics and are not modelled here: refused by name.
REFUSED = {"tendon": "tendons", "include": "<include> of "
           "other files", "flexcomp": "flexes", "deformable": "deformables",
           "composite": "composites", "replicate": "<replicate>", "attach": "<attach>",
           "plugin": "plugins"}
# What a <frame> may hold: bodies (turned and moved by it) and elements without mass.
FRAME_CONTENT = ("body", "frame", "site", "camera", "light")
JOINT_KINDS = ("hinge", "slide")
# Actuators whose own state (activation) would enter the dynamics.
ACTUATOR_DYNAMICS = ("cylinder", "muscle", "intvelocity", "adhesion")


def read_mjcf(path, lock: Mapping[str, float] | None = None,
              payload: Mapping[str, object] | None = None, floating_base: bool = False) -> Model:
    """Load a MuJoCo MJCF file as a robot model (the URDF reader's ``lock``, ``payload`` and
    ``floating_base`` take the MJCF's joint and body names)."""
    return parse_mjcf(read_text_file(path), source=str(path), lock=lock, payload=payload,
                      floating_base=floating_base)


def parse_mjcf(text: str, *, source: str = "<mjcf>", lock: Mapping[str, float] | None = None,
               payload: Mapping[str, object] | None = None,
               floating_base: bool = False) -> Model:
    """The model of an MJCF document (module docstring): its bodies and joints as a URDF read
    by model/urdf.py, under the document's <option gravity>."""
    from .gravity import with_gravity
    from .urdf import parse_urdf

    root = _root(text, source)
    if root.tag == "robot":  # a URDF saved as .xml: read as one
        return parse_urdf(text, source=source, lock=lock, payload=payload,
                          floating_base=floating_base)
    reader = _Reader(root, source)
    reader.floating = bool(floating_base)
    urdf = reader.urdf()
    slides = {s: free for free, three in reader.slides.items() for s in three}
    locked = [name for name in (lock or {}) if name in reader.slides or name in slides]
    if locked:
        raise ModelError(f"the free joint '{slides.get(locked[0], locked[0])}' cannot be "
                         "locked (yet)", field=f"lock.{locked[0]}", source=source)
    locked = [name for name in (lock or {}) if name in reader.balls]
    if locked:
        raise ModelError(f"the ball joint '{locked[0]}' cannot be locked (yet)",
                         field=f"lock.{locked[0]}", source=source)
    model = parse_urdf(urdf, source=source, lock=lock, payload=payload,
                       floating_base=bool(floating_base) and reader.free is None)
    joints = len(reader.joint_names) + len(reader.balls)
    if reader.balls:  # the tree's ball joints in MuJoCo's layout (mjcf_ball.py)
        model = with_ball_joints(model, reader.balls, source)
    model = with_free_joints(model, reader.slides)  # MuJoCo's layout (mjcf_free.py)
    coordinate = {joint: name for name, joint in model.source_names}  # locked: none
    model = replace(model, description=f"Robot '{model.name}' read from MJCF ({joints} joints, "
                                       f"{reader.bodies} bodies).",
                    source_armature=tuple((coordinate[joint], value) for joint, value
                                          in reader.armature.items() if joint in coordinate))
    gravity = reader.gravity
    if not np.allclose(gravity, (0.0, 0.0, -9.81), rtol=0, atol=0):
        model = with_gravity(model, tuple(gravity), field="option.gravity")
    return model


def _root(text: str, source: str):
    """The <mujoco> element, parsed with no entity, DTD or network (as the URDF reader)."""
    require_extra("urdf", ("lxml", "yourdfpy"), "reading an MJCF robot")
    from lxml import etree

    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False,
                             huge_tree=False, remove_comments=True, remove_pis=True)
    try:
        root = etree.fromstring(text.encode("utf-8"), parser)
    except etree.XMLSyntaxError as exc:
        raise ModelError(f"not well-formed XML ({exc})", source=source) from None
    if root.getroottree().docinfo.doctype:
        raise ModelError("a <!DOCTYPE> (an MJCF file needs none; entities are not read)",
                         source=source)
    if root.tag not in ("mujoco", "robot"):
        raise ModelError(f"the root element is <{root.tag}>, not <mujoco> (MJCF) or <robot> "
                         "(URDF): not a robot description", source=source)
    return root


def _children(element, tag: str | None = None):
    return [c for c in element if isinstance(c.tag, str) and (tag is None or c.tag == tag)]


class _Reader:
    """One MJCF document: its compiler settings, default classes and body tree."""

    def __init__(self, root, source: str):
        self.source = source
        self.root = root
        self.name = root.get("model") or Path(source).stem or "MJCF robot"
        for element in root.iter():
            if isinstance(element.tag, str) and element.tag in REFUSED and (
                    element.tag != "tendon" or _children(element)):
                raise self.error(f"{REFUSED[element.tag]} are not supported (yet)",
                                 f"<{element.tag}>")
        for frame in root.iter("frame"):
            held = [c.tag for c in _children(frame) if c.tag not in FRAME_CONTENT]
            if held:
                raise self.error(f"a <{held[0]}> in a <frame> is not supported (yet): only "
                                 "bodies", "<frame>")
        self.angle, self.sequence, self.from_geoms = self._compiler()
        self.gravity = self._gravity()
        self.defaults = self._defaults()
        self._check_actuators()
        self.mimics = read_equalities(self)  # joint1 -> (joint2, c0, c1)
        # per hinge or slide joint: (damping, frictionloss, armature), and its URDF element
        self.losses: dict[str, tuple[float, float, float]] = {}
        self.elements: dict[str, object] = {}
        self.joint_names: list[str] = []
        self.balls: dict[str, tuple[str, str, str]] = {}  # a ball joint's three URDF hinges
        self.floating = False  # floating_base asked for: a free joint is the free flyer
        self.free: str | None = None  # that free joint's name, once read
        # a free joint in MuJoCo's layout: its three slides (mjcf_free.py); its ball in balls
        self.slides: dict[str, tuple[str, str, str]] = {}
        self.link_names: set[str] = {"world"}
        self.bodies = 0

    def named(self, name: str) -> bool:
        """Whether a joint (or a free joint's slide) of this name is read already."""
        return name in self.joint_names or name in self.balls or any(
            name in slides for slides in self.slides.values())

    def error(self, message: str, field: str | None = None) -> ModelError:
        return ModelError(message, field=field, source=self.source)

    # -- numbers ----------------------------------------------------------------------------

    def numbers(self, text: str | None, count: int | None, where: str) -> list[float]:
        if text is None:
            return []
        try:
            values = [float(v) for v in text.split()]
        except ValueError:
            raise self.error(f"{text.strip()[:40]!r} is not a list of numbers", where) from None
        if count is not None and len(values) != count:
            raise self.error(f"expected {count} numbers, got {len(values)}", where)
        for v in values:
            if not math.isfinite(v) or abs(v) >= MAX_MJCF_NUMBER:
                raise self.error(f"the number {v:g} is not finite or too large (below "
                                 f"{MAX_MJCF_NUMBER:g})", where)
        return values

    def vector(self, attrs, key: str, default, where: str) -> np.ndarray:
        text = attrs.get(key)
        return np.array(default, float) if text is None else \
            np.array(self.numbers(text, len(default), f"{where}.{key}"))

    def orientation(self, attrs, where: str) -> np.ndarray:
        """R of the element's one orientation attribute (identity without one)."""
        given = [k for k in ("quat", "axisangle", "euler", "xyaxes", "zaxis") if k in attrs]
        if len(given) > 1:
            raise self.error(f"two orientations ({' and '.join(given)}): give one", where)
        if not given:
            return np.eye(3)
        key = given[0]
        field = f"{where}.{key}"
        count = {"quat": 4, "axisangle": 4, "euler": 3, "xyaxes": 6, "zaxis": 3}[key]
        v = self.numbers(attrs[key], count, field)
        try:
            if key == "quat":
                return quaternion_matrix(*v)
            if key == "axisangle":
                return axis_angle_matrix(v[:3], v[3] * self.angle)
            if key == "euler":
                return euler_matrix([a * self.angle for a in v], self.sequence)
            return xy_axes_matrix(v) if key == "xyaxes" else z_axis_matrix(v)
        except ValueError as exc:
            raise self.error(str(exc), field) from None

    # -- the document's settings ------------------------------------------------------------

    def _compiler(self):
        settings: dict[str, str] = {}
        for compiler in self.root.iter("compiler"):
            settings.update(compiler.attrib)
        angle = settings.get("angle", "degree")
        if angle not in ("degree", "radian"):
            raise self.error(f"angle {angle!r} is neither degree nor radian", "compiler.angle")
        sequence = settings.get("eulerseq", "xyz")
        if len(sequence) != 3 or any(c not in "xyzXYZ" for c in sequence):
            raise self.error(f"eulerseq {sequence!r} is not three of x, y, z, X, Y, Z",
                             "compiler.eulerseq")
        from_geoms = settings.get("inertiafromgeom", "auto")
        if from_geoms not in ("auto", "true", "false"):
            raise self.error(f"inertiafromgeom {from_geoms!r} is not auto, true or false",
                             "compiler.inertiafromgeom")
        for key in ("coordinate", "settotalmass", "balanceinertia", "boundmass",
                    "boundinertia", "fusestatic", "alignfree"):
            value = settings.get(key)
            if value not in (None, "local", "-1", "false", "0", "0.0"):
                raise self.error(f"{key}={value!r} is not supported (yet)", f"compiler.{key}")
        group = self.numbers(settings.get("inertiagrouprange", "0 5"), 2,
                             "compiler.inertiagrouprange")
        self.groups = (int(group[0]), int(group[1]))
        self.autolimits = settings.get("autolimits", "true") == "true"
        return (math.pi / 180 if angle == "degree" else 1.0), sequence, from_geoms

    def _gravity(self) -> np.ndarray:
        gravity = np.array([0.0, 0.0, -9.81])
        for option in self.root.iter("option"):
            gravity = self.vector(option.attrib, "gravity", gravity, "option")
        return gravity

    def _defaults(self) -> dict[str, dict[str, dict[str, str]]]:
        """class name -> element tag -> attributes, each class over its parent's."""
        classes: dict[str, dict[str, dict[str, str]]] = {}

        def walk(element, name: str, inherited):
            own = {tag: dict(attrs) for tag, attrs in inherited.items()}
            for child in _children(element):
                if child.tag != "default":
                    own.setdefault(child.tag, {}).update(child.attrib)
            if name in classes:
                raise self.error(f"two default classes are named '{name}'", "default")
            classes[name] = own
            for child in _children(element, "default"):
                walk(child, child.get("class") or "", own)

        tops = _children(self.root, "default")
        if len(tops) > 1:
            raise self.error("more than one top-level <default>", "default")
        classes["main"] = {}
        if tops:
            del classes["main"]
            walk(tops[0], tops[0].get("class") or "main", {})
        return classes

    def attrs(self, element, childclass: str, where: str) -> dict[str, str]:
        """The element's attributes over its class's defaults (its class, else the enclosing
        childclass, else main)."""
        name = element.get("class") or childclass
        if name not in self.defaults:
            raise self.error(f"no default class '{name}'{did_you_mean(name, self.defaults)}",
                             f"{where}.class")
        merged = dict(self.defaults[name].get(element.tag, {}))
        merged.update(element.attrib)
        return merged

    def _check_actuators(self) -> None:
        for section in self.root.iter("actuator"):
            for actuator in _children(section):
                where = f"actuator '{actuator.get('name') or actuator.tag}'"
                attrs = self.attrs(actuator, "main", where)
                dynamic = actuator.tag in ACTUATOR_DYNAMICS or attrs.get(
                    "dyntype", "none") != "none" or float(attrs.get("timeconst", 0) or 0) > 0
                if dynamic:
                    raise self.error("an actuator with dynamics of its own (an activation "
                                     "state) is not supported (yet)", where)

    # -- the body tree as a URDF ------------------------------------------------------------

    def urdf(self) -> str:
        """The body tree as URDF text (our own names and numbers, escaped by ElementTree)."""
        worlds = _children(self.root, "worldbody")
        if len(worlds) != 1:
            raise self.error(f"{len(worlds)} <worldbody> elements: an MJCF model has one",
                             "worldbody")
        robot = ElementTree.Element("robot", name=self.name)
        ElementTree.SubElement(robot, "link", name="world")
        self.robot = robot
        for body, offset, childclass in self._child_bodies(worlds[0], np.eye(4), "main"):
            self._body(body, "world", offset, childclass)
        for child in _children(worlds[0]):
            if child.tag == "joint" or child.tag == "freejoint":
                raise self.error("the world body cannot have joints", f"worldbody.{child.tag}")
        if not self.joint_names and self.free is None and not self.balls:
            raise self.error("no hinge, slide or ball joint: nothing moves", "worldbody")
        check_mimics(self, self.mimics, self.joint_names, {*self.slides, self.free} - {None})
        for name, (joint2, c0, c1) in self.mimics.items():
            ElementTree.SubElement(self.elements[name], "mimic", joint=joint2,
                                   multiplier=repr(float(c1)), offset=repr(float(c0)))
        self.armature = {}
        for name, (damping, friction, armature) in folded_losses(self, self.mimics,
                                                                 self.losses).items():
            if damping or friction:
                ElementTree.SubElement(self.elements[name], "dynamics", damping=repr(damping),
                                       friction=repr(friction))
            if armature:
                self.armature[name] = armature
        return ElementTree.tostring(robot, encoding="unicode")

    def _fresh_link(self, name: str) -> str:
        while name in self.link_names:
            name += "_"
        self.link_names.add(name)
        return name

    def _body(self, body, parent: str, offset: np.ndarray, childclass: str) -> None:
        """One body: its joints (links at their anchors), its inertial, then its children.
        ``offset`` is the parent body's frame in its link's frame (4 x 4)."""
        self.bodies += 1
        name = body.get("name") or f"body{self.bodies}"
        where = f"body '{name}'"
        childclass = body.get("childclass") or childclass
        if childclass not in self.defaults:
            raise self.error(f"no default class '{childclass}'"
                             f"{did_you_mean(childclass, self.defaults)}", f"{where}.childclass")
        attrs = dict(body.attrib)
        for key, bad in (("mocap", "true"),):
            if attrs.get(key) == bad:
                raise self.error("a mocap body is not supported (yet)", where)
        if float(attrs.get("gravcomp", 0) or 0) != 0:
            raise self.error("gravcomp is not supported (yet)", f"{where}.gravcomp")
        current = offset @ _transform(self.orientation(attrs, where),
                                      self.vector(attrs, "pos", (0, 0, 0), where))
        link = parent
        joints = [c for c in _children(body) if c.tag in ("joint", "freejoint")]
        for k, joint in enumerate(joints):
            link, current = self._joint(joint, k, name, link, current, childclass, where,
                                        last=k == len(joints) - 1)
        if not joints:  # welded to its parent
            link = self._fresh_link(name)
            self._urdf_joint(f"{name}_weld", "fixed", parent, link, current)
            current = np.eye(4)
        self._inertial(body, link, current, childclass, where)
        for child, offset, inner in self._child_bodies(body, current, childclass):
            self._body(child, link, offset, inner)

    def _child_bodies(self, element, offset: np.ndarray, childclass: str):
        """The element's child bodies, each with its parent's frame turned by the <frame>s
        around it (4 x 4) and its childclass."""
        for child in _children(element):
            if child.tag == "body":
                yield child, offset, childclass
            elif child.tag == "frame":
                attrs = self.attrs(child, childclass, "frame")
                turned = offset @ _transform(self.orientation(attrs, "frame"),
                                             self.vector(attrs, "pos", (0, 0, 0), "frame"))
                yield from self._child_bodies(child, turned, child.get("childclass") or
                                              childclass)

    def _joint(self, joint, k: int, body: str, parent: str, current: np.ndarray,
               childclass: str, where: str, last: bool):
        if joint.tag == "freejoint":
            kind = "free"
        else:
            kind = None
        name = joint.get("name") or f"{body}_joint{k}" if joint.tag == "joint" else \
            joint.get("name") or f"{body}_free"
        field = f"{where}.joint '{name}'"
        attrs = self.attrs(joint, childclass, field) if joint.tag == "joint" else \
            dict(joint.attrib)
        kind = kind or attrs.get("type", "hinge")
        if kind == JointKind.FREE:
            return free_joint(self, name, body, parent, field, attrs, only=len(
                [c for c in _children(joint.getparent()) if c.tag in ("joint", "freejoint")]
            ) == 1)
        if kind == "ball":
            return ball_joint(self, name, body, parent, current, field, attrs, last)
        if kind not in JOINT_KINDS:
            raise self.error(f"unknown joint type {kind!r} (hinge, slide, ball or free)"
                             f"{did_you_mean(kind, JOINT_KINDS)}", f"{field}.type")
        losses = [self.numbers(attrs.get(key, "0"), 1, f"{field}.{key}")[0]
                  for key in ("damping", "frictionloss", "armature")]
        for key, value in zip(("damping", "frictionloss", "armature"), losses, strict=True):
            if value < 0:
                raise self.error(f"{key} {value:g} is negative", f"{field}.{key}")
        for key in ("ref", "stiffness", "springref"):
            if float(self.numbers(attrs.get(key, "0"), 1, f"{field}.{key}")[0]) != 0:
                raise self.error(f"{key} other than 0 is not supported (yet)", f"{field}.{key}")
        if attrs.get("springdamper"):
            raise self.error("springdamper is not supported (yet)", f"{field}.springdamper")
        if self.named(name):
            raise self.error(f"two joints are named '{name}'", field)
        self.joint_names.append(name)
        axis = self.vector(attrs, "axis", (0, 0, 1), field)
        if float(np.linalg.norm(axis)) < 1e-12:
            raise self.error("the axis has zero length", f"{field}.axis")
        anchor = self.vector(attrs, "pos", (0, 0, 0), field)
        link = self._fresh_link(body if last else f"{body}_{name}")
        scale = self.angle if kind == "hinge" else 1.0
        limit = self._limit(attrs, field, scale)
        urdf_kind = "prismatic" if kind == "slide" else (
            "revolute" if limit is not None else "continuous")
        origin = current @ _transform(np.eye(3), anchor) if kind == "hinge" else current
        self.elements[name] = self._urdf_joint(name, urdf_kind, parent, link, origin, axis,
                                               limit)
        self.losses[name] = (float(losses[0]), float(losses[1]), float(losses[2]))
        return link, (_transform(np.eye(3), -anchor) if kind == "hinge" else np.eye(4))

    def _limit(self, attrs, field: str, scale: float):
        limited = attrs.get("limited", "auto")
        if limited not in ("auto", "true", "false"):
            raise self.error(f"limited={limited!r} is not auto, true or false",
                             f"{field}.limited")
        span = self.numbers(attrs.get("range"), 2, f"{field}.range") if "range" in attrs \
            else None
        on = limited == "true" or (limited == "auto" and self.autolimits and span is not None)
        if not on or span is None:
            return None
        if not span[0] < span[1]:
            raise self.error(f"the range {span[0]:g} {span[1]:g} is empty (lower below upper)",
                             f"{field}.range")
        return span[0] * scale, span[1] * scale

    def _urdf_joint(self, name: str, kind: str, parent: str, child: str, origin: np.ndarray,
                    axis=None, limit=None):
        joint = ElementTree.SubElement(self.robot, "joint", name=name, type=kind)
        ElementTree.SubElement(joint, "parent", link=parent)
        ElementTree.SubElement(joint, "child", link=child)
        ElementTree.SubElement(joint, "origin", xyz=_text(origin[:3, 3]),
                               rpy=_text(rpy(origin[:3, :3])))
        if axis is not None:
            ElementTree.SubElement(joint, "axis", xyz=_text(axis / np.linalg.norm(axis)))
        if limit is not None:
            ElementTree.SubElement(joint, "limit", lower=repr(float(limit[0])),
                                   upper=repr(float(limit[1])), effort="0", velocity="0")
        ElementTree.SubElement(self.robot, "link", name=child)
        return joint

    def _inertial(self, body, link: str, current: np.ndarray, childclass: str,
                  where: str) -> None:
        """The body's mass and inertia, in its link's frame (``current``: the body's frame
        there): its <inertial>, or its geoms' by MuJoCo's rules."""
        inertials = _children(body, "inertial")
        if len(inertials) > 1:
            raise self.error("two <inertial> elements", where)
        if inertials and self.from_geoms != "true":
            mass, center, tensor = self._given_inertial(inertials[0], f"{where}.inertial")
        elif self.from_geoms != "false":
            mass, center, tensor = self._geom_inertia(body, childclass, where)
        else:
            mass, center, tensor = 0.0, np.zeros(3), np.zeros((3, 3))
        if mass == 0 and not np.any(tensor):
            return
        R = current[:3, :3]
        element = next(e for e in self.robot.iter("link") if e.get("name") == link)
        inertial = ElementTree.SubElement(element, "inertial")
        ElementTree.SubElement(inertial, "origin", xyz=_text(current[:3, :3] @ center
                                                             + current[:3, 3]), rpy="0 0 0")
        ElementTree.SubElement(inertial, "mass", value=repr(float(mass)))
        I = R @ tensor @ R.T
        ElementTree.SubElement(inertial, "inertia", **{
            key: repr(float(I[i, j])) for key, (i, j) in (
                ("ixx", (0, 0)), ("ixy", (0, 1)), ("ixz", (0, 2)), ("iyy", (1, 1)),
                ("iyz", (1, 2)), ("izz", (2, 2)))})

    def _given_inertial(self, element, where: str):
        attrs = dict(element.attrib)
        if "mass" not in attrs or "pos" not in attrs:
            raise self.error("an <inertial> needs mass and pos", where)
        mass = self.numbers(attrs["mass"], 1, f"{where}.mass")[0]
        if mass < 0:
            raise self.error(f"the mass {mass:g} is negative", f"{where}.mass")
        center = self.vector(attrs, "pos", (0, 0, 0), where)
        R = self.orientation(attrs, where)
        if "fullinertia" in attrs:
            if "diaginertia" in attrs:
                raise self.error("both diaginertia and fullinertia: give one", where)
            if any(k in attrs for k in ("quat", "axisangle", "euler", "xyaxes", "zaxis")):
                raise self.error("fullinertia with an orientation (the tensor is in the body's "
                                 "axes: give one or the other, as MuJoCo)", where)
            xx, yy, zz, xy, xz, yz = self.numbers(attrs["fullinertia"], 6,
                                                  f"{where}.fullinertia")
            principal = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
        elif "diaginertia" in attrs:
            principal = np.diag(self.numbers(attrs["diaginertia"], 3, f"{where}.diaginertia"))
        else:
            raise self.error("an <inertial> needs diaginertia or fullinertia", where)
        return mass, center, R @ principal @ R.T

    def _geom_inertia(self, body, childclass: str, where: str):
        parts = []
        for k, geom in enumerate(_children(body, "geom")):
            field = f"{where}.geom '{geom.get('name') or k}'"
            attrs = self.attrs(geom, childclass, field)
            group = int(self.numbers(attrs.get("group", "0"), 1, f"{field}.group")[0])
            if not self.groups[0] <= group <= self.groups[1]:
                continue
            if attrs.get("shellinertia", "false") == "true":
                raise self.error("shellinertia is not supported (yet)", field)
            kind = attrs.get("type", "sphere")
            size = self.numbers(attrs.get("size", ""), None, f"{field}.size")
            center = self.vector(attrs, "pos", (0, 0, 0), field)
            R = self.orientation(attrs, field)
            if "fromto" in attrs:
                a, b = np.split(np.array(self.numbers(attrs["fromto"], 6,
                                                      f"{field}.fromto")), 2)
                half = float(np.linalg.norm(b - a)) / 2
                if half < 1e-12:
                    raise self.error("fromto's two points coincide", f"{field}.fromto")
                if kind in ("capsule", "cylinder"):
                    size = [size[0] if size else 0.0, half]
                elif kind in ("box", "ellipsoid") and len(size) >= 2:
                    size = [size[0], size[1], half]
                center, R = (a + b) / 2, z_axis_matrix(b - a)
            check_geom(kind, size, field, self.source)
            volume, principal = geom_volume_and_inertia(kind, size)
            if "mass" in attrs:
                mass = self.numbers(attrs["mass"], 1, f"{field}.mass")[0]
                density = mass / volume
            else:
                density = self.numbers(attrs.get("density", repr(DENSITY)), 1,
                                       f"{field}.density")[0]
            if density < 0:
                raise self.error("a negative mass or density", field)
            parts.append((density * volume, center, R, density * principal))
        return combined_inertia(parts)


def _transform(R: np.ndarray, p) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, p
    return T


def _text(values) -> str:
    return " ".join(repr(float(v)) for v in values)


__all__ = ["parse_mjcf", "read_mjcf"]
