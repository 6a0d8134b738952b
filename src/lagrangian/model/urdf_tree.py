"""A URDF robot as numbers: its kinematic tree (model/tree.py) for the recursive algorithms,
read from the same joints and links as urdf.py's symbolic bodies. Each moving joint is one
TreeJoint (a free flyer first for a floating base), fixed and locked joints fold into the next
joint's placement, and each link's inertial is a TreeLink whose sums are the bodies' inertias."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..kinds import JointKind
from .tree import (
    FREE_CONFIGURATION,
    FREE_VELOCITY,
    KinematicTree,
    TreeFrame,
    TreeJoint,
    TreeLink,
    link_inertias,
)

MOVABLE = ("revolute", "continuous", "prismatic")
# a floating joint's six symbolic coordinates, by suffix (urdf_bodies.py): three slides along
# its frame's axes, then the rpy angles
FREE_SLIDES = ("x", "y", "z")
FREE_TURNS = ("roll", "pitch", "yaw")
# a screw: no URDF type, the tree builder's only (model/robot_builder.py: the joint's ``pitch``,
# m/rad)
HELICAL = "helical"
# Entries of a rotation within this of 0 or +-1 are taken as exact: cos(pi/2) = 6e-17 in a
# URDF's rpy would otherwise keep every product it enters.
SNAP = 1e-14


def numeric_tree(links_by_name, root: str, order, position, names: dict[str, str], bodies,
                 floating_base: bool = False, free_joints=None) -> KinematicTree:
    """The same robot as numbers for the recursive algorithms (model/tree.py): ``links_by_name``
    the URDF's links, ``order`` its joints parent-first, ``position(joint)`` a joint's angle or
    distance as k q + offset, ``names`` joint -> coordinate, ``free_joints`` a floating joint
    between two links -> its coordinates' stem (a free flyer with seven numbers in q, six in
    v, no actuator; the model's six symbolic coordinates are its x, y, z and rpy)."""
    free_joints = free_joints or {}
    # each joint's first number in q, and the tree's q and v names, in the joints' order
    sequence = (list(names) if not free_joints
                else [j.name for j in order if j.name in names or j.name in free_joints])
    place: dict[str, int] = {}
    configuration, velocity, actuators, symbolic = [], [], [], []
    for name in sequence:
        place[name] = len(configuration)
        if name in free_joints:
            stem = free_joints[name]
            configuration += [f"{stem}_{k}" for k in FREE_CONFIGURATION]
            velocity += [f"{stem}_{k}" for k in FREE_VELOCITY]
            symbolic += [f"{stem}_{k}" for k in (*FREE_SLIDES, *FREE_TURNS)]
            actuators += [None] * len(FREE_VELOCITY)
        else:
            configuration.append(names[name])
            velocity.append(names[name])
            symbolic.append(names[name])
            actuators.append(f"tau_{names[name]}")
    coordinate = {symbol: place[joint] for joint, symbol in names.items()}
    anchor = {root: (-1, np.eye(3), np.zeros(3))}  # link -> (moving body, R, t in it)
    joints: list[dict] = []
    free = dict(parent=-1, kind=JointKind.FREE_FLYER, axis=np.zeros(3), coordinate=-1,
                multiplier=1.0, offset=0.0, pitch=0.0)  # the free flyer: its numbers come first
    if floating_base:  # Pinocchio's name for the root joint it adds
        joints.append(dict(free, name="root_joint", rotation=np.eye(3),
                           translation=np.zeros(3)))
        anchor[root] = (0, np.eye(3), np.zeros(3))
    for joint in order:
        body, turn, shift = anchor[joint.parent]
        origin = np.eye(4) if joint.origin is None else np.asarray(joint.origin, float)
        rotation = snapped(turn @ snapped(origin[:3, :3]))
        translation = shift + turn @ snapped(origin[:3, 3])
        if joint.name in free_joints:  # a free flyer below the root: its own numbers
            joints.append(dict(free, name=joint.name, parent=body, rotation=rotation,
                               translation=translation, coordinate=place[joint.name]))
            anchor[joint.child] = (len(joints) - 1, np.eye(3), np.zeros(3))
            continue
        if joint.type == "floating":  # the root link's only moving joint (_check_floating)
            joints.append(dict(free, name=joint.name, rotation=rotation,
                               translation=translation))
            anchor[joint.child] = (len(joints) - 1, np.eye(3), np.zeros(3))
            continue
        if joint.type not in MOVABLE and joint.type != HELICAL:
            anchor[joint.child] = (body, rotation, translation)
            continue
        axis = np.asarray(joint.axis if joint.axis is not None else (1, 0, 0), float)
        axis = snapped(axis / float(np.linalg.norm(axis)))
        angle = position(joint)[0]
        if angle.free_symbols:  # k q + offset with one coordinate q
            (symbol,) = angle.free_symbols
            k = float(angle.diff(symbol))
            offset = float(angle.subs(symbol, 0))
            joints.append(dict(name=joint.name, parent=body, kind=JOINT_KIND[joint.type],
                               rotation=rotation, translation=translation, axis=axis,
                               coordinate=coordinate[str(symbol)], multiplier=k,
                               offset=offset, pitch=float(getattr(joint, "pitch", 0.0))))
            anchor[joint.child] = (len(joints) - 1, np.eye(3), np.zeros(3))
        else:  # locked, or a mimic of a locked joint: a fixed joint at that value
            theta = float(angle)
            if joint.type == "prismatic":
                anchor[joint.child] = (body, rotation, translation + rotation @ axis * theta)
            elif joint.type == HELICAL:
                anchor[joint.child] = (body, rotation @ axis_rotation(axis, theta),
                                       translation + rotation @ axis * (joint.pitch * theta))
            else:
                anchor[joint.child] = (body, rotation @ axis_rotation(axis, theta),
                                       translation)
    links = []
    for name, (body, turn, shift) in anchor.items():
        inertial = links_by_name[name].inertial
        carries = not carries_nothing(inertial)
        where = np.asarray(inertial.origin if carries and inertial.origin is not None
                           else np.eye(4), dtype=float)
        tensor = np.asarray(inertial.inertia if carries and inertial.inertia is not None
                            else np.zeros((3, 3)), dtype=float)
        links.append(TreeLink(name, body, turn, shift,
                              float(inertial.mass or 0.0) if carries else 0.0,
                              snapped(where[:3, 3]), snapped(where[:3, :3]),
                              0.5 * (tensor + tensor.T)))
    inertias = link_inertias(links, len(joints))
    held = sum(link.mass for link in links if link.body < 0)  # the mass welded to a fixed root

    def vector(a):
        return tuple(float(x) for x in a)

    def matrix(a):
        return tuple(vector(row) for row in a)

    # every link's frame on its moving body, and each joint's frame (its child link's)
    frames = [TreeFrame(name, body, matrix(turn), vector(shift))
              for name, (body, turn, shift) in anchor.items()]
    by_link = {f.name: f for f in frames}
    frames += [dataclasses.replace(by_link[joint.child], name=joint.name)
               for joint in order if joint.name not in by_link and joint.child in by_link]
    if floating_base and "root_joint" not in by_link:
        frames.append(dataclasses.replace(by_link[root], name="root_joint"))
    return KinematicTree(
        frames=tuple(frames),
        links=tuple(TreeLink(k.name, k.body, matrix(k.rotation), vector(k.translation),
                             k.mass, vector(k.com), matrix(k.com_rotation),
                             matrix(k.inertia)) for k in links),
        joints=tuple(TreeJoint(
            name=j["name"], parent=j["parent"], kind=j["kind"], rotation=matrix(j["rotation"]),
            translation=vector(j["translation"]), axis=vector(j["axis"]),
            coordinate=j["coordinate"], multiplier=j["multiplier"], offset=j["offset"],
            mass=m, first_moment=vector(h), inertia=matrix(0.5 * (J + J.T)), pitch=j["pitch"])
            for j, (m, h, J) in zip(joints, inertias, strict=True)),
        coordinates=tuple(configuration), gravity_parameter="g",
        gravity_direction=(0.0, 0.0, -1.0), actuators=tuple(actuators),
        velocities=tuple(velocity) if free_joints else (),
        model_coordinates=tuple(symbolic) if free_joints else (),
        rigid_bodies=tuple(bodies), root_link=root, root_mass=held)


