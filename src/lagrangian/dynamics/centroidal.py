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


def _motion_cross(V, S):
    """[v; w] x [v'; w'] for (N, 6) rows."""
    v, w, sv, sw = V[:, :3], V[:, 3:], S[:, :3], S[:, 3:]
    return np.concatenate([np.cross(w, sv) + np.cross(v, sw), np.cross(w, sw)], axis=1)


def spatial_motion(kinematics, Q: np.ndarray, V: np.ndarray, bodies) -> list[tuple]:
    """Each body's spatial velocity and its acceleration at q_ddot = 0 (N, 6 each: at the
    world's origin, world axes; m/s, rad/s; m/s^2, rad/s^2)."""
    tree = kinematics.tree
    count = len(Q)
    out: list[tuple[np.ndarray, np.ndarray]] = []
    for k, joint in enumerate(tree.joints):
        R, o = bodies[k]
        s_w, s_v = kinematics._models[k].subspace(joint.axis)
        S = np.zeros((count, 6))
        if s_w is not None:
            w = R @ np.array(s_w)
            S[:, 3:] = w
            S[:, :3] = np.cross(o, w)  # the world origin's velocity: w x (0 - o)
        if s_v is not None:
            S[:, :3] += R @ np.array(s_v)
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
    p_dot = velocity[:, :3] + np.cross(w, p)
    p_ddot = drift[:, :3] + np.cross(w_dot, p) + np.cross(w, p_dot)
    if reference == "local":
        Rt = np.swapaxes(R, -1, -2)
        p_ddot, w_dot = (Rt @ p_ddot[..., None])[..., 0], (Rt @ w_dot[..., None])[..., 0]
    elif reference == "world":  # the point at the world's origin: p_ddot - w_dot x p - w x (w x p)
        p_ddot = p_ddot - np.cross(w_dot, p) - np.cross(w, np.cross(w, p))
    return np.concatenate([p_ddot, w_dot], axis=1).reshape(batch + (6,))


def centroidal_momentum_matrix(kinematics, q) -> np.ndarray:
    """A_g with h_g = A_g q_dot, (..., 6, n): linear momentum (kg m/s per unit rate) and angular
    momentum about the centre of mass (kg m^2/s), world axes (Pinocchio's ccrba)."""
    Q, batch = kinematics._q(q)
    bodies = kinematics._bodies(Q)
    kinematics._moving_mass()  # refused in one line without moving mass
    centre = kinematics.center_of_mass(Q)
    A = np.zeros((len(Q), 6, kinematics.n))
    for k, (joint, (R, p)) in enumerate(zip(kinematics.tree.joints, bodies, strict=True)):
        if joint.mass <= 0:
            continue
        m, h = joint.mass, np.array(joint.first_moment)
        c = h / m
        # inertia about the body's centre of mass, body axes: J_O - m (|c|^2 1 - c c^T)
        inertia = np.array(joint.inertia) - m * (c @ c * np.eye(3) - np.outer(c, c))
        point = p + R @ c
        J = kinematics._point_jacobian(Q, bodies, k, point)
        linear = m * J[:, :3]
        A[:, :3] += linear
        A[:, 3:] += (R @ inertia @ np.swapaxes(R, -1, -2)) @ J[:, 3:]
        A[:, 3:] += np.cross((point - centre)[:, :, None], linear, axisa=1, axisb=1, axisc=1)
    return A.reshape(batch + (6, kinematics.n))


__all__ = ["centroidal_momentum_matrix", "jacobian_dot_times_v", "spatial_motion"]
