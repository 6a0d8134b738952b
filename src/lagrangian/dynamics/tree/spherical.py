"""The spherical (ball) joint of a kinematic tree, MuJoCo's ball joint: the body turns freely
about the joint's origin, nq = 4 configuration numbers and nv = 3 velocity numbers.

Configuration: a unit quaternion in MuJoCo's order (qw, qx, qy, qz), R = R_0 R(q) (body ->
parent axes), the origin fixed at t_0. Velocity: the body's angular velocity relative to its
parent, in the body's own axes (rad/s), [w]x = R(q)^T R(q)_dot; its generalized force is the
moment on the body about the joint's origin in those axes (N m). So S = (1, 0): three angular
columns e_x, e_y, e_z of the body's axes.

On the manifold: q (+) v dt = q exp(v dt) (integrate, the rotation turned in its own axes) and
its inverse (difference); a quaternion whose norm is off 1 by more than QUATERNION_TOLERANCE
is refused in one line naming the joint, a nearer one used normalized.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...kinds import JointKind
from ...model.quaternions import QUATERNION_TOLERANCE, check_quaternions, quaternion_matrix
from ...model.tree import refuse_ball_joints

_UNIT = np.eye(3)


@dataclass(frozen=True)
class SphericalModel:
    """The ball joint: S = three unit angular columns in the body's axes."""

    kind: JointKind = JointKind.SPHERICAL
    nq: int = 4
    nv: int = 3

    def columns(self) -> list[tuple[np.ndarray, None]]:
        """S as three (s_w, s_v) columns (None: zero), in the order of the velocity."""
        return [(_UNIT[k], None) for k in range(3)]

    def placement_arrays(self, R0, t0, q4):
        """R (N, 3, 3) and p (3,) of the body in its parent for quaternions q4 (N, 4), w first."""
        return R0 @ wxyz_matrix(q4), t0


def wxyz_matrix(quaternion) -> np.ndarray:
    """The rotation (..., 3, 3) of quaternions (..., 4) in MuJoCo's order w, x, y, z, normalized."""
    quaternion = np.asarray(quaternion, dtype=np.result_type(quaternion, float))
    return quaternion_matrix(np.concatenate([quaternion[..., 1:4], quaternion[..., :1]], -1))


def ball_slices(tree) -> list[tuple[str, int, int]]:
    """(name, q index, v index) of each ball joint's first number, in the full q and v."""
    return [(j.name, tree.base_nq + j.coordinate,
             tree.base_nv + tree.velocity_index(j.coordinate)) for j in tree.spherical]


def quaternion_slices(tree) -> list[tuple[str, str, int, str]]:
    """(name, what, index, order) of each quaternion among the joints' numbers, in the full q:
    a ball joint's (w x y z) and a free flyer's below the root (x y z w, after x, y, z)."""
    free = [(j.name, "floating joint", tree.base_nq + j.coordinate + 3, "x y z w")
            for j in tree.free_joints]
    free_joints = getattr(tree, "mujoco_free", ())  # MJCF free joints: a ball at world slides
    return [(name, "free joint" if name in free_joints else "ball joint", iq, "w x y z")
            for name, iq, _ in ball_slices(tree)] + free


def check_tree_quaternions(tree, Q: np.ndarray, field: str = "q") -> None:
    """Refuse, in one line, a flat batch of configurations (N, nq) whose base quaternion or any
    ball joint's quaternion has a norm off 1 by more than QUATERNION_TOLERANCE, naming the
    joint and the state; a state not all finite is not refused (its rows are NaN)."""
    if tree.floating_base:
        check_quaternions(Q, field=field)
    if not tree.quaternion_joints:
        return
    with np.errstate(invalid="ignore", over="ignore"):
        finite = np.isfinite(Q).all(axis=-1)
        for name, what, iq, order in quaternion_slices(tree):
            norms = np.linalg.norm(Q[:, iq:iq + 4], axis=-1)
            bad = np.flatnonzero(finite & (np.abs(norms - 1.0) > QUATERNION_TOLERANCE))
            if bad.size:
                raise InputError(
                    f"the {what} '{name}' quaternion (q[{iq}:{iq + 4}], {order}) has norm "
                    f"{norms[bad[0]]:.9g}" + (f" in state {bad[0]}" if len(Q) > 1 else "")
                    + f"; a unit quaternion is needed (|q| within {QUATERNION_TOLERANCE:g} of 1)",
                    field=field)


