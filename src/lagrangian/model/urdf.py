"""Robot arms from URDF: joints become the kinematic tree of 3D bodies, links their inertia.

URDF is read by yourdfpy (meshes, visual and collision elements are never loaded). Each
revolute, continuous or prismatic joint that is neither locked nor a mimic is a coordinate named
after it (rad or m); its actuator is the generalized force ``tau_<joint>`` (N m, or N for a
prismatic joint), a parameter of value 0. Gravity is g = 9.81 m/s^2 along -z (gravity.py turns
it). The file's joint names and limits are kept (Model.source_names, source_ratings; the
position limits as the coordinates' ranges). A link's frame is

    R_child = R_parent R_origin(rpy) R_axis(angle),  x_child = x_parent + R_parent xyz (+ d axis)

and its inertial (mass, tensor about the centre of mass in the inertial frame, that frame's
origin and rpy) becomes a rigid body whose inertia is turned into link axes, I = R I' R^T.
Joint damping and friction (<dynamics>) are kept (Model.source_dynamics) but left out of the
equations, as Pinocchio does: M, C q_dot and g are the rigid-body terms a controller needs;
dynamics(actuators=True) adds them (dynamics/actuators.py).

The root link is bolted to the world unless ``floating_base``: then a free-flyer joint carries it
(its kinematic tree's first joint, dynamics/tree/free_flyer.py), as Pinocchio's
``buildModelFromUrdf(path, JointModelFreeFlyer())``. A URDF ``floating`` joint from the root link
is read the same way (its origin the free flyer's placement). A floating base lives in the tree
only: the model's coordinates and rigid bodies are the joints', and deriving its equations is
refused (derivation/lagrange.py). Any other floating joint (between two links) frees its child
from its parent: a free flyer inside the tree (<joint>_x .. _qw in q, <joint>_vx .. _wz in v,
model/tree.py), and in the model six coordinates <joint>_x, _y, _z (m) and _roll, _pitch, _yaw
(rad), the symbolic bodies' (urdf_bodies.py); no actuator, no limit.
"""

from __future__ import annotations

import io
import keyword
import math
import re
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

import numpy as np
import sympy as sp

from ..errors import ModelError, did_you_mean, require_extra
from .builder import ModelBuilder
from .expressions import RESERVED
from .lazy_bodies import LAZY_ABOVE
from .model import Model
from .reader import read_text_file
from .tree import FREE_CONFIGURATION, FREE_VELOCITY
from .urdf_bodies import SymbolicBodies, _number
from .urdf_lock import lock_value
from .urdf_tree import FREE_SLIDES, FREE_TURNS, MOVABLE, numeric_tree

SUPPORTED = (*MOVABLE, "fixed")
GRAVITY = 9.81  # m/s^2, along -z


def read_urdf(path, lock: Mapping[str, float] | None = None,
              payload: Mapping[str, object] | None = None, floating_base: bool = False) -> Model:
    """Load a URDF file as a model; ``lock`` freezes joints at values (rad or m, or a text
    with its unit, "30deg") by name,
    ``payload`` adds point masses to links (urdf_payload.py), ``floating_base`` frees the root."""
    return parse_urdf(read_text_file(path), source=str(path), lock=lock, payload=payload,
                      floating_base=floating_base)


def example_urdf(name: str):
    """The path of a built-in URDF example (``two_link_arm``), else of an installed
    example-robot-data robot by its short name (``panda``, model/robots.py) that no built-in
    example shadows, or None."""
    from importlib import resources

    from .robots import example_robot, shadowed

    entry = resources.files("lagrangian.model.examples") / f"{name}.urdf"
    if not re.fullmatch(r"\w+", name):
        return None
    if entry.is_file():
        return Path(str(entry))
    return None if shadowed(name) else example_robot(name)


