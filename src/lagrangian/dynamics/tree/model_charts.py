"""A fixed-base tree's configuration and velocity from the model's own coordinates, where the
two differ: a ball joint is three Euler hinges ``<ball>__x, __y, __z`` in the model (R = Rx(a)
Ry(b) Rz(c), model/mjcf_ball.py's chain) and a quaternion w x y z with the body's angular
velocity in the tree; a free flyer below the root is ``<joint>_x, _y, _z, _roll, _pitch, _yaw``
in the model (R = Rz(yaw) Ry(pitch) Rx(roll), the URDF's rpy) and x y z, qx qy qz qw with its
twist in its own axes in the tree. ``v = E(theta) theta_dot``, so that M_theta = E^T M E and a
generalized force in theta is E^T tau (virtual work: tau . dv = tau . E dtheta). Units SI."""

from __future__ import annotations

import numpy as np

from ...kinds import JointKind

FREE_MODEL = ("x", "y", "z", "roll", "pitch", "yaw")  # a free flyer's six in the model


def _turn(axis: int, angle: np.ndarray) -> np.ndarray:
    """Rotations (..., 3, 3) about the unit axis e_axis by angle (...)."""
    c, s = np.cos(angle), np.sin(angle)
    R = np.zeros(np.shape(angle) + (3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    R[..., axis, axis] = 1.0
    R[..., i, i], R[..., j, j], R[..., i, j], R[..., j, i] = c, c, -s, s
    return R


def _quaternion_wxyz(R: np.ndarray) -> np.ndarray:
    """The unit quaternion (..., 4), w x y z with w >= 0, of rotations R (..., 3, 3)."""
    from .free_flyer import matrix_quaternion

    xyzw = matrix_quaternion(R)
    return np.concatenate([xyzw[..., 3:], xyzw[..., :3]], axis=-1)


def _wrap(angle: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """angle plus whole turns, within a half turn of centre (rad)."""
    return centre + (angle - centre + np.pi) % (2 * np.pi) - np.pi


def _nearest(triple: np.ndarray, near: np.ndarray) -> np.ndarray:
    """Of an Euler triple (..., 3) (outer, middle, inner) and its twin (outer + pi, pi -
    middle, inner + pi), the one nearest ``near`` (3), outer and inner wrapped to it."""
    one = triple.copy()
    two = np.stack([triple[..., 0] + np.pi, np.pi - triple[..., 1], triple[..., 2] + np.pi], -1)
    choices = []
    for branch in (one, two):
        branch[..., [0, 2]] = _wrap(branch[..., [0, 2]], near[[0, 2]])
        branch[..., 1] = _wrap(branch[..., 1], near[1])
        choices.append(branch)
    closer = (np.abs(choices[1] - near).sum(-1) < np.abs(choices[0] - near).sum(-1))[..., None]
    return np.where(closer, choices[1], choices[0])


class ModelCharts:
    """Theta (the model's coordinates) -> the tree's q and E(theta) (v = E theta_dot)."""

    def __init__(self, model, velocity_names):
        tree = model.kinematic_tree
        names = [c.name for c in model.coordinates]
        self.n, self.nq, self.nv = len(names), len(tree.coordinates), len(velocity_names)
        self.hinges = []  # (model index, q index, v index) of each one-number joint
        self.balls = []  # (model indices of x, y, z; q index of w; v index of omega_x)
        self.free = []  # (model indices of x..yaw; q index of x; v index of v_x)
        grouped = set()
        for j in tree.joints:
            if j.coordinate < 0:
                continue
            iv = tree.velocity_index(j.coordinate)
            if j.kind == JointKind.SPHERICAL:
                self.balls.append(([names.index(f"{j.name}__{a}") for a in "xyz"],
                                   j.coordinate, iv))
                grouped.update(range(j.coordinate, j.coordinate + 4))
            elif j.kind == JointKind.FREE_FLYER:
                self.free.append(([names.index(f"{j.name}_{a}") for a in FREE_MODEL],
                                  j.coordinate, iv))
                grouped.update(range(j.coordinate, j.coordinate + 7))
        for k, name in enumerate(tree.coordinates):
            if k not in grouped:
                self.hinges.append((names.index(name), k, tree.velocity_index(k)))

    def configuration(self, theta: np.ndarray) -> np.ndarray:
        """The tree's q (..., nq) at the model's coordinates theta (..., n)."""
        theta = np.asarray(theta, dtype=float)
        q = np.zeros(theta.shape[:-1] + (self.nq,))
        for k, iq, _ in self.hinges:
            q[..., iq] = theta[..., k]
        for (a, b, c), iq, _ in self.balls:
            R = _turn(0, theta[..., a]) @ _turn(1, theta[..., b]) @ _turn(2, theta[..., c])
            q[..., iq:iq + 4] = _quaternion_wxyz(R)
        for indices, iq, _ in self.free:
            x, y, z, roll, pitch, yaw = (theta[..., k] for k in indices)
            R = _turn(2, yaw) @ _turn(1, pitch) @ _turn(0, roll)
            q[..., iq:iq + 3] = np.stack([x, y, z], axis=-1)
            wxyz = _quaternion_wxyz(R)
            q[..., iq + 3:iq + 7] = np.concatenate([wxyz[..., 1:], wxyz[..., :1]], axis=-1)
        return q

    def angles(self, q: np.ndarray, near: np.ndarray) -> np.ndarray:
        """The model's coordinates theta (..., n) of the tree's q (..., nq), each Euler triple
        on the branch nearest ``near`` (n; (a, b, c) and (a + pi, pi - b, c + pi) turn alike,
        a and c taken within a half turn of near's): configuration's inverse."""
        from ...model.quaternions import quaternion_matrix

        q, near = np.asarray(q, dtype=float), np.asarray(near, dtype=float)
        theta = np.zeros(q.shape[:-1] + (self.n,))
        for k, iq, _ in self.hinges:
            theta[..., k] = q[..., iq]
        for indices, iq, _ in self.balls:  # R = Rx(a) Ry(b) Rz(c), quaternion w x y z
            R = quaternion_matrix(np.concatenate([q[..., iq + 1:iq + 4], q[..., iq:iq + 1]], -1))
            b = np.arcsin(np.clip(R[..., 0, 2], -1.0, 1.0))
            a, c = np.arctan2(-R[..., 1, 2], R[..., 2, 2]), np.arctan2(-R[..., 0, 1], R[..., 0, 0])
            theta[..., indices] = _nearest(np.stack([a, b, c], -1), near[indices])
        for indices, iq, _ in self.free:  # R = Rz(yaw) Ry(pitch) Rx(roll), x y z w
            theta[..., indices[:3]] = q[..., iq:iq + 3]
            R = quaternion_matrix(q[..., iq + 3:iq + 7])
            pitch = -np.arcsin(np.clip(R[..., 2, 0], -1.0, 1.0))
            roll, yaw = np.arctan2(R[..., 2, 1], R[..., 2, 2]), np.arctan2(R[..., 1, 0], R[..., 0, 0])
            theta[..., indices[3:]] = _nearest(np.stack([roll, pitch, yaw], -1), near[indices[3:]])
        return theta

    def singular(self, theta: np.ndarray, tolerance: float = 1e-6) -> bool:
        """Whether theta is at a singularity of an Euler chart (gimbal lock: cos b = 0 for a
        ball's Rx Ry Rz, cos(pitch) = 0 for a free flyer's rpy), where E loses a direction."""
        theta = np.asarray(theta, dtype=float)
        middles = [b for (_, b, _), _, _ in self.balls] + [i[4] for i, _, _ in self.free]
        return any(abs(np.cos(theta[..., k])).min() < tolerance for k in middles)

    def same(self, first: np.ndarray, second: np.ndarray, tolerance: float = 1e-7) -> bool:
        """Whether two model configurations place the tree alike: Euler angles cover each
        turn twice ((a, b, c) and (a + pi, pi - b, c + pi)), so quaternions compare up to
        sign; the rest by value, angles modulo a turn."""
        one, two = self.configuration(first), self.configuration(second)
        quaternions = [(iq, 4) for _, iq, _ in self.balls] + [(iq + 3, 4) for _, iq, _ in self.free]
        for iq, width in quaternions:
            if abs(float(one[iq:iq + width] @ two[iq:iq + width])) < 1.0 - tolerance:
                return False
        positions = [iq + r for _, iq, _ in self.free for r in range(3)]
        if positions and np.abs(one[positions] - two[positions]).max() > tolerance:
            return False
        turns = [iq for _, iq, _ in self.hinges]
        difference = np.abs(one[turns] - two[turns])
        return bool(np.all(np.minimum(difference, np.abs(difference - 2 * np.pi)
                                      % (2 * np.pi)) <= tolerance))

    def rates(self, theta: np.ndarray) -> np.ndarray:
        """E(theta) (..., nv, n): the tree's v per unit of each model rate theta_dot."""
        theta = np.asarray(theta, dtype=float)
        E = np.zeros(theta.shape[:-1] + (self.nv, self.n))
        unit = np.eye(3)
        for k, _, iv in self.hinges:
            E[..., iv, k] = 1.0
        for (a, b, c), _, iv in self.balls:  # w_body = Rz^T Ry^T e_x a' + Rz^T e_y b' + e_z c'
            Rz_T = np.swapaxes(_turn(2, theta[..., c]), -1, -2)
            Ry_T = np.swapaxes(_turn(1, theta[..., b]), -1, -2)
            E[..., iv:iv + 3, a] = (Rz_T @ Ry_T)[..., :, 0]
            E[..., iv:iv + 3, b] = Rz_T[..., :, 1]
            E[..., iv:iv + 3, c] = unit[:, 2]
        for indices, _, iv in self.free:  # v_lin = R^T x_dot; w_body from the rpy rates
            roll, pitch, yaw = (theta[..., k] for k in indices[3:])
            Rx, Ry, Rz = _turn(0, roll), _turn(1, pitch), _turn(2, yaw)
            R_T = np.swapaxes(Rz @ Ry @ Rx, -1, -2)
            for r in range(3):
                E[..., iv:iv + 3, indices[r]] = R_T[..., :, r]
            Rx_T, Ry_T = np.swapaxes(Rx, -1, -2), np.swapaxes(Ry, -1, -2)
            E[..., iv + 3:iv + 6, indices[5]] = (Rx_T @ Ry_T)[..., :, 2]
            E[..., iv + 3:iv + 6, indices[4]] = Rx_T[..., :, 1]
            E[..., iv + 3:iv + 6, indices[3]] = unit[:, 0]
        return E


__all__ = ["FREE_MODEL", "ModelCharts"]