def carries_nothing(inertial) -> bool:
    """No inertial, or mass and inertia tensor both zero: a link with mass 0 but a tensor (the
    Bolt biped's feet) still turns with inertia, as Pinocchio keeps it."""
    if inertial is None:
        return True
    tensor = inertial.inertia if inertial.inertia is not None else np.zeros((3, 3))
    return not inertial.mass and not np.any(np.asarray(tensor, dtype=float))


JOINT_KIND = {"revolute": JointKind.REVOLUTE, "continuous": JointKind.REVOLUTE,
              "prismatic": JointKind.PRISMATIC, HELICAL: JointKind.HELICAL}


def snapped(a) -> np.ndarray:
    """Entries within SNAP of an integer made that integer (as _number does for the symbols)."""
    a = np.array(a, dtype=float)
    near = np.abs(a - np.round(a)) < SNAP
    a[near] = np.round(a[near])
    return a


def axis_rotation(axis, angle: float) -> np.ndarray:
    """Rot(u, angle) by Rodrigues' formula."""
    x = np.asarray(axis, float)
    cross = np.array([[0, -x[2], x[1]], [x[2], 0, -x[0]], [-x[1], x[0], 0]])
    return math.cos(angle) * np.eye(3) + math.sin(angle) * cross \
        + (1 - math.cos(angle)) * np.outer(x, x)


__all__ = ["FREE_SLIDES", "FREE_TURNS", "HELICAL", "JOINT_KIND", "MOVABLE", "SNAP",
           "axis_rotation", "carries_nothing", "numeric_tree", "snapped"]
