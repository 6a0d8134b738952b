"""Velocity-level kinematics of a robot's tree beyond the Jacobian, batched over states, in
Pinocchio's conventions: a frame's classical acceleration drift J_dot q_dot (the acceleration at
q_ddot = 0, as getFrameClassicalAcceleration with a = 0) and the centroidal momentum matrix A_g
(h_g = A_g q_dot: linear momentum and angular momentum about the centre of mass, world axes, as
ccrba).

Spatial velocities are taken at the world's origin in world axes, V = [v_O; w] (v_O: the
velocity of the body point passing the origin): V_k = V_parent + S_k theta_dot_k, and at
q_ddot = 0 the spatial acceleration A_k = A_parent + (V_k x S_k) theta_dot_k, with
[v; w] x [v'; w'] = [w x v' + v x w'; w x w']. A point p of the body then has p_dot =
v_O + w x p and p_ddot = a_O + w_dot x p + w x p_dot. A floating base's free flyer gives six
columns (S = 1 in the base's axes, world_columns), a ball joint three (S = 1 on the angular
rows, its body's axes); each S moves with its own body (d/dt S = V x S), so at q_ddot = 0 the
drift it adds is V x (S v), as a one-number joint's.
"""

from __future__ import annotations

import numpy as np

from ...errors import InputError
from ...kinds import JointKind
from ..tree.joint_models import ONE_DOF
from ..tree.numbers import batch_shape, float_array
from .recursions import _cross, _dot

REFERENCES = ("world", "local", "local_world_aligned")


def check_reference(reference: str) -> None:
    """A frame Jacobian's reference is one of REFERENCES, else one line naming it."""
    if reference not in REFERENCES:
        raise InputError(f"unknown reference '{reference}'; use one of "
                         f"{', '.join(REFERENCES)}", field="reference")


# the joints these walks take: those, a free flyer (six columns) and a ball joint (three)
WALKED = (*ONE_DOF, JointKind.FREE_FLYER, JointKind.SPHERICAL)


def require_known_joints(tree, what: str, field: str = "q") -> None:
    """Refused in one line for a tree with a joint these walks do not know (their columns
    would be miscounted): revolute, prismatic, helical, ball and free flyer are known."""
    odd = sorted({str(j.kind) for j in tree.joints if j.kind not in WALKED})
    if odd:
        raise InputError(f"{what} of a tree with a {', '.join(odd)} joint: not yet (revolute, "
                         "prismatic, helical, ball and free flyer only)", field=field)


def world_columns(kinematics, k: int, joint, body) -> tuple[np.ndarray, list[int]]:
    """Joint k's motion subspace at the world's origin in world axes, (N, 6, c) with linear
    rows first and the multiplier in, and the c velocity numbers it drives: a free flyer's six
    (S = 1 in its body's axes: [R e; 0] and [p x R e; R e]; the base's, or one below the
    root), a ball joint's three (S = [0; 1] in its body's axes: [o x R e; R e]), else the
    joint's one column."""
    R, o = body
    if joint.kind == JointKind.SPHERICAL:
        S = np.zeros((len(o), 6, 3))
        S[:, 3:] = R
        S[:, :3] = np.cross(o[:, :, None], R, axisa=1, axisb=1, axisc=1)
        first = kinematics.tree.base_nv + kinematics.tree.velocity_index(joint.coordinate)
        return S, list(range(first, first + 3))
    if joint.kind == JointKind.FREE_FLYER:
        S = np.zeros((len(o), 6, 6))
        S[:, :3, :3] = R
        S[:, 3:, 3:] = R
        S[:, :3, 3:] = np.cross(o[:, :, None], R, axisa=1, axisb=1, axisc=1)
        if joint.coordinate < 0:  # the floating base's six
            return S, list(range(6))
        first = kinematics.tree.base_nv + kinematics.tree.velocity_index(joint.coordinate)
        return S, list(range(first, first + 6))  # a free flyer's below the root
    s_v, s_w = _world_subspace(kinematics, k, joint, body)
    S = np.zeros((len(o), 6, 1))
    S[:, :3, 0] = s_v
    if s_w is not None:
        S[:, 3:, 0] = s_w
    return joint.multiplier * S, [kinematics.tree.base_nv
                                  + kinematics.tree.velocity_index(joint.coordinate)]


