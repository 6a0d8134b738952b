"""Velocity-level kinematics of a robot's tree beyond the Jacobian, batched over states, in
Pinocchio's conventions: a frame's classical acceleration drift J_dot q_dot (the acceleration at
q_ddot = 0, as getFrameClassicalAcceleration with a = 0) and the centroidal momentum matrix A_g
(h_g = A_g q_dot: linear momentum and angular momentum about the centre of mass, world axes, as
ccrba).

Spatial velocities are taken at the world's origin in world axes, V = [v_O; w] (v_O: the
velocity of the body point passing the origin): V_k = V_parent + S_k theta_dot_k, and at
q_ddot = 0 the spatial acceleration A_k = A_parent + (V_k x S_k) theta_dot_k, with
[v; w] x [v'; w'] = [w x v' + v x w'; w x w']. A point p of the body then has p_dot =
v_O + w x p and p_ddot = a_O + w_dot x p + w x p_dot.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..kinds import JointKind
from .recursive_numpy import _cross, _dot

# the joints these walks take: one coordinate each (a floating base's free flyer is six)
ONE_DOF = (JointKind.REVOLUTE, JointKind.PRISMATIC)


def require_fixed_base(tree, what: str, field: str = "q") -> None:
    """Refused in one line for a tree with a joint of more than one coordinate (a floating
    base): these walks give each joint one column, and would be wrong there."""
    if any(JointKind(j.kind) not in ONE_DOF for j in tree.joints):
        raise InputError(f"{what} of a floating base: not yet (a fixed-base robot's only)",
                         field=field)


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
        R, o = bodies[k]
        s_v, s_w = _world_subspace(kinematics, k, joint, (R, o))
        S = np.zeros((count, 6))
        S[:, :3] = s_v
        if s_w is not None:
            S[:, 3:] = s_w
        rate = (joint.multiplier * V[:, joint.coordinate])[:, None]
        if joint.parent < 0:
            velocity, drift = S * rate, np.zeros((count, 6))
        else:
            velocity, drift = out[joint.parent]
            velocity = velocity + S * rate
        out.append((velocity, drift + _motion_cross(velocity, S) * rate))
    return out


def jacobian_dot_times_v(kinematics, q, v, frame: str, reference: str) -> np.ndarray:
    """The frame's classical acceleration at q_ddot = 0, [a; w_dot] = J_dot q_dot, (..., 6):
    "local_world_aligned" the origin's acceleration and w_dot in world axes, "local" the same in
    the frame's axes, "world" those of the body point passing the world's origin (Pinocchio's
    getFrameClassicalAcceleration with a = 0)."""
    from .frames import REFERENCES

    require_fixed_base(kinematics.tree, "J_dot q_dot")
    if reference not in REFERENCES:
        raise InputError(f"unknown reference '{reference}'; use one of "
                         f"{', '.join(REFERENCES)}", field="reference")
    n = kinematics.n
    q, v = kinematics._q(q)[0].reshape(np.shape(q)), kinematics._q(v, "v")[0].reshape(np.shape(v))
    batch = np.broadcast_shapes(q.shape[:-1], v.shape[:-1])
    Q = np.broadcast_to(q, batch + (n,)).reshape(-1, n)
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
    require_fixed_base(kinematics.tree, "the centroidal momentum matrix")
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
        s_v, s_w = _world_subspace(kinematics, k, joint, bodies[k])
        linear = mass[k] * s_v
        angular = _cross(first[k], s_v)
        if s_w is not None:
            linear = linear + _cross(s_w, first[k])
            angular = angular + (inertia[k] @ s_w[..., None])[..., 0]
        A[:, :3, joint.coordinate] += joint.multiplier * linear
        A[:, 3:, joint.coordinate] += joint.multiplier * angular
    total = sum(mass[k] for k, j in enumerate(joints) if j.parent < 0)
    centre = sum(first[k] for k, j in enumerate(joints) if j.parent < 0) / total
    A[:, 3:] -= np.cross(centre[:, :, None], A[:, :3], axisa=1, axisb=1, axisc=1)
    return A.reshape(batch + (6, kinematics.n))


def _world_subspace(kinematics, k: int, joint, body):
    """S of joint k at the world's origin in world axes: (s_v (N, 3), s_w (N, 3) or None)."""
    R, o = body
    s_w, s_v = kinematics._models[k].subspace(joint.axis)
    w = None if s_w is None else R @ np.array(s_w)
    linear = np.zeros(o.shape) if w is None else _cross(o, w)  # the origin's: w x (0 - o)
    if s_v is not None:
        linear = linear + R @ np.array(s_v)
    return linear, w


__all__ = ["centroidal_momentum_matrix", "jacobian_dot_times_v", "spatial_motion"]