def unit_ball_quaternions(tree, Q: np.ndarray) -> np.ndarray:
    """Q (N, nq) with each ball quaternion within the tolerance but not within rounding of 1
    made unit (as the base's, recursive._unit_quaternions): a unit one keeps its bits."""
    out = Q
    for _, _, iq, _ in quaternion_slices(tree):
        with np.errstate(over="ignore", invalid="ignore"):  # a state beyond 1e154: its NaN row
            norms = np.sqrt((out[:, iq:iq + 4] ** 2).sum(axis=-1))
        edge = np.isfinite(out).all(axis=-1) & ~(np.abs(norms - 1.0) <= QUATERNION_TOLERANCE)
        if edge.any():
            out = out.copy() if out is Q else out
            out[edge, iq:iq + 4] /= norms[edge, None]
    return out


def ball_quaternions_unit(tree, Q: np.ndarray) -> bool:
    """Whether every finite state's ball quaternions are within the tolerance of unit norm."""
    finite = np.isfinite(Q).all(axis=-1)
    for _, _, iq, _ in quaternion_slices(tree):
        norms = np.sqrt((Q[:, iq:iq + 4] ** 2).sum(axis=-1))
        if (finite & ~(np.abs(norms - 1.0) <= QUATERNION_TOLERANCE)).any():
            return False
    return True


def _multiply(a, b) -> np.ndarray:
    """The quaternion product a b (..., 4), w first."""
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw],
                    -1)


def exp_quaternion(w) -> np.ndarray:
    """The unit quaternion (..., 4), w first, of the rotation exp([w]x) (w (..., 3) in rad)."""
    angle = np.linalg.norm(w, axis=-1, keepdims=True)
    small = angle < 1e-6
    half = 0.5 * np.where(small, 1.0, angle)
    factor = np.where(small, 0.5 - angle ** 2 / 48, np.sin(half) / np.where(small, 1.0, angle))
    return np.concatenate([np.where(small, 1 - angle ** 2 / 8, np.cos(half)), factor * w], -1)


def log_quaternion(quaternion) -> np.ndarray:
    """w (..., 3), |w| <= pi, with exp_quaternion(w) = +-quaternion (w first)."""
    quaternion = np.where(quaternion[..., :1] < 0, -quaternion, quaternion)
    vector, scalar = quaternion[..., 1:], quaternion[..., 0]
    norm = np.linalg.norm(vector, axis=-1)
    angle = 2 * np.arctan2(norm, scalar)
    factor = np.where(norm < 1e-12, 2.0 / np.where(scalar == 0, 1.0, scalar),
                      angle / np.where(norm < 1e-12, 1.0, norm))
    return vector * factor[..., None]


def integrate_balls(tree, Q: np.ndarray, V: np.ndarray, out: np.ndarray) -> None:
    """Each ball joint of ``out`` (q (+) v already written elsewhere): q exp(v), normalized,
    in the hemisphere of the given quaternion (a run's quaternions stay continuous)."""
    for _, iq, iv in ball_slices(tree):
        q0 = Q[:, iq:iq + 4] / np.linalg.norm(Q[:, iq:iq + 4], axis=-1, keepdims=True)
        q1 = _multiply(q0, exp_quaternion(V[:, iv:iv + 3]))
        out[:, iq:iq + 4] = q1 / np.linalg.norm(q1, axis=-1, keepdims=True)