def velocity_array(kinematics, v, field: str = "v") -> np.ndarray:
    """v as an array of nv numbers along the last axis, else one line naming ``field``."""
    from ..tree.free_flyer import BASE_VELOCITY

    v = float_array(v, field)
    if v.ndim == 0 or v.shape[-1] != kinematics.n:
        tree = kinematics.tree
        names = (BASE_VELOCITY if tree.floating_base else ()) + tuple(tree.coordinates)
        shape = "()" if v.ndim == 0 else str(v.shape)
        raise InputError(f"expected {kinematics.n} values ({', '.join(names)}) along the last "
                         f"axis, got shape {shape}", field=field)
    return v


def _motion_cross(V, S):
    """[v; w] x [v'; w'] for (N, 6) rows."""
    v, w, sv, sw = V[:, :3], V[:, 3:], S[:, :3], S[:, 3:]
    return np.concatenate([_cross(w, sv) + _cross(v, sw), _cross(w, sw)], axis=1)


def spatial_motion(kinematics, Q: np.ndarray, V: np.ndarray, bodies) -> list[tuple]:
    """Each body's spatial velocity and its acceleration at q_ddot = 0 (N, 6 each: at the
    world's origin, world axes; m/s, rad/s; m/s^2, rad/s^2)."""
    tree = kinematics.tree
    count = len(Q)
    out: list[tuple[np.ndarray, np.ndarray]] = []
    for k, joint in enumerate(tree.joints):
        S, index = world_columns(kinematics, k, joint, bodies[k])
        motion = (S @ V[:, index, None])[..., 0]  # S q_dot of this joint
        if joint.parent < 0:
            velocity, drift = motion, np.zeros((count, 6))
        else:
            velocity, drift = out[joint.parent]
            velocity = velocity + motion
        out.append((velocity, drift + _motion_cross(velocity, motion)))
    return out


def jacobian_dot_times_v(kinematics, q, v, frame: str, reference: str) -> np.ndarray:
    """The frame's classical acceleration at q_ddot = 0, [a; w_dot] = J_dot q_dot, (..., 6):
    "local_world_aligned" the origin's acceleration and w_dot in world axes, "local" the same in
    the frame's axes, "world" those of the body point passing the world's origin (Pinocchio's
    getFrameClassicalAcceleration with a = 0)."""
    require_known_joints(kinematics.tree, "J_dot q_dot")
    check_reference(reference)
    n, nq = kinematics.n, len(kinematics.coordinates)
    q, v = kinematics._q(q)[0].reshape(np.shape(q)), velocity_array(kinematics, v)
    batch = batch_shape((q, v), ("q", "v"))
    Q = np.broadcast_to(q, batch + (nq,)).reshape(-1, nq)
    V = np.broadcast_to(v, batch + (n,)).reshape(-1, n)
    bodies = kinematics._bodies(Q)
    R, p = kinematics._frame_pose(Q, bodies, frame)
    body = kinematics._frame(frame).body
    if body < 0:
        return np.zeros(batch + (6,))
    velocity, drift = spatial_motion(kinematics, Q, V, bodies)[body]
    w, w_dot = velocity[:, 3:], drift[:, 3:]
    p_dot = velocity[:, :3] + _cross(w, p)
    p_ddot = drift[:, :3] + _cross(w_dot, p) + _cross(w, p_dot)
    if reference == "local":
        Rt = np.swapaxes(R, -1, -2)
        p_ddot, w_dot = (Rt @ p_ddot[..., None])[..., 0], (Rt @ w_dot[..., None])[..., 0]
    elif reference == "world":  # the point at the world's origin: p_ddot - w_dot x p - w x (w x p)
        p_ddot = p_ddot - _cross(w_dot, p) - _cross(w, _cross(w, p))
    return np.concatenate([p_ddot, w_dot], axis=1).reshape(batch + (6,))


