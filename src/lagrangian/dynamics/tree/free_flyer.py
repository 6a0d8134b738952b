"""The free-flyer joint of a floating base (Pinocchio's JointModelFreeFlyer): the base body moves
freely in space, nq = 7 configuration numbers and nv = 6 velocity numbers.

Configuration, in Pinocchio's layout: the base's origin (x, y, z) in the world (m), then its
orientation as a unit quaternion (qx, qy, qz, qw). Velocity: the base's spatial velocity in its
own axes, linear then angular, (v, w) with v = R^T p_dot (m/s) and [w]x = R^T R_dot (rad/s). Its
generalized force is the wrench on the base in its own axes, force then moment (N, N m).

The configuration is on a manifold: q (+) v dt = (p, R) exp6(v dt) (integrate), and its inverse
(difference); a quaternion whose norm is off 1 by more than QUATERNION_TOLERANCE is refused, a
nearer one used normalized (float32 data, or a controller's rounding, reads as meant).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...kinds import JointKind

# the quaternions' numbers are the model's (simulation integrates them too): re-exported here
from ...model.quaternions import QUATERNION_TOLERANCE, check_quaternions, quaternion_matrix

BASE_CONFIGURATION = ("base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz", "base_qw")
BASE_VELOCITY = ("base_vx", "base_vy", "base_vz", "base_wx", "base_wy", "base_wz")
# The six columns of S: linear velocity e_k per unit (k = 0..2), then angular e_k.
_UNIT = np.eye(3)


@dataclass(frozen=True)
class FreeFlyerModel:
    """The free-flyer joint: S = 1 (6 x 6) in the base's axes, linear rows first."""

    kind: JointKind = JointKind.FREE_FLYER
    nq: int = 7
    nv: int = 6

    def columns(self) -> list[tuple[np.ndarray | None, np.ndarray | None]]:
        """S as six (s_w, s_v) columns (None: zero), in the order of the velocity."""
        return [(None, _UNIT[k]) for k in range(3)] + [(_UNIT[k], None) for k in range(3)]

    def placement_arrays(self, R0, t0, q7):
        """R (N, 3, 3) and p (N, 3) of the base in its parent for configurations q7 (N, 7)."""
        R = quaternion_matrix(q7[:, 3:7])
        return R0 @ R, t0 + q7[:, :3] @ np.asarray(R0).T


def matrix_quaternion(R) -> np.ndarray:
    """The unit quaternion (..., 4), x y z w with w >= 0, of rotations R (..., 3, 3)."""
    R = np.asarray(R, dtype=float)
    trace = np.trace(R, axis1=-2, axis2=-1)
    candidates = np.stack([  # 4 x (x, y, z, w), each accurate where its own entry is largest
        np.stack([1 + R[..., 0, 0] - R[..., 1, 1] - R[..., 2, 2], R[..., 0, 1] + R[..., 1, 0],
                  R[..., 0, 2] + R[..., 2, 0], R[..., 2, 1] - R[..., 1, 2]], -1),
        np.stack([R[..., 0, 1] + R[..., 1, 0], 1 - R[..., 0, 0] + R[..., 1, 1] - R[..., 2, 2],
                  R[..., 1, 2] + R[..., 2, 1], R[..., 0, 2] - R[..., 2, 0]], -1),
        np.stack([R[..., 0, 2] + R[..., 2, 0], R[..., 1, 2] + R[..., 2, 1],
                  1 - R[..., 0, 0] - R[..., 1, 1] + R[..., 2, 2], R[..., 1, 0] - R[..., 0, 1]], -1),
        np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                  R[..., 1, 0] - R[..., 0, 1], 1 + trace], -1)], -2)
    diagonal = np.stack([R[..., 0, 0], R[..., 1, 1], R[..., 2, 2], trace], -1)
    best = np.take_along_axis(candidates, np.argmax(diagonal, -1)[..., None, None], -2)[..., 0, :]
    best = best / np.linalg.norm(best, axis=-1, keepdims=True)
    return np.where(best[..., 3:] < 0, -best, best)


def _skew(x) -> np.ndarray:
    out = np.zeros(x.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2], out[..., 1, 2] = -x[..., 2], x[..., 1], -x[..., 0]
    out[..., 1, 0], out[..., 2, 0], out[..., 2, 1] = x[..., 2], -x[..., 1], x[..., 0]
    return out


