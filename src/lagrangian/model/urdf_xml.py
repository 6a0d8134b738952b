"""A URDF document read into plain records: the robot's links (inertials) and joints (type,
parent, child, origin, axis, limit, mimic), with the defaults of the URDF specification (an
absent origin is the identity, an absent axis is x, a mimic's multiplier 1 and offset 0).

Read with the standard library's expat parser, entities refused: an entity declaration, an
external entity or DTD, or a reference to an undeclared entity is an error, never expanded or
fetched (as defusedxml does), so a file cannot grow a billion laughs or read another. Visual,
collision, material, transmission and gazebo elements are skipped unread: meshes are never
loaded. An origin's rpy is roll about x, pitch about y, yaw about z, fixed axes:
R = Rz(yaw) Ry(pitch) Rx(roll), as urdfdom, Pinocchio and yourdfpy read it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from xml.etree.ElementTree import Element, TreeBuilder

import numpy as np

from ..errors import ModelError


@dataclass
class Inertial:
    origin: np.ndarray | None  # 4 x 4, the centre of mass frame in the link's
    mass: float | None  # kg
    inertia: np.ndarray | None  # 3 x 3, kg m^2, about the centre of mass


@dataclass
class Link:
    name: str
    inertial: Inertial | None


@dataclass
class Limit:
    lower: float | None  # rad or m
    upper: float | None


@dataclass
class Mimic:
    joint: str | None
    multiplier: float
    offset: float


@dataclass
class Joint:
    name: str
    type: str | None
    parent: str
    child: str
    origin: np.ndarray | None  # 4 x 4, the child's frame in the parent's at angle 0
    axis: np.ndarray  # unit vector in the joint frame (normalized by the reader of the tree)
    limit: Limit | None
    mimic: Mimic | None


@dataclass
class Robot:
    name: str
    links: list[Link] = field(default_factory=list)
    joints: list[Joint] = field(default_factory=list)


class _Refused(Exception):
    """An entity, raised from expat's handlers and turned into a ModelError."""


def parse_robot(text: str, source: str) -> Robot:
    """The robot of a URDF document, or a ModelError naming the element and the fault."""
    root = _elements(text, source)
    if root.tag != "robot":
        raise ModelError(f"the root element is <{root.tag}>, not <robot> (not a URDF robot)",
                         source=source)
    reader = _Reader(source)
    for kind in ("link", "joint"):  # named before any fault is named with them
        for element in root.findall(kind):
            reader.name(element, kind)
    _check_inertials(root, source)
    robot = Robot(reader.name(root, "robot"))
    robot.links = [reader.link(element) for element in root.findall("link")]
    robot.joints = [reader.joint(element) for element in root.findall("joint")]
    return robot


def _elements(text: str, source: str) -> Element:
    import xml.parsers.expat as expat

    def refuse(what):
        def handler(*_):
            raise _Refused(f"{what}: a URDF is read without entities (none is expanded or "
                           "fetched); write the text itself")
        return handler

    builder = TreeBuilder()
    parser = expat.ParserCreate()
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    parser.EntityDeclHandler = refuse("an entity declaration (<!ENTITY ...>)")
    parser.UnparsedEntityDeclHandler = refuse("an entity declaration (<!ENTITY ...>)")
    parser.ExternalEntityRefHandler = refuse("an external entity")
    parser.SkippedEntityHandler = refuse("an entity reference that is not declared")

    def doctype(name, system_id, public_id, internal_subset):
        if system_id or public_id:  # unread, its entities would silently vanish from attributes
            refuse("an external DTD (<!DOCTYPE ... SYSTEM ...>)")()

    parser.StartDoctypeDeclHandler = doctype
    parser.StartElementHandler = builder.start
    parser.EndElementHandler = builder.end
    parser.CharacterDataHandler = builder.data
    try:
        parser.Parse(text, True)  # a str: read as the Unicode it is, whatever the header says
        return builder.close()
    except _Refused as exc:
        raise ModelError(str(exc), source=source) from None
    except (expat.ExpatError, AssertionError) as exc:  # TreeBuilder asserts a closed root
        raise ModelError(f"not well-formed XML ({exc or 'no element'})", source=source) from None