def centroidal_momentum_matrix(kinematics, q) -> np.ndarray:
    """A_g with h_g = A_g q_dot, (..., 6, n): linear momentum (kg m/s per unit rate) and angular
    momentum about the centre of mass (kg m^2/s), world axes (Pinocchio's ccrba).

    By composite bodies: each subtree's mass M, first moment h and inertia I_O about the world's
    origin (world axes) summed from the leaves up; a unit rate along S = [s_v; s_w] (at the
    origin) gives the subtree the momentum [M s_v + s_w x h; h x s_v + I_O s_w]; then the
    angular rows are moved to the centre of mass G: k_G = k_O - G x l."""
    require_known_joints(kinematics.tree, "the centroidal momentum matrix")
    Q, batch = kinematics._q(q)
    kinematics._moving_mass()  # refused in one line without moving mass
    bodies = kinematics._bodies(Q)
    joints = kinematics.tree.joints
    eye = np.eye(3)
    mass = [j.mass for j in joints]
    first, inertia = [], []
    for joint, (R, p) in zip(joints, bodies, strict=True):
        m = joint.mass
        hr = (R @ np.array(joint.first_moment)[:, None])[..., 0]
        ph, pp = _dot(p, hr)[:, None, None], _dot(p, p)[:, None, None]
        outer = p[:, :, None] * hr[:, None, :]
        # J_O = R J R^T + m (|p|^2 1 - p p^T) + 2 (p.h) 1 - p h^T - h p^T (h turned into world)
        inertia.append(R @ np.array(joint.inertia) @ np.swapaxes(R, -1, -2)
                       + m * (pp * eye - p[:, :, None] * p[:, None, :])
                       + 2.0 * ph * eye - outer - np.swapaxes(outer, -1, -2))
        first.append(hr + m * p)
    for k in reversed(range(len(joints))):
        parent = joints[k].parent
        if parent >= 0:
            mass[parent] += mass[k]
            first[parent] = first[parent] + first[k]
            inertia[parent] = inertia[parent] + inertia[k]
    A = np.zeros((len(Q), 6, kinematics.n))
    for k, joint in enumerate(joints):
        S, index = world_columns(kinematics, k, joint, bodies[k])
        s_v, s_w = np.swapaxes(S[:, :3], 1, 2), np.swapaxes(S[:, 3:], 1, 2)  # (N, c, 3)
        h = first[k][:, None, :]
        linear = mass[k] * s_v + _cross(s_w, h)
        angular = _cross(h, s_v) + s_w @ np.swapaxes(inertia[k], 1, 2)
        A[:, :3, index] += np.swapaxes(linear, 1, 2)
        A[:, 3:, index] += np.swapaxes(angular, 1, 2)
    total = sum(mass[k] for k, j in enumerate(joints) if j.parent < 0)
    centre = sum(first[k] for k, j in enumerate(joints) if j.parent < 0) / total
    A[:, 3:] -= np.cross(centre[:, :, None], A[:, :3], axisa=1, axisb=1, axisc=1)
    return A.reshape(batch + (6, kinematics.n))


def _world_subspace(kinematics, k: int, joint, body):
    """S of joint k at the world's origin in world axes: (s_v (N, 3), s_w (N, 3) or None)."""
    R, o = body
    s_w, s_v = kinematics._models[k].subspace(joint.axis, joint.pitch)
    w = None if s_w is None else R @ np.array(s_w)
    linear = np.zeros(o.shape) if w is None else _cross(o, w)  # the origin's: w x (0 - o)
    if s_v is not None:
        linear = linear + R @ np.array(s_v)
    return linear, w


__all__ = ["centroidal_momentum_matrix", "check_reference", "jacobian_dot_times_v", "ONE_DOF",
           "REFERENCES", "require_known_joints", "spatial_motion", "velocity_array", "WALKED",
           "world_columns"]
