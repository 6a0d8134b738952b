"""A robot's kinematic tree in numbers, kept beside its symbolic rigid bodies.

Each moving body hangs from its parent body (or the ground) by one revolute or prismatic joint:

    R = R_0 Rot(u, theta),  p = t_0           (revolute: child axes -> parent axes, origin in parent)
    R = R_0,                p = t_0 + R_0 u theta   (prismatic)
    R = R_0 Rot(u, theta),  p = t_0 + R_0 u pitch theta   (helical: a screw, pitch in m/rad)

with theta = k q[c] + offset (k = 1, offset = 0 except for a mimic joint). A spherical (ball)
joint turns its body by a unit quaternion, MuJoCo's ball joint: R = R_0 R(qw, qx, qy, qz), p = t_0,
four configuration numbers q[c:c+4] (w first, MuJoCo's order) and three velocity numbers, the
body's angular velocity relative to its parent in the body's own axes (rad/s); so after a ball
joint a coordinate's place in q and in v differ (KinematicTree.velocity_index). A floating base is a
free-flyer joint at the root (joints[0], parent -1, kind free_flyer): the base link's body, moved
by the configuration's first 7 numbers (position, quaternion x y z w) and the velocity's first 6
(dynamics/tree/free_flyer.py); the other joints' numbers follow, q[7 + c] and v[6 + c]. A free
flyer below the root (a URDF floating joint between two links, coordinate c >= 0) moves its body
in its parent by q[c:c+7] (x y z in the joint's frame, then qx qy qz qw: R = R_0 R(q),
p = t_0 + R_0 (x, y, z)) and v's six numbers (linear then angular, the body's own axes), as
Pinocchio's JointModelFreeFlyer anywhere in a tree. MuJoCo's free joint (JointKind.FREE) is no
joint of its own here: three prismatic joints along the world's axes from the ground (massless
bodies) and a spherical joint at their end, MuJoCo's qpos and qvel exactly (model/mjcf_free.py).
Fixed and locked
joints are folded into R_0, t_0 of the next joint down, and the links they carry into the
inertia of the moving body above them. A body's inertia is (m, h = m c, J_O): mass (kg), first
moment about its frame's origin (kg m) and inertia tensor about that origin (kg m^2), in its
own axes: additive, so the links fixed to one body simply sum. Recursive algorithms (composite
rigid body, Newton-Euler) run on this tree without the expanded equations.

A model file's (or ModelBuilder's) rigid bodies on revolute and prismatic joints give the same
tree (body_tree), its numbers taken from the parameter values: one joint type for both.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import sympy as sp

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
    coordinate: int  # index in ``coordinates`` of the (first) configuration number that drives it
    multiplier: float  # theta = multiplier * q[coordinate] + offset
    offset: float
    mass: float  # kg
    first_moment: Vector3  # h = m c about the joint's origin, body axes (kg m)
    inertia: Matrix3x3  # J_O about the joint's origin, body axes (kg m^2)
    pitch: float = 0.0  # a helical joint's slide per turn of theta (m/rad); 0 for the others

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
class TreeLink:
    """A link's inertial as the URDF gives it, and where the link sits on a moving body: mass
    (kg), centre of mass ``com`` in the link's frame (m), the inertial frame's axes
    ``com_rotation`` (inertial -> link axes) and the inertia tensor about the centre of mass in
    those axes (kg m^2); the link's frame is ``rotation``, ``translation`` in the body's axes.
    The body inertias of the tree are these links' sums (``link_inertias``)."""

    name: str
    body: int
    rotation: Matrix3x3
    translation: Vector3
    mass: float
    com: Vector3
    com_rotation: Matrix3x3
    inertia: Matrix3x3