_MOMENTS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def _check_inertials(root: Element, source: str) -> None:
    """Each link's inertial has its mass and all six moments, as urdfdom requires (a missing
    mass read as 0, or a missing moment as 1 kg m^2, would be a different robot)."""
    for link in root.findall("link"):
        inertial = link.find("inertial")
        if inertial is None:
            continue
        where = f"link '{link.get('name')}'.inertial"
        mass = inertial.find("mass")
        if mass is None:
            raise ModelError("no <mass> element (an inertial needs <mass value=\"...\"/>)",
                             field=f"{where}.mass", source=source)
        if mass.get("value") is None:
            raise ModelError("no value (write <mass value=\"...\"/>)", field=f"{where}.mass",
                             source=source)
        inertia = inertial.find("inertia")
        if inertia is None:
            raise ModelError("no <inertia> element (an inertial needs ixx, ixy, ixz, iyy, iyz "
                             "and izz)", field=f"{where}.inertia", source=source)
        missing = [key for key in _MOMENTS if inertia.get(key) is None]
        if missing:
            raise ModelError(f"no {', '.join(missing)} (an inertia needs all six of "
                             f"{', '.join(_MOMENTS)})", field=f"{where}.inertia", source=source)


class _Reader:
    def __init__(self, source: str):
        self.source = source

    def error(self, message: str, field: str) -> ModelError:
        return ModelError(message, field=field, source=self.source)

    def name(self, element: Element, kind: str) -> str:
        name = element.get("name")
        if name is None:
            raise self.error(f"a <{kind}> without a name (write <{kind} name=\"...\">)", kind)
        return name

    def numbers(self, element: Element, key: str, default: str, count: int,
                where: str) -> list[float]:
        text = element.get(key, default)
        try:
            values = [float(part) for part in text.split()]
        except ValueError:
            values = []
        if len(values) != count:
            raise self.error(f"{key}=\"{text}\" is not {count} numbers", where)
        return values

    def number(self, element: Element | None, key: str, where: str) -> float | None:
        text = None if element is None else element.get(key)
        if text is None:
            return None
        try:
            return float(text)
        except ValueError:
            raise self.error(f"{key}=\"{text}\" is not a number", f"{where}.{key}") from None

    def origin(self, element: Element | None, where: str) -> np.ndarray | None:
        if element is None:
            return None
        where = f"{where}.origin"
        xyz = self.numbers(element, "xyz", "0 0 0", 3, where)
        roll, pitch, yaw = self.numbers(element, "rpy", "0 0 0", 3, where)
        frame = np.eye(4)
        frame[:3, :3] = _rotation_z(yaw) @ _rotation_y(pitch) @ _rotation_x(roll)
        frame[:3, 3] = xyz
        return frame

    def link(self, element: Element) -> Link:
        name = self.name(element, "link")
        inertial = element.find("inertial")
        if inertial is None:
            return Link(name, None)
        where = f"link '{name}'.inertial"
        moments = {key: self.number(inertial.find("inertia"), key, f"{where}.inertia")
                   for key in _MOMENTS}
        xx, xy, xz, yy, yz, zz = (moments[key] for key in _MOMENTS)
        return Link(name, Inertial(
            origin=self.origin(inertial.find("origin"), where),
            mass=self.number(inertial.find("mass"), "value", f"{where}.mass"),
            inertia=np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], dtype=float)))

    def joint(self, element: Element) -> Joint:
        name = self.name(element, "joint")
        where = f"joint '{name}'"
        ends = []
        for role in ("parent", "child"):
            end = element.find(role)
            if end is None or end.get("link") is None:
                raise self.error(f"no <{role} link=\"...\"/>", where)
            ends.append(end.get("link"))
        axis = element.find("axis")
        limit = element.find("limit")
        mimic = element.find("mimic")
        return Joint(
            name=name, type=element.get("type"), parent=ends[0], child=ends[1],
            origin=self.origin(element.find("origin"), where),
            axis=np.array([1.0, 0.0, 0.0]) if axis is None
            else np.array(self.numbers(axis, "xyz", "1 0 0", 3, f"{where}.axis")),
            limit=None if limit is None else Limit(
                self.number(limit, "lower", f"{where}.limit"),
                self.number(limit, "upper", f"{where}.limit")),
            mimic=None if mimic is None else Mimic(
                mimic.get("joint"),
                _or(self.number(mimic, "multiplier", f"{where}.mimic"), 1.0),
                _or(self.number(mimic, "offset", f"{where}.mimic"), 0.0)))


def _or(value: float | None, default: float) -> float:
    return default if value is None else value


def _cos_sin(a: float) -> tuple[float, float]:
    """cos and sin, nan for an angle that is not finite (named later by the tree's check)."""
    return (math.cos(a), math.sin(a)) if math.isfinite(a) else (math.nan, math.nan)


def _rotation_x(a: float) -> np.ndarray:
    c, s = _cos_sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _rotation_y(a: float) -> np.ndarray:
    c, s = _cos_sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rotation_z(a: float) -> np.ndarray:
    c, s = _cos_sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


__all__ = ["Inertial", "Joint", "Limit", "Link", "Mimic", "Robot", "parse_robot"]