def difference_balls(tree, Q0: np.ndarray, Q1: np.ndarray, out: np.ndarray) -> None:
    """Each ball joint's v with q0 (+) v = q1: log(q0^-1 q1) (the inverse of integrate)."""
    for _, iq, iv in ball_slices(tree):
        q0 = Q0[:, iq:iq + 4] / np.linalg.norm(Q0[:, iq:iq + 4], axis=-1, keepdims=True)
        q1 = Q1[:, iq:iq + 4] / np.linalg.norm(Q1[:, iq:iq + 4], axis=-1, keepdims=True)
        out[:, iv:iv + 3] = log_quaternion(_multiply(q0 * [1.0, -1.0, -1.0, -1.0], q1))


def integrate_tree(tree, Q: np.ndarray, V: np.ndarray) -> np.ndarray:
    """q (+) v for a flat batch of a tree with ball joints or free flyers below the root: a
    floating base and each free flyer by its twist (free_flyer.py), each ball by q exp(w), the
    other joints by q + v."""
    from .free_flyer import integrate

    out = np.empty_like(Q)
    if tree.floating_base:
        out[:, :7] = integrate(Q[:, :7], V[:, :6])[:, :7]
    qs, vs = joint_layout(tree)
    out[:, tree.base_nq + qs] = Q[:, tree.base_nq + qs] + V[:, tree.base_nv + vs]
    integrate_balls(tree, Q, V, out)
    for j in tree.free_joints:  # a free flyer below the root: by its twist, as the base's
        iq, iv = tree.base_nq + j.coordinate, tree.base_nv + tree.velocity_index(j.coordinate)
        out[:, iq:iq + 7] = integrate(Q[:, iq:iq + 7], V[:, iv:iv + 6])
    return out


def difference_tree(tree, Q0: np.ndarray, Q1: np.ndarray) -> np.ndarray:
    """v with q0 (+) v = q1 for a flat batch of a tree with ball joints (integrate_tree's
    inverse), shape (N, nv)."""
    from .free_flyer import difference

    out = np.empty((len(Q0), tree.nv))
    if tree.floating_base:
        out[:, :6] = difference(Q0[:, :7], Q1[:, :7])
    qs, vs = joint_layout(tree)
    out[:, tree.base_nv + vs] = Q1[:, tree.base_nq + qs] - Q0[:, tree.base_nq + qs]
    difference_balls(tree, Q0, Q1, out)
    for j in tree.free_joints:
        iq, iv = tree.base_nq + j.coordinate, tree.base_nv + tree.velocity_index(j.coordinate)
        out[:, iv:iv + 6] = difference(Q0[:, iq:iq + 7], Q1[:, iq:iq + 7])
    return out


def joint_layout(tree) -> tuple[np.ndarray, np.ndarray]:
    """Index arrays (over the joints' own numbers, after the base) of the q entries that are
    plain coordinates and of the v entries that are their rates, in the same order."""
    qs, vs = [], []
    balls = {j.coordinate for j in tree.spherical}
    free = {j.coordinate for j in tree.free_joints}
    c = 0
    k = 0
    while c < len(tree.coordinates):
        if c in balls or c in free:  # a quaternion: 4 numbers and 3 rates, or 7 and 6
            c, k = (c + 4, k + 3) if c in balls else (c + 7, k + 6)
            continue
        qs.append(c)
        vs.append(k)
        c, k = c + 1, k + 1
    return np.array(qs, dtype=int), np.array(vs, dtype=int)


def refuse_spherical(tree, what: str) -> None:
    """Refuse, in one line naming the joint, a tree with a ball joint where ``what`` (an
    algorithm or backend) has no ball joint yet (model/tree.py's refuse_ball_joints)."""
    refuse_ball_joints(tree if getattr(tree, "joints", None) is not None else None, what)


__all__ = ["SphericalModel", "ball_quaternions_unit", "ball_slices", "check_tree_quaternions",
           "quaternion_slices",
           "difference_balls", "difference_tree", "exp_quaternion", "integrate_balls",
           "integrate_tree", "joint_layout",
           "log_quaternion", "refuse_spherical", "unit_ball_quaternions", "wxyz_matrix"]