INERTIAL_FIELDS = ("mass", "com_x", "com_y", "com_z", "ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def link_inertias(links, count: int):
    """Each moving body's (m, h = m c, J_O) summed over its links, numpy (count bodies)."""
    import numpy as np

    out = [[0.0, np.zeros(3), np.zeros((3, 3))] for _ in range(count)]
    for link in links:
        if link.body < 0:
            continue
        turn, shift = np.array(link.rotation), np.array(link.translation)
        axes = np.array(link.com_rotation)
        tensor = np.array(link.inertia)
        tensor = turn @ (axes @ tensor @ axes.T) @ turn.T
        center = shift + turn @ np.array(link.com)
        mass = float(link.mass)
        # about the body's origin: J_O = I_C + m (|c|^2 1 - c c^T), h = m c
        out[link.body][0] += mass
        out[link.body][1] += mass * center
        out[link.body][2] += tensor + mass * (center @ center * np.eye(3)
                                              - np.outer(center, center))
    return out


def with_link_inertials(tree: KinematicTree, values) -> KinematicTree:
    """The tree with some links' inertials replaced: ``values`` {(link, field): number}, field
    one of INERTIAL_FIELDS (the URDF's <mass>, <origin xyz> and <inertia>), as if the file had
    been edited; every body's inertia summed anew from its links."""
    from dataclasses import replace

    by_name = {link.name: link for link in tree.links}
    for (name, field_), value in values.items():
        link = by_name[name]
        if field_ == "mass":
            link = replace(link, mass=float(value))
        elif field_.startswith("com_"):
            com = list(link.com)
            com["xyz".index(field_[-1])] = float(value)
            link = replace(link, com=tuple(com))
        else:
            r, c = "xyz".index(field_[1]), "xyz".index(field_[2])
            rows = [list(row) for row in link.inertia]
            rows[r][c] = rows[c][r] = float(value)
            link = replace(link, inertia=tuple(tuple(row) for row in rows))
        by_name[name] = link
    links = tuple(by_name[link.name] for link in tree.links)
    inertias = link_inertias(links, len(tree.joints))
    joints = tuple(replace(j, mass=float(m), first_moment=tuple(float(x) for x in h),
                           inertia=tuple(tuple(float(x) for x in row) for row in 0.5 * (J + J.T)))
                   for j, (m, h, J) in zip(tree.joints, inertias, strict=True))
    return replace(tree, joints=joints, links=links, rigid_bodies=tree.rigid_bodies)


@dataclass(frozen=True)
class KinematicTree:
    """The moving bodies of a robot, gravity g along ``gravity_direction`` (world axes, unit),
    and for each coordinate the parameter whose value is its actuator force (tau_<joint>)."""

    joints: tuple[TreeJoint, ...]
    coordinates: tuple[str, ...]
    gravity_parameter: str
    gravity_direction: Vector3
    actuators: tuple[str, ...]  # one parameter name (or None) per velocity number
    # the velocity's names where they differ from the coordinates (a ball joint: 4 numbers in q,
    # 3 in v); () where they are the same. Out of repr: the compiled modules' keys (repr) of
    # the trees without a ball joint stay as they were.
    velocities: tuple[str, ...] = field(default=(), repr=False)
    # The model's rigid bodies built from the same joints: a model whose bodies are not these
    # (edited after reading) is not described by this tree.
    rigid_bodies: tuple = field(default=(), compare=False, repr=False)
    # Every link and joint frame, for placements and Jacobians (dynamics/algorithms/frames.py); not part of
    # the tree's identity (the dynamics, and the compiled module's key, do not depend on them).
    frames: tuple[TreeFrame, ...] = field(default=(), compare=False, repr=False)
    # Every link with an inertial (TreeLink): its mass, centre of mass and inertia are the
    # dynamics' runtime parameters (`<link>.mass`, ...); the joints' numbers are their sums.
    links: tuple[TreeLink, ...] = field(default=(), compare=False, repr=False)
    # The root link and the mass (kg) welded to it that a fixed base holds still (a legged
    # robot's trunk), for the note that names floating_base; not part of the dynamics.
    root_link: str = field(default="", compare=False, repr=False)
    root_mass: float = field(default=0.0, compare=False, repr=False)
    # The model's own coordinates where they are not the tree's (an MJCF ball joint: three hinge
    # angles in the symbolic model, its quaternion here); () where they are the same.
    model_coordinates: tuple[str, ...] = field(default=(), compare=False, repr=False)
    # MJCF free joints in MuJoCo's layout (model/mjcf_free.py): the ball joints that end three
    # world slides, named by the free joint, for the words of a refusal; not the dynamics'
    mujoco_free: tuple[str, ...] = field(default=(), compare=False, repr=False)

    @property
    def velocity_coordinates(self) -> tuple[str, ...]:
        """The names of the joints' velocity numbers (the coordinates but for ball joints)."""
        return self.velocities or self.coordinates

    @property
    def spherical(self) -> tuple[TreeJoint, ...]:
        """The tree's ball joints (a quaternion each)."""
        return tuple(j for j in self.joints if j.kind == JointKind.SPHERICAL)

    @property
    def nq(self) -> int:
        """The configuration's numbers: the base's, then the joints' (4 per ball joint)."""
        return self.base_nq + len(self.coordinates)

    @property
    def nv(self) -> int:
        """The velocity's numbers: the base's, then the joints' (3 per ball joint)."""
        return self.base_nv + len(self.velocity_coordinates)

    @property
    def free_joints(self) -> tuple[TreeJoint, ...]:
        """The free flyers below the root (a URDF floating joint between two links): 7 of the
        joints' own configuration numbers each (x y z, qx qy qz qw), 6 velocity numbers."""
        return tuple(j for j in self.joints
                     if j.kind == JointKind.FREE_FLYER and j.coordinate >= 0)

    @property
    def quaternion_joints(self) -> tuple[TreeJoint, ...]:
        """The joints with a quaternion among the joints' own numbers (ball joints and free
        flyers below the root): where q and v differ in length after the base."""
        return tuple(j for j in self.joints if j.coordinate >= 0 and j.kind in _QUATERNION)

    def velocity_index(self, coordinate: int) -> int:
        """Where the configuration number ``coordinate`` (an index in ``coordinates``) has its
        rate among the joints' velocity numbers: one less per ball joint or free flyer before
        it (4 numbers in q and 3 in v, or 7 and 6)."""
        return coordinate - sum(1 for j in self.joints
                                if j.kind in _QUATERNION and 0 <= j.coordinate < coordinate)

    @property
    def floating_base(self) -> bool:
        """Whether the root body moves freely (a free-flyer joint first, its numbers the
        base's: coordinate -1)."""
        return bool(self.joints) and self.joints[0].kind == JointKind.FREE_FLYER \
            and self.joints[0].coordinate < 0

    @property
    def base_nq(self) -> int:
        """Configuration numbers before the joints' own: 7 for a floating base, else 0."""
        return 7 if self.floating_base else 0

    @property
    def base_nv(self) -> int:
        """Velocity numbers before the joints' own: 6 for a floating base, else 0."""
        return 6 if self.floating_base else 0


def refuse_ball_joints(tree: KinematicTree | None, what: str) -> None:
    """Refuse, in one line naming the joint, a tree with a ball joint or a free flyer below
    the root where ``what`` (an algorithm or an export) walks one-number joints and a base
    only (its numbers would be miscounted)."""
    balls = () if tree is None else tree.spherical
    if balls:
        from ..errors import ModelError

        if balls[0].name in tree.mujoco_free:
            # one free joint can be the floating base instead, which more of the tools take
            hint = ": load with floating_base=True (--floating-base) for the free flyer" \
                if len(tree.mujoco_free) == 1 else ""
            raise ModelError(f"joint '{balls[0].name}' is a free joint in MuJoCo's layout (three "
                             f"slides and a ball joint), which {what} does not take yet{hint}",
                             field="joint")
        raise ModelError(f"joint '{balls[0].name}' is a ball (spherical) joint, which {what} "
                         "does not take yet (M, inverse and forward dynamics and their "
                         "derivatives, the energies, frames and Jacobians, kernel='unrolled' "
                         "and the C export do)",
                         field="joint")
    refuse_free_joints(tree, what)


def refuse_free_joints(tree: KinematicTree | None, what: str) -> None:
    """Refuse, in one line naming the joint, a tree with a free flyer below the root (a URDF
    floating joint between two links) where ``what`` does not take one."""
    free = () if tree is None else tree.free_joints
    if free:
        from ..errors import ModelError

        raise ModelError(f"joint '{free[0].name}' is a floating joint below the root (a free "
                         f"flyer between two links), which {what} does not take yet (M, "
                         "inverse and forward dynamics and their derivatives, the energies, "
                         "frames, Jacobians, simulate, kernel='unrolled' and the C export do)",
                         field="joint")


_QUATERNION = (JointKind.SPHERICAL, JointKind.FREE_FLYER)
# a free flyer's numbers by suffix, in Pinocchio's order (a floating base's: base_x, ...; one
# below the root: <joint>_x, ...): position in the parent's joint frame (m) and quaternion, then
# the body's linear (m/s) and angular (rad/s) velocity in its own axes
FREE_CONFIGURATION = ("x", "y", "z", "qx", "qy", "qz", "qw")
FREE_VELOCITY = ("vx", "vy", "vz", "wx", "wy", "wz")
_IDENTITY: Matrix3x3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def body_tree(model, values: Mapping[sp.Symbol, float]) -> KinematicTree | None:
    """The kinematic tree of a model whose only components are rigid bodies on revolute and
    prismatic joints (constant mass and inertia, no t), gravity along a fixed direction with a
    parameter for its magnitude, and at most one parameter per coordinate as its generalized
    force; numbers from ``values`` (parameter symbol -> SI value). None where the model holds
    anything else, so that nothing it holds is ever left out."""
    if (not model.rigid_bodies or model.particles or model.bodies or model.springs
            or model.dampers or model.loads or model.constraints or model.contacts
            or model.kinetic_energy != 0 or model.potential_energy != 0
            or model.dissipation != 0 or model.kinematic_tree is not None):
        return None
    names = {p.symbol: p.name for p in model.parameters}
    gravity_parameter, direction = None, (0.0, 0.0, 0.0)
    if model.gravity is not None:
        gravity_parameter = names.get(model.gravity.magnitude)
        direction = _numbers(model.gravity.direction, values)
        if gravity_parameter is None or direction is None:
            return None
    forces: dict[str, list] = {}
    for coordinate, force in model.generalized_forces:
        forces.setdefault(coordinate, []).append(force)
    actuators = []
    for c in model.coordinates:
        given = forces.get(c.name, [])
        if len(given) > 1 or (given and given[0] not in names):
            return None
        actuators.append(names[given[0]] if given else None)
    index = {b.name: k for k, b in enumerate(model.rigid_bodies)}
    coordinates = {symbol: k for k, symbol in enumerate(model.q)}
    joints = []
    for body in model.rigid_bodies:
        joint = _tree_joint(body, index, coordinates, model.time, values)
        if joint is None:
            return None
        joints.append(joint)
    return KinematicTree(joints=tuple(joints), coordinates=tuple(c.name for c in model.coordinates),
                         gravity_parameter=gravity_parameter, gravity_direction=direction,
                         actuators=tuple(actuators), rigid_bodies=model.rigid_bodies)


def _tree_joint(body, index, coordinates, time, values) -> TreeJoint | None:
    """One body on its joint in numbers, or None where it is not on a revolute or prismatic
    joint driven by one coordinate (theta = k q + offset), or its inertia is not constant."""
    joint = body.joint
    if joint is None or (body.parent is not None and body.parent not in index):
        return None
    driving = [s for s in joint.variable.free_symbols if s in coordinates]
    if len(driving) != 1 or time in joint.variable.free_symbols:
        return None
    q = driving[0]
    slope = sp.diff(joint.variable, q)
    multiplier = _number(slope, values)
    offset = _number(joint.variable.xreplace({q: sp.S.Zero}), values)
    mass = _number(body.mass, values)
    center = _numbers(joint.center, values)
    at, axis = _numbers(joint.at, values), _numbers(joint.axis, values)
    inertia = [_numbers(row, values) for row in body.inertia]
    if (None in (multiplier, offset, mass, center, at, axis) or None in inertia
            or q in slope.free_symbols or multiplier == 0):
        return None
    # J_O = I_c + m (|c|^2 E - c c^T): the inertia about the joint's origin (parallel axes)
    c2 = sum(x * x for x in center)
    about_origin = tuple(tuple(inertia[i][j] + mass * ((c2 if i == j else 0.0) - center[i] * center[j])
                               for j in range(3)) for i in range(3))
    return TreeJoint(name=body.name, parent=-1 if body.parent is None else index[body.parent],
                     kind=joint.kind, rotation=_IDENTITY, translation=at, axis=axis,
                     coordinate=coordinates[q], multiplier=multiplier, offset=offset, mass=mass,
                     first_moment=tuple(mass * x for x in center), inertia=about_origin)


def _number(expr, values) -> float | None:
    try:
        value = float(expr.xreplace(values) if isinstance(expr, sp.Basic) else expr)
    except (TypeError, ValueError):
        return None
    return value if value == value and abs(value) != float("inf") else None


def _numbers(vector, values) -> tuple | None:
    found = tuple(_number(x, values) for x in vector)
    return None if None in found else found


__all__ = ["FREE_CONFIGURATION", "FREE_VELOCITY", "INERTIAL_FIELDS", "KinematicTree",
           "TreeFrame", "TreeJoint", "TreeLink", "body_tree", "link_inertias",
           "refuse_ball_joints", "refuse_free_joints", "with_link_inertials"]