def parse_urdf(text: str, *, source: str = "<urdf>",
               lock: Mapping[str, float] | None = None,
               payload: Mapping[str, object] | None = None,
               floating_base: bool = False) -> Model:
    """The model of a URDF document (see the module docstring for what each element becomes);
    ``payload`` {link: mass or (mass, (x, y, z))} adds point masses (urdf_payload.py)."""
    from .urdf_payload import payload_values

    robot = _parse(text, source, payload_values(payload) if payload else None)
    return _Tree(robot, source).model(dict(lock or {}), bool(floating_base))


def _parse(text: str, source: str, payloads=None):
    require_extra("urdf", ("lxml", "yourdfpy"), "reading a URDF robot")
    from lxml import etree

    data = text.encode("utf-8")
    try:
        root = etree.fromstring(data, etree.XMLParser(resolve_entities=False, no_network=True))
    except etree.XMLSyntaxError as exc:
        raise ModelError(f"not well-formed XML ({exc})", source=source) from None
    _check_robot(root, source)
    _check_inertials(root, source)
    if payloads:
        from .urdf_payload import add_payloads

        add_payloads(root, payloads, source)
        data = etree.tostring(root)
    import yourdfpy

    try:
        # a non-finite origin makes trimesh warn while parsing; the joint is named below
        with np.errstate(all="ignore"):
            urdf = yourdfpy.URDF.load(io.BytesIO(data), build_scene_graph=False,
                                      load_meshes=False, load_collision_meshes=False,
                                      build_collision_scene_graph=False)
    except Exception as exc:  # yourdfpy's own errors are plain exceptions of many kinds
        reason = (f"an element lacks its {exc} attribute" if isinstance(exc, KeyError)
                  else " ".join(str(exc).split())[:200] or "unreadable")
        raise ModelError(f"not a URDF robot ({reason})", source=source) from None
    return urdf.robot


def _check_robot(root, source: str) -> None:
    """The document is a named <robot> with links: what yourdfpy needs before it can say why."""
    if root.tag != "robot":
        raise ModelError(f"the root element is <{root.tag}>, not <robot>: not a URDF robot",
                         source=source)
    if root.find("link") is None:
        raise ModelError("the <robot> holds no <link>: an empty robot (is this the output of a "
                         "xacro file that needed arguments?)", source=source)
    if not root.get("name"):
        raise ModelError("the <robot> element has no name (write <robot name=\"...\">)",
                         source=source)


def _check_inertials(root, source: str) -> None:
    """Each link's inertial has its mass and all six moments, as urdfdom requires: yourdfpy
    would read a missing mass as 0 and a missing ixx, iyy or izz as 1 kg m^2."""
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


_MOMENTS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
# Every number of a URDF is below this in size: masses, lengths and moments multiply (m r^2, and
# composite inertias down the chain), and a mass of 1e308 or a length of 1e200 gave inf.
MAX_URDF_NUMBER = 1e30


def identifier(name: str) -> str:
    """A joint name as a coordinate name of the model grammar (letters, digits, _)."""
    text = re.sub(r"\W", "_", name)
    if not text or not text[0].isalpha():
        text = "q_" + text
    if text in RESERVED or keyword.iskeyword(text) or text in ("g", "t"):
        text = text + "_joint"
    return text


