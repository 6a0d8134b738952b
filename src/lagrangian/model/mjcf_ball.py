"""An MJCF ball joint as the kinematic tree's spherical joint, in MuJoCo's layout: its qpos a
unit quaternion w x y z (4 numbers), its qvel the body's angular velocity relative to its parent
in the body's own axes (3 numbers, rad/s), so a state moves between MuJoCo and us unchanged.

The reader writes the ball as three hinges about the anchor's x, y and z axes (two massless links
between them) for the URDF reader, so that the model's symbolic bodies are the same robot in
Euler angles (``<joint>__x``, ``__y``, ``__z``: what derive and the symbolic paths see); then
``with_ball_joints`` merges the three tree bodies into one spherical joint, whose configuration
names are ``<joint>_qw, _qx, _qy, _qz`` and velocity names ``<joint>_wx, _wy, _wz``: the names
that dynamics, kinematics and simulate (its start, stop condition and columns) take, where the
Euler hinges are refused by name. The three hinges' actuator parameters are dropped: a ball
joint has no actuator here.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import ModelError
from ..kinds import JointKind
from .tree import TreeFrame, TreeJoint

AXES = "xyz"


def _transform(translation) -> np.ndarray:
    out = np.eye(4)
    out[:3, 3] = translation
    return out


def ball_joint(reader, name: str, body: str, parent: str, current: np.ndarray, field: str,
               attrs, last: bool):
    """Write a ball joint's three hinges (x, y, z at its anchor) into the reader's URDF; the
    (link, frame) that follow, as _Reader._joint returns them."""
    for key in ("damping", "frictionloss", "armature", "stiffness", "ref", "springref"):
        if float(reader.numbers(attrs.get(key, "0"), 1, f"{field}.{key}")[0]) != 0:
            raise reader.error(f"{key} on a ball joint is not supported (yet)", f"{field}.{key}")
    if attrs.get("limited") == "true" or (attrs.get("limited", "auto") == "auto"
                                          and reader.autolimits and "range" in attrs):
        raise reader.error("a ball joint's range (a cone limit) is not supported (yet)",
                           f"{field}.range")
    if reader.named(name):
        raise reader.error(f"two joints are named '{name}'", field)
    anchor = reader.vector(attrs, "pos", (0, 0, 0), field)
    hinges = tuple(f"{name}__{a}" for a in AXES)
    links = [reader._fresh_link(f"{body}_{name}_{a}") for a in AXES[:2]]
    links.append(reader._fresh_link(body if last else f"{body}_{name}"))
    origins = [current @ _transform(anchor), np.eye(4), np.eye(4)]
    chain = [parent, *links]
    for k in range(3):
        reader._urdf_joint(hinges[k], "continuous", chain[k], chain[k + 1], origins[k],
                           np.eye(3)[k])
    reader.balls[name] = hinges
    return links[-1], _transform(-anchor)


def with_ball_joints(model, balls: dict[str, tuple[str, str, str]], source: str):
    """The model with each ball's three hinge bodies of its tree merged into one spherical
    joint (module docstring); the symbolic bodies (Euler angles) are kept as they are."""
    tree = model.kinematic_tree
    coordinate_of = {joint: name for name, joint in model.source_names}
    helpers = {h for hinges in balls.values() for h in hinges}
    for ball, hinges in balls.items():
        if any(h not in coordinate_of for h in hinges):
            raise ModelError(f"the ball joint '{ball}' cannot be locked or followed by an "
                             "equality (yet)", field=f"joint '{ball}'", source=source)
    joints = list(tree.joints)
    by_name = {j.name: i for i, j in enumerate(joints)}
    first_of = {by_name[hinges[0]]: ball for ball, hinges in balls.items()}
    dropped = {by_name[h] for hinges in balls.values() for h in hinges[:2]}
    last_of = {by_name[hinges[2]]: ball for ball, hinges in balls.items()}
    # the new q and v names and each old coordinate's new q index
    old = tree.coordinates
    names_q, names_v, new_index = [], [], {}
    ball_at = {}
    helper_coordinates = {coordinate_of[h] for h in helpers}
    first_coordinate = {coordinate_of[hinges[0]]: ball for ball, hinges in balls.items()}
    actuators = []
    for c, name in enumerate(old):
        if name in first_coordinate:
            ball = first_coordinate[name]
            ball_at[ball] = len(names_q)
            names_q += [f"{ball}_q{a}" for a in "wxyz"]
            names_v += [f"{ball}_w{a}" for a in AXES]
            actuators += [None, None, None]
        elif name not in helper_coordinates:
            new_index[c] = len(names_q)
            names_q.append(name)
            names_v.append(name)
            actuators.append(tree.actuators[c])
    body_index, kept = {}, []
    for i in range(len(joints)):
        if i in dropped:
            continue
        body_index[i] = len(kept)
        kept.append(i)
    for i in dropped:  # a ball's helper bodies stand for the ball's body
        ball = next(b for b, hinges in balls.items() if joints[i].name in hinges)
        body_index[i] = body_index[by_name[balls[ball][2]]]
    out = []
    for i in kept:
        j = joints[i]
        parent = -1 if j.parent < 0 else body_index[j.parent]
        if i in last_of:
            ball = last_of[i]
            start = joints[by_name[balls[ball][0]]]
            out.append(TreeJoint(
                name=ball, parent=-1 if start.parent < 0 else body_index[start.parent],
                kind=JointKind.SPHERICAL, rotation=start.rotation, translation=start.translation,
                axis=(0.0, 0.0, 1.0), coordinate=ball_at[ball], multiplier=1.0, offset=0.0,
                mass=j.mass, first_moment=j.first_moment, inertia=j.inertia))
            continue
        if i in first_of:
            continue
        coordinate = j.coordinate if j.coordinate < 0 else new_index[j.coordinate]
        out.append(replace(j, parent=parent, coordinate=coordinate))
    # the helpers' frames go (they turn by part of the rotation only)
    frames = tuple(TreeFrame(f.name, -1 if f.body < 0 else body_index[f.body], f.rotation,
                             f.translation) for f in tree.frames
                   if f.name not in helpers and f.body not in dropped)
    by_frame = {f.name: f for f in frames}
    links = tuple(replace(k, body=-1 if k.body < 0 else body_index[k.body]) for k in tree.links)
    for ball, hinges in balls.items():  # the ball's own frame: its body's (at its anchor)
        body = body_index[by_name[hinges[2]]]
        if ball not in by_frame:
            frames += (TreeFrame(ball, body, ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
                                 (0.0, 0.0, 0.0)),)
    merged = replace(tree, joints=tuple(out), coordinates=tuple(names_q),
                     velocities=tuple(names_v), actuators=tuple(actuators), frames=frames,
                     links=links,
                     model_coordinates=tuple(c.name for c in model.coordinates))
    # the hinges' actuator parameters and forces go: a ball joint has none here
    taus = {f"tau_{coordinate_of[h]}" for h in helpers}
    return replace(model, kinematic_tree=merged,
                   parameters=tuple(p for p in model.parameters if p.name not in taus),
                   generalized_forces=tuple((c, f) for c, f in model.generalized_forces
                                            if c not in helper_coordinates),
                   source_names=tuple(p for p in model.source_names if p[1] not in helpers),
                   source_ratings=tuple(r for r in model.source_ratings
                                        if r[0] not in helper_coordinates),
                   source_dynamics=tuple(r for r in model.source_dynamics
                                         if r[0] not in helper_coordinates))


__all__ = ["ball_joint", "with_ball_joints"]