def exp6(twist) -> tuple[np.ndarray, np.ndarray]:
    """The rigid motion (R, p) reached moving at the constant body twist (v, w) (..., 6) for a
    unit time: R = exp([w]x), p = V(w) v (SE(3)'s exponential)."""
    v, w = twist[..., :3], twist[..., 3:]
    angle = np.linalg.norm(w, axis=-1)[..., None, None]
    W = _skew(w)
    W2 = W @ W
    small = angle < 1e-6
    a = np.where(small, 1.0, angle)  # Taylor series below 1e-6 rad (no 0/0)
    sin_term = np.where(small, 1 - angle ** 2 / 6, np.sin(a) / a)
    cos_term = np.where(small, 0.5 - angle ** 2 / 24, (1 - np.cos(a)) / a ** 2)
    third = np.where(small, 1 / 6 - angle ** 2 / 120, (a - np.sin(a)) / a ** 3)
    eye = np.eye(3)
    R = eye + sin_term * W + cos_term * W2
    V = eye + cos_term * W + third * W2
    return R, (V @ v[..., None])[..., 0]


def log6(R, p) -> np.ndarray:
    """The body twist (v, w) (..., 6) with exp6(v, w) = (R, p): the inverse of exp6."""
    w = _log3(R)
    angle = np.linalg.norm(w, axis=-1)[..., None, None]
    W = _skew(w)
    small = angle < 1e-6
    a = np.where(small, 1.0, angle)
    # V^-1 = 1 - W/2 + (1/a^2)(1 - a sin a / (2 (1 - cos a))) W^2
    coefficient = np.where(small, 1 / 12 + angle ** 2 / 720,
                           (1 - a * np.sin(a) / (2 * (1 - np.cos(a)))) / a ** 2)
    V_inv = np.eye(3) - 0.5 * W + coefficient * (W @ W)
    return np.concatenate([(V_inv @ p[..., None])[..., 0], w], -1)


def _log3(R) -> np.ndarray:
    """w with exp([w]x) = R, |w| <= pi (through the quaternion: accurate near 0 and pi)."""
    quaternion = matrix_quaternion(R)
    vector, scalar = quaternion[..., :3], quaternion[..., 3]
    norm = np.linalg.norm(vector, axis=-1)
    angle = 2 * np.arctan2(norm, scalar)
    factor = np.where(norm < 1e-12, 2.0 / np.where(scalar == 0, 1.0, scalar),
                      angle / np.where(norm < 1e-12, 1.0, norm))
    return vector * factor[..., None]


def checking_quaternions(function):
    """``function(q, ...)`` refusing a base quaternion of the wrong norm first, in one line
    (a compiled function that does not check it itself)."""
    low, high = (1 - QUATERNION_TOLERANCE) ** 2, (1 + QUATERNION_TOLERANCE) ** 2

    def checked(q, *rest):
        Q = q if q.__class__ is np.ndarray else np.asarray(q, dtype=float)
        if Q.ndim == 1 and Q.shape[0] >= 7:  # one state: |q|^2 in plain floats (a microsecond)
            x, y, z, w = Q[3:7].tolist()
            if low <= x * x + y * y + z * z + w * w <= high:
                return function(q, *rest)
        if Q.ndim and Q.shape[-1] >= 7:  # a wrong width is the function's to name
            flat = Q.reshape(-1, Q.shape[-1])
            check_quaternions(flat)
        return function(q, *rest)
    return checked


def integrate(Q: np.ndarray, V: np.ndarray) -> np.ndarray:
    """q (+) v for a flat batch: the base moved by exp6 of its twist v[:6] in its own axes,
    the joints by q + v; the quaternion comes back normalized (w >= 0 not imposed)."""
    R = quaternion_matrix(Q[:, 3:7])
    dR, dp = exp6(V[:, :6])
    out = np.empty_like(Q)
    out[:, :3] = Q[:, :3] + (R @ dp[..., None])[..., 0]
    quaternion = matrix_quaternion(R @ dR)
    # keep the hemisphere of the given quaternion: a run's quaternions stay continuous
    same = np.sum(quaternion * Q[:, 3:7], axis=-1, keepdims=True) >= 0
    out[:, 3:7] = np.where(same, quaternion, -quaternion)
    out[:, 7:] = Q[:, 7:] + V[:, 6:]
    return out


def difference(Q0: np.ndarray, Q1: np.ndarray) -> np.ndarray:
    """v with q0 (+) v = q1 (the inverse of integrate), shape (N, nv)."""
    R0, R1 = quaternion_matrix(Q0[:, 3:7]), quaternion_matrix(Q1[:, 3:7])
    R0t = np.swapaxes(R0, -1, -2)
    twist = log6(R0t @ R1, (R0t @ (Q1[:, :3] - Q0[:, :3])[..., None])[..., 0])
    return np.concatenate([twist, Q1[:, 7:] - Q0[:, 7:]], -1)


__all__ = ["BASE_CONFIGURATION", "BASE_VELOCITY", "QUATERNION_TOLERANCE", "FreeFlyerModel",
           "check_quaternions", "checking_quaternions", "difference", "exp6", "integrate", "log6",
           "matrix_quaternion", "quaternion_matrix"]