class _Tree(SymbolicBodies):
    def __init__(self, robot, source: str):
        self.source = source
        # two links or joints of one name would make one of them vanish (urdfdom refuses them)
        for kind, items in (("link", robot.links), ("joint", robot.joints)):
            seen: set[str] = set()
            for item in items:
                if item.name in seen:
                    raise self.error(f"two {kind}s are named '{item.name}' (each {kind} needs a "
                                     "name of its own)", f"{kind} '{item.name}'")
                seen.add(item.name)
        self.links = {link.name: link for link in robot.links}
        self.joints = list(robot.joints)
        self.by_name = {j.name: j for j in self.joints}
        # a planar joint's name -> its child link (the joint's frame), once expanded
        self.planar: dict[str, str] = {}
        self.name = robot.name or "URDF robot"
        for joint in self.joints:
            self._check_numbers(joint)
        for link in robot.links:
            inertial = link.inertial
            if inertial is not None:
                self._check_finite(f"link '{link.name}'.inertial",
                                   (("origin", inertial.origin), ("mass", inertial.mass),
                                    ("inertia", inertial.inertia)))

    def error(self, message: str, field: str | None = None) -> ModelError:
        return ModelError(message, field=field, source=self.source)

    def _check_numbers(self, joint) -> None:
        """Every number of a joint finite (an origin of inf, a mimic multiplier of nan)."""
        where = f"joint '{joint.name}'"
        numbers = (("origin", joint.origin), ("axis", joint.axis))
        if joint.mimic is not None:
            numbers += (("mimic.multiplier", joint.mimic.multiplier),
                        ("mimic.offset", joint.mimic.offset))
        self._check_finite(where, numbers)
        if joint.limit is not None:  # only a range: +-1.8e308 stands for none in some files
            self._check_finite(where, (("limit.lower", joint.limit.lower),
                                       ("limit.upper", joint.limit.upper)), bounded=False)

    def _check_finite(self, where: str, numbers, bounded: bool = True) -> None:
        for name, value in numbers:
            if value is None:
                continue
            try:
                numbers = np.asarray(value, dtype=float)
                finite = bool(np.all(np.isfinite(numbers)))
            except (TypeError, ValueError):
                finite = False
            if not finite:
                raise self.error("a number that is not finite", f"{where}.{name}")
            if bounded and np.any(np.abs(numbers) >= MAX_URDF_NUMBER):
                raise self.error(f"the number {float(np.abs(numbers).max()):g} is too large (a "
                                 f"URDF's numbers are SI and below {MAX_URDF_NUMBER:g} in size)",
                                 f"{where}.{name}")

    def _check_tree(self) -> tuple[str, dict[str, list]]:
        parent_of: dict[str, object] = {}
        children: dict[str, list] = {}
        for joint in self.joints:
            where = f"joint '{joint.name}'"
            if joint.type not in SUPPORTED and joint.type != "floating":
                raise self.error(
                    f"unknown joint type {joint.type!r} (use revolute, continuous, "
                    f"prismatic, planar, floating or fixed)"
                    f"{did_you_mean(str(joint.type), (*SUPPORTED, 'planar', 'floating'))}", where)
            for role, link in (("parent", joint.parent), ("child", joint.child)):
                if link not in self.links:
                    raise self.error(f"no link '{link}' for its {role}"
                                     f"{did_you_mean(str(link), list(self.links))}", where)
            if joint.child in parent_of:
                raise self.error(
                    f"link '{joint.child}' is the child of joints '{parent_of[joint.child].name}' "
                    f"and '{joint.name}': a closed loop (URDF describes trees only)", where)
            parent_of[joint.child] = joint
            children.setdefault(joint.parent, []).append(joint)
        roots = [name for name in self.links if name not in parent_of]
        if len(roots) != 1:
            if not roots:
                raise self.error("every link is the child of a joint: a closed loop "
                                 "(URDF describes trees only)")
            raise self.error(f"the links form {len(roots)} separate trees (roots "
                             f"{', '.join(repr(r) for r in roots)}); a robot has one root link")
        reached, stack = set(), [roots[0]]
        while stack:
            link = stack.pop()
            reached.add(link)
            stack += [j.child for j in children.get(link, [])]
        if len(reached) != len(self.links):
            lost = next(j for j in self.joints if j.child not in reached)
            raise self.error("its links form a closed loop, unreachable from the root link "
                             f"'{roots[0]}' (URDF describes trees only)", f"joint '{lost.name}'")
        self._check_floating(roots[0], children)
        return roots[0], children

    def _check_floating(self, root: str, children: dict[str, list]) -> None:
        """A floating joint that is the root link's one moving joint frees the whole robot: the
        free flyer at the tree's root (Pinocchio's layout puts it first). Any other one frees
        its child from its parent (self.free: a free flyer below the root, its own seven
        configuration numbers); it has no limit and no mimic."""
        self.free = {}
        for joint in self.joints:
            if joint.type != "floating":
                continue
            where = f"joint '{joint.name}'"
            if joint.mimic is not None:
                raise self.error("a floating joint cannot mimic another joint", f"{where}.mimic")
            others = [j.name for j in children[root] if j is not joint and j.type != "fixed"]
            if joint.parent == root and not others:
                continue  # the floating base
            if joint.limit is not None:
                raise self.error("a floating joint has no limits (its child moves freely, as "
                                 "Pinocchio's free flyer): remove its <limit>", f"{where}.limit")
            self.free[joint.name] = ""  # its coordinates' stem, named in model()

    def _expand_planar(self) -> None:
        """Each planar joint as the three one-coordinate joints it is: <name>_x and <name>_y
        sliding along the plane's axes e1, e2 of the joint's frame, then <name>_theta turning
        about its normal n (the URDF axis; e1 the frame axis least along n, made normal to it,
        e2 = n x e1: x, y for n = z, as Pinocchio's JointModelPlanar), through two massless links;
        so every stage and backend moves it (nq = nv = 3, rates the coordinates' derivatives)."""
        import yourdfpy

        planar = [j for j in self.joints if j.type == "planar"]
        if not planar:
            return
        names = set(self.links) | set(self.by_name)

        def fresh(name: str) -> str:
            while name in names:
                name += "_"
            names.add(name)
            return name

        expanded = []
        for joint in self.joints:
            if joint.type != "planar":
                expanded.append(joint)
                continue
            where = f"joint '{joint.name}'"
            if joint.mimic is not None:
                raise self.error("a planar joint cannot mimic another joint", f"{where}.mimic")
            normal = np.asarray(joint.axis if joint.axis is not None else (0, 0, 1), float)
            norm = float(np.linalg.norm(normal))
            if not math.isfinite(norm) or norm == 0:
                raise self.error("the axis (the plane's normal) has zero length", f"{where}.axis")
            normal = normal / norm
            first = np.eye(3)[int(np.argmin(np.abs(normal)))]
            first = first - normal * float(first @ normal)
            first /= float(np.linalg.norm(first))
            second = np.cross(normal, first)
            links = [fresh(f"{joint.name}_x_link"), fresh(f"{joint.name}_y_link")]
            for link in links:
                self.links[link] = yourdfpy.Link(name=link)
            steps = (("x", "prismatic", first, joint.parent, links[0], joint.origin),
                     ("y", "prismatic", second, links[0], links[1], None),
                     ("theta", "continuous", normal, links[1], joint.child, None))
            for suffix, kind, axis, parent, child, origin in steps:
                expanded.append(yourdfpy.Joint(
                    name=fresh(f"{joint.name}_{suffix}"), type=kind, parent=parent,
                    child=child, origin=origin, axis=np.array(axis), dynamics=joint.dynamics))
            self.planar[joint.name] = joint.child
        self.joints = expanded
        self.by_name = {j.name: j for j in self.joints}

    def model(self, lock: dict[str, float], floating_base: bool = False) -> Model:
        for name in lock:
            if self.by_name.get(name) is not None and self.by_name[name].type == "planar":
                raise ModelError(f"joint '{name}' is planar: lock its coordinates "
                                 f"'{name}_x', '{name}_y', '{name}_theta' one by one",
                                 field=f"lock.{name}")
        self._expand_planar()
        root, children = self._check_tree()
        floats = [j.name for j in self.joints if j.type == "floating" and j.name not in self.free]
        if floating_base and floats:
            floating = floats[0]
            raise ModelError(f"the URDF's joint '{floating}' already floats the base; "
                             "floating_base would add a second free flyer above it",
                             field="floating_base")
        order = []  # joints from the root down, depth first in document order
        stack = list(reversed(children.get(root, [])))
        while stack:
            joint = stack.pop()
            order.append(joint)
            stack += list(reversed(children.get(joint.child, [])))
        movable = [j.name for j in order if j.type in MOVABLE]
        for name, value in lock.items():
            if name not in self.by_name:
                raise ModelError(f"no joint '{name}' in {self.source}"
                                 f"{did_you_mean(str(name), movable)}", field=f"lock.{name}")
            if self.by_name[name].type not in MOVABLE:
                raise ModelError(f"joint '{name}' is {self.by_name[name].type}: only revolute, "
                                 "continuous and prismatic joints can be locked",
                                 field=f"lock.{name}")
            # a locked mimic joint (the Panda's second finger) is frozen at its own value
            lock[name] = lock_value(self.by_name[name], value)  # its unit and limit checked

        builder = ModelBuilder(self.name, f"Robot '{self.name}' read from URDF "
                               f"({len(order)} joints, {len(self.links)} links).",
                               source=self.source)
        g = builder.parameter("g", GRAVITY, "m/s^2")
        builder.set_gravity(g, (0, 0, -1))
        names: dict[str, str] = {}
        taken = {"g"}
        for joint in order:
            if joint.name in self.free:  # its six coordinates (urdf_bodies.py), no actuator
                self.free[joint.name] = self._free_coordinates(builder, joint, taken)
                continue
            if joint.type not in MOVABLE or joint.name in lock or joint.mimic is not None:
                continue
            name = identifier(joint.name)
            while name in taken or f"tau_{name}" in taken:
                name += "_"
            taken |= {name, f"tau_{name}"}
            names[joint.name] = name
            unit = "m" if joint.type == "prismatic" else "rad"
            limit = joint.limit if joint.type != "continuous" else None
            span = None
            initial = 0.0
            if limit is not None and limit.lower is not None and limit.upper is not None \
                    and limit.lower < limit.upper:
                span = (float(limit.lower), float(limit.upper))
                if not span[0] <= 0.0 <= span[1]:
                    initial = 0.5 * (span[0] + span[1])
            field = f"joint '{joint.name}'"
            builder.coordinate(name, unit, initial=initial, rate=0.0, range=span, field=field)
            tau = builder.parameter(f"tau_{name}", 0.0, "N" if unit == "m" else "N*m",
                                    field=field)
            builder.add_generalized_force(name, tau, field=field)
        if not names and not self.free:
            raise self.error("no joint left to move: a model needs at least one revolute, "
                             "continuous or prismatic joint that is not locked"
                             + (" (a lone floating body: not yet)" if floating_base or any(
                                 j.type == "floating" for j in order) else ""))
        position = self._positions(lock, names)
        model = builder.build_model()
        if len(names) > LAZY_ABOVE:  # a long chain: its symbolic bodies when first asked for
            tree = numeric_tree(self.links, root, order, position, names, (), floating_base,
                                self.free)
            bodies = self._lazy_bodies(root, order, position, tree)
            tree = replace(tree, rigid_bodies=bodies)
        else:
            bodies = tuple(self._bodies(root, order, position))
            tree = numeric_tree(self.links, root, order, position, names, bodies, floating_base,
                                self.free)
        if self.planar:  # a planar joint's own name: its frame, its child link's
            by_link = {f.name: f for f in tree.frames}
            tree = replace(tree, frames=tree.frames + tuple(
                replace(by_link[child], name=name) for name, child in self.planar.items()
                if name not in by_link))
        return replace(model, rigid_bodies=bodies, kinematic_tree=tree,
                       source_names=tuple((name, joint) for joint, name in names.items()),
                       source_ratings=tuple((name, *self._ratings(joint))
                                            for joint, name in names.items()),
                       source_dynamics=tuple((name, *self._friction(joint))
                                             for joint, name in names.items()))

    def _free_coordinates(self, builder: ModelBuilder, joint, taken: set[str]) -> str:
        """A floating joint's six coordinates, <stem>_x, _y, _z (m) and _roll, _pitch, _yaw
        (rad), each at 0, unbounded and without an actuator; the stem (the joint's name) is
        kept clear of the tree's own names for it (free_flyer.free_names)."""
        stem = identifier(joint.name)
        suffixes = (*FREE_SLIDES, *FREE_TURNS, *FREE_CONFIGURATION, *FREE_VELOCITY)
        while any(f"{stem}_{k}" in taken or f"tau_{stem}_{k}" in taken for k in suffixes):
            stem += "_"
        taken |= {f"{stem}_{k}" for k in suffixes}
        field = f"joint '{joint.name}'"
        for k in (*FREE_SLIDES, *FREE_TURNS):
            builder.coordinate(f"{stem}_{k}", "m" if k in FREE_SLIDES else "rad", initial=0.0,
                               rate=0.0, field=field)
        return stem

    def _friction(self, name: str) -> tuple[float, float]:
        """A joint's <dynamics> damping and Coulomb friction (0 where absent); a negative or
        non-finite one is refused, naming the joint."""
        dynamics = self.by_name[name].dynamics
        values = []
        for key in ("damping", "friction"):
            value = getattr(dynamics, key, None) if dynamics is not None else None
            try:  # yourdfpy keeps the attribute's text where it is not a number ("")
                value = 0.0 if value is None else float(value)
            except (TypeError, ValueError):
                raise self.error(f"<dynamics {key}=\"{value}\"> is not a number",
                                 f"joint '{name}'.dynamics.{key}") from None
            if not (math.isfinite(value) and value >= 0):
                raise self.error(f"<dynamics {key}=\"{value:g}\"> must be a finite number >= 0",
                                 f"joint '{name}'.dynamics.{key}")
            values.append(value)
        return values[0], values[1]

    def _ratings(self, name: str) -> tuple[float | None, float | None]:
        """A joint's velocity and effort limits (positive numbers, else None)."""
        limit = self.by_name[name].limit

        def positive(value):
            try:
                value = float(value)
            except (TypeError, ValueError):
                return None
            return value if math.isfinite(value) and value > 0 else None

        return (None, None) if limit is None else (positive(limit.velocity),
                                                   positive(limit.effort))

    def _positions(self, lock: dict[str, float], names: dict[str, str]):
        """Each movable joint's position (angle or distance) and rate as expressions in q."""
        values: dict[str, tuple[sp.Expr, sp.Expr]] = {}

        def value(joint, path=()):
            if joint.name in values:
                return values[joint.name]
            if joint.name in names:
                symbol = sp.Symbol(names[joint.name])
                values[joint.name] = (symbol, sp.Symbol(names[joint.name] + "_dot"))
            elif joint.name in lock:
                values[joint.name] = (_number(lock[joint.name]), sp.S.Zero)
            else:  # a mimic joint: multiplier * master + offset
                mimic = joint.mimic
                master = self.by_name.get(mimic.joint)
                field = f"joint '{joint.name}'.mimic"
                if master is None:
                    raise self.error(f"mimics no joint '{mimic.joint}'"
                                     f"{did_you_mean(str(mimic.joint), list(self.by_name))}",
                                     field)
                if master.type not in MOVABLE or master.name in path:
                    raise self.error(f"mimics '{mimic.joint}', which is "
                                     + ("a cycle of mimics" if master.name in path
                                        else f"a {master.type} joint"), field)
                angle, rate = value(master, (*path, joint.name))
                k = _number(mimic.multiplier if mimic.multiplier is not None else 1.0)
                offset = _number(mimic.offset or 0.0)
                values[joint.name] = (k * angle + offset, k * rate)
            return values[joint.name]

        return value


__all__ = ["example_urdf", "identifier", "parse_urdf", "read_urdf"]
