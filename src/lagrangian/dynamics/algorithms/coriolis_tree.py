"""C(q, v) of a robot's kinematic tree as a matrix, by spatial algebra in world axes
(Pinocchio's computeCoriolisMatrix), for a floating base as for a fixed one, batched over states.

With each body's spatial inertia I_k at the world's origin (world axes, linear rows first), its
velocity V_k there and its Jacobian J_k (columns S of the joints above it, d/dt S = V x S):

    M = sum J_k^T I_k J_k,   C = sum J_k^T (I_k J_dot_k + B_k J_k),
    B_k = 1/2 (V_k x* I_k - I_k V_k x) + 1/2 (I_k V_k) x-bar,

with (f x-bar) V = V x* f. Then C v = sum J_k^T (I_k a_k + V_k x* I_k V_k) = bias - g, and
M_dot - 2C = sum J_k^T (-(I_k V_k) x-bar) J_k + (J_dot^T I J - J^T I J_dot) is skew-symmetric,
in the velocity v of the tree (a floating base's own twist first: nv = n + 6), M_dot along
q (+) v dt. By composite bodies (subtree sums I^c, B^c), for joints a above or at b:
C[a, b] = S_a^T (I^c_b S_dot_b + B^c_b S_b) and C[b, a] = S_b^T (I^c_b S_dot_a + B^c_b S_a).
"""

from __future__ import annotations

import numpy as np

from ..tree.numbers import batch_shape
from .centroidal import require_known_joints, velocity_array, world_columns


def _skew(x: np.ndarray) -> np.ndarray:
    """[x]x for rows x (N, 3)."""
    out = np.zeros(x.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2], out[..., 1, 2] = -x[..., 2], x[..., 1], -x[..., 0]
    out[..., 1, 0], out[..., 2, 0], out[..., 2, 1] = x[..., 2], -x[..., 1], x[..., 0]
    return out


def motion_cross_matrix(V: np.ndarray) -> np.ndarray:
    """V x as a matrix (N, 6, 6) for V = [v; w]: [[w x, v x], [0, w x]]."""
    out = np.zeros(V.shape[:-1] + (6, 6))
    W = _skew(V[..., 3:])
    out[..., :3, :3] = out[..., 3:, 3:] = W
    out[..., :3, 3:] = _skew(V[..., :3])
    return out


def force_bar_matrix(F: np.ndarray) -> np.ndarray:
    """The matrix of V -> V x* F for a wrench F = [f; n] (N, 6, 6): [[0, -[f]x], [-[f]x, -[n]x]]
    (V x* F = [w x f; v x f + w x n]), skew-symmetric."""
    out = np.zeros(F.shape[:-1] + (6, 6))
    fx = _skew(-F[..., :3])
    out[..., :3, 3:] = out[..., 3:, :3] = fx
    out[..., 3:, 3:] = _skew(-F[..., 3:])
    return out


def spatial_inertias(kinematics, bodies) -> list[np.ndarray]:
    """Each body's spatial inertia at the world's origin in world axes (N, 6, 6):
    [[m 1, -[h]x], [[h]x, J_O]] with h its first moment and J_O its inertia about the origin."""
    eye = np.eye(3)
    out = []
    for joint, (R, p) in zip(kinematics.tree.joints, bodies, strict=True):
        m = joint.mass
        hr = R @ np.array(joint.first_moment)
        ph, pp = (p * hr).sum(-1)[:, None, None], (p * p).sum(-1)[:, None, None]
        outer = p[:, :, None] * hr[:, None, :]
        J = (R @ np.array(joint.inertia) @ np.swapaxes(R, -1, -2)
             + m * (pp * eye - p[:, :, None] * p[:, None, :])
             + 2.0 * ph * eye - outer - np.swapaxes(outer, -1, -2))
        H = _skew(hr + m * p)
        inertia = np.zeros((len(p), 6, 6))
        inertia[:, :3, :3] = m * eye
        inertia[:, :3, 3:], inertia[:, 3:, :3], inertia[:, 3:, 3:] = -H, H, J
        out.append(inertia)
    return out


def coriolis_matrix(kinematics, q, v) -> np.ndarray:
    """C(q, v) with C v = bias - g and M_dot - 2C skew-symmetric, (..., nv, nv) (kg m^2/s per
    entry for angles), as Pinocchio's computeCoriolisMatrix (module docstring)."""
    require_known_joints(kinematics.tree, "C(q, v)")
    n, nq = kinematics.n, len(kinematics.coordinates)
    q, v = kinematics._q(q)[0].reshape(np.shape(q)), velocity_array(kinematics, v)
    batch = batch_shape((q, v), ("q", "v"))
    Q = np.broadcast_to(q, batch + (nq,)).reshape(-1, nq)
    V = np.broadcast_to(v, batch + (n,)).reshape(-1, n)
    joints = kinematics.tree.joints
    bodies = kinematics._bodies(Q)
    inertia = spatial_inertias(kinematics, bodies)
    columns, rates, velocity, B = [], [], [], []
    for k, joint in enumerate(joints):
        S, index = world_columns(kinematics, k, joint, bodies[k])
        ov = (S @ V[:, index, None])[..., 0]
        if joint.parent >= 0:
            ov = ov + velocity[joint.parent]
        cross = motion_cross_matrix(ov)
        columns.append((S, index))
        rates.append(cross @ S)  # d/dt S = V x S: S moves with its body
        velocity.append(ov)
        star = -np.swapaxes(cross, -1, -2)  # V x* = -(V x)^T
        I = inertia[k]
        B.append(0.5 * (star @ I - I @ cross)
                 + 0.5 * force_bar_matrix((I @ ov[..., None])[..., 0]))
    C = np.zeros((len(Q), n, n))
    composite_I, composite_B = list(inertia), B
    for b in reversed(range(len(joints))):
        S_b, index_b = columns[b]
        I_c, B_c = composite_I[b], composite_B[b]
        own = I_c @ rates[b] + B_c @ S_b  # (N, 6, c_b)
        tail = np.swapaxes(S_b, -1, -2) @ I_c  # S_b^T I^c_b
        tail_B = np.swapaxes(S_b, -1, -2) @ B_c
        a = b
        while a >= 0:
            S_a, index_a = columns[a]
            # C[a, b] = S_a^T (I^c_b S_dot_b + B^c_b S_b)
            C[:, np.array(index_a)[:, None], np.array(index_b)] += \
                np.swapaxes(S_a, -1, -2) @ own
            if a != b:  # C[b, a] = S_b^T (I^c_b S_dot_a + B^c_b S_a)
                C[:, np.array(index_b)[:, None], np.array(index_a)] += \
                    tail @ rates[a] + tail_B @ S_a
            a = joints[a].parent
        parent = joints[b].parent
        if parent >= 0:
            composite_I[parent] = composite_I[parent] + I_c
            composite_B[parent] = composite_B[parent] + B_c
    return C.reshape(batch + (n, n))


__all__ = ["coriolis_matrix", "force_bar_matrix", "motion_cross_matrix", "spatial_inertias"]
