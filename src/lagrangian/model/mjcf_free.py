"""An MJCF free joint (``<freejoint>``, ``<joint type="free">``), in one of two layouts.

By default MuJoCo's own, so a state moves between MuJoCo and us unchanged: q = [x, y, z (m, the
body's origin in world axes), qw, qx, qy, qz], v = [the origin's velocity in world axes (m/s),
the body's angular velocity in its own axes (rad/s)], the generalized force [world force (N),
moment in body axes (N m)]. Kinematically that is exactly three prismatic joints along the
world's x, y and z from the ground (massless bodies between them) and then a ball joint at
their end with no offset: JointKind.FREE, written as those joints, so every backend moves it
as it moves slides and balls. Its coordinates are ``<joint>_x, _y, _z`` and the ball's
``<joint>_qw .. _qz`` (velocities ``<joint>_wx .. _wz``, model/mjcf_ball.py); the slides'
bodies have no frames of their own, the joint's frame is its body's. The state is absolute:
the file's pos and quat of the body are only MuJoCo's qpos0.

With ``floating_base`` it is the tree's free flyer instead (a floating base, Pinocchio's layout:
x y z, qx qy qz qw and the velocity in body axes; model/mjcf_state.py converts MuJoCo's), for
the centroidal and floating-base tools.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .mjcf_ball import AXES, ball_joint

LOSSES = ("damping", "frictionloss", "armature", "stiffness")


def free_joint(reader, name: str, body: str, parent: str, field: str, attrs, only: bool):
    """Write a free joint into the reader's URDF (module docstring); the (link, frame) that
    follow, as _Reader._joint returns them."""
    if reader.floating:
        return _floating(reader, name, body, parent, field, attrs, only)
    if parent != "world" or not only:
        raise reader.error("a free joint must be the only joint of a body at the top of the "
                           "worldbody (MuJoCo's rule)", field)
    _no_losses(reader, field, attrs)
    if attrs.get("align", "false") not in ("false", "auto"):  # it would move the body's frame
        raise reader.error("align on a free joint is not supported (yet)", f"{field}.align")
    slides = tuple(f"{name}_{a}" for a in AXES)
    for taken in (name, *slides):
        if reader.named(taken):
            raise reader.error(f"two joints are named '{taken}'", field)
    link = parent
    for axis, slide in zip(np.eye(3), slides, strict=True):
        # along the world's axes from the ground: the slides' rates are the world velocity
        child = reader._fresh_link(f"{body}_{slide}_slide")
        reader._urdf_joint(slide, "prismatic", link, child, np.eye(4), axis)
        link = child
    reader.slides[name] = slides
    # the ball at the slides' end, no offset: its quaternion and body-axes rate are MuJoCo's
    return ball_joint(reader, name, body, link, np.eye(4), field, {}, last=True)


def _floating(reader, name: str, body: str, parent: str, field: str, attrs, only: bool):
    """With floating_base: the tree's free flyer, in its own (Pinocchio's) layout."""
    if parent != "world" or not only:
        raise reader.error("with floating_base, a free joint must be the only joint of the "
                           "one body at the top of the worldbody (the floating base)", field)
    if reader.free is not None:
        raise reader.error("with floating_base the model has one free joint, the floating "
                           "base (load without floating_base for several, in MuJoCo's layout)",
                           field)
    if reader.joint_names or reader.balls:
        raise reader.error("the floating base must come first in the worldbody", field)
    _no_losses(reader, field, attrs)
    reader.free = name
    link = reader._fresh_link(body)
    # the free flyer's state is the body's placement: the file's pos and quat are only
    # MuJoCo's default qpos0
    reader._urdf_joint(name, "floating", "world", link, np.eye(4))
    return link, np.eye(4)


def _no_losses(reader, field: str, attrs) -> None:
    for key in LOSSES:  # <joint type="free" ...>
        if reader.numbers(attrs.get(key, "0"), 1, f"{field}.{key}")[0] != 0:
            raise reader.error(f"{key} on a free joint is not supported (yet)",
                               f"{field}.{key}")


def with_free_joints(model, slides: dict[str, tuple[str, str, str]]):
    """The model (its balls merged) with each free joint's slides made plain coordinates of
    the tree: no actuator (a free joint has none here), no frames on their massless bodies."""
    if not slides:
        return model
    tree = model.kinematic_tree
    names = {s for three in slides.values() for s in three}
    coordinate_of = {joint: c for c, joint in model.source_names}
    coordinates = {coordinate_of[s] for s in names}
    hidden = {i for i, j in enumerate(tree.joints) if j.name in names}
    actuators = tuple(None if c in coordinates else a
                      for c, a in zip(tree.velocity_coordinates, tree.actuators, strict=True))
    merged = replace(tree, actuators=actuators, mujoco_free=tuple(slides),
                     frames=tuple(f for f in tree.frames if f.body not in hidden))
    taus = {f"tau_{c}" for c in coordinates}
    return replace(model, kinematic_tree=merged,
                   parameters=tuple(p for p in model.parameters if p.name not in taus),
                   generalized_forces=tuple((c, f) for c, f in model.generalized_forces
                                            if c not in coordinates),
                   source_ratings=tuple(r for r in model.source_ratings
                                        if r[0] not in coordinates),
                   source_dynamics=tuple(r for r in model.source_dynamics
                                         if r[0] not in coordinates))


__all__ = ["free_joint", "with_free_joints"]
