"""The recursions of recursive_numpy.py over a tree in numpy, on flat batches of states (N, ...),
the bodies visited in Python: Newton-Euler, the composite-rigid-body M, forward dynamics by
Cholesky, the energies; a mixin (TreeRecursions) of recursive_numpy.NumpyBackend, which
sets _joints, _g, _up and _actuators, and the NumericSystem kernel over it."""

from __future__ import annotations

import numpy as np

from ...kinds import JointKind
from ...model.tree import KinematicTree
from ..tree.joint_models import joint_model


def _cross(a, b):
    """a x b over the last axis (either may be a constant 3-vector); where one factor is a
    constant, [a]x b by a matrix made once is cheaper (numpy's cost is per call here)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape), dtype=np.result_type(a, b))
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    return out


def _apply(R, x):
    """R x."""
    return (R @ x[..., None])[..., 0]


def _apply_transpose(R, x):
    """R^T x."""
    return (x[..., None, :] @ R)[..., 0, :]


def _dot(a, b):
    return (a * b).sum(axis=-1)


def _skew_batch(p) -> np.ndarray:
    """[p]x for each row of p (N, 3)."""
    out = np.zeros(p.shape[:-1] + (3, 3), dtype=np.result_type(p, float))
    out[..., 0, 1], out[..., 0, 2], out[..., 1, 2] = -p[..., 2], p[..., 1], -p[..., 0]
    out[..., 1, 0], out[..., 2, 0], out[..., 2, 1] = p[..., 2], -p[..., 1], p[..., 0]
    return out


def _skew(u) -> np.ndarray:
    """[u]x, with [u]x x = u x x."""
    return np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])


def _project(j, moment, force):
    """S^T (n, f) = s_w . n + s_v . f for a batch of wrenches (N m or N)."""
    total = 0.0
    if j.s_w is not None:
        total = total + moment @ j.s_w
    if j.s_v is not None:
        total = total + force @ j.s_v
    return total


class _Joint:
    """One joint's constants as arrays."""

    def __init__(self, joint, tree: KinematicTree):
        self.parent = joint.parent
        self.model = joint_model(joint.kind)
        flyer = joint.kind == JointKind.FREE_FLYER
        self.free = flyer and joint.coordinate < 0  # a floating base: numbers 0..6 of q
        # a free flyer below the root: q[iq:iq+7] x y z qx qy qz qw, v[iv:iv+6] linear, angular
        self.inner = flyer and joint.coordinate >= 0
        self.ball = joint.kind == JointKind.SPHERICAL  # q[iq:iq+4] w x y z, v[iv:iv+3]
        self.coordinate = joint.coordinate
        self.iq = tree.base_nq + joint.coordinate  # its (first) number in q, and in v, a, tau
        self.iv = tree.base_nv + (tree.velocity_index(joint.coordinate) if tree.velocities
                                  else joint.coordinate)
        # S as (s_w, s_v) columns, one per velocity number, for the joints of several
        self.columns = (j_model.columns() if (j_model := self.model_of(joint)) is not None
                        else None)
        self.multiplier = joint.multiplier
        self.offset = joint.offset
        self.R0 = np.array(joint.rotation, dtype=float)
        self.t0 = np.array(joint.translation, dtype=float)
        self.u = np.array(joint.axis, dtype=float)
        self.pitch = joint.pitch  # a helical joint's (m/rad)
        s_w, s_v = ((None, None) if flyer or self.ball
                    else self.model.subspace(self.u, self.pitch))
        self.s_w = None if s_w is None else np.array(s_w)
        self.s_v = None if s_v is None else np.array(s_v)
        self.m = float(joint.mass)
        self.h = np.array(joint.first_moment, dtype=float)
        self.H = _skew(self.h)
        self.P0 = _skew(self.t0)  # [p]x of a revolute joint's fixed origin
        self.J = np.array(joint.inertia, dtype=float)

    def model_of(self, joint):
        """The joint model of a joint of several velocity numbers below the root, else None."""
        if joint.coordinate >= 0 and joint.kind in (JointKind.FREE_FLYER, JointKind.SPHERICAL):
            return joint_model(joint.kind)
        return None


def _spatial_inertia(m, h, J, count: int) -> np.ndarray:
    """A body's 6 x 6 inertia about its origin, linear rows first: (f, n) = I (v, w) with
    f = m v - [h]x w, n = [h]x v + J w; (count, 6, 6)."""
    h = np.broadcast_to(h, (count, 3))
    H = _skew_batch(h)
    out = np.zeros((count, 6, 6), dtype=H.dtype)
    out[:, :3, :3] = m * np.eye(3) if np.ndim(m) == 0 else np.asarray(m)[:, None, None] * np.eye(3)
    out[:, :3, 3:] = -H
    out[:, 3:, :3] = H
    out[:, 3:, 3:] = J
    return out


def _positive_definite(matrix) -> bool:
    try:
        np.linalg.cholesky(matrix)
    except np.linalg.LinAlgError:
        return False
    return True


class TreeRecursions:
    """Newton-Euler, CRBA, forward dynamics and the energies over flat batches (SI); the
    host sets tree, n, _joints, _g, _up and _actuators (recursive_numpy.NumpyBackend)."""

    def _kinematics(self, Q):
        """Each body's rotation R (body -> parent axes, (N, 3, 3) or constant), origin p in
        its parent ((N, 3) or constant) and [p]x (p x y = [p]x y, y x p = [p]x^T y)."""
        placements = []
        for j in self._joints:
            if j.free:
                R, p = j.model.placement_arrays(j.R0, j.t0, Q[:, :7])
                placements.append((R, p, _skew_batch(p)))
                continue
            if j.ball:  # R0 R(quaternion), the origin fixed
                R, p = j.model.placement_arrays(j.R0, j.t0, Q[:, j.iq:j.iq + 4])
                placements.append((R, p, j.P0))
                continue
            if j.inner:  # R0 R(quaternion), the origin t0 + R0 (x, y, z)
                R, p = j.model.placement_arrays(j.R0, j.t0, Q[:, j.iq:j.iq + 7])
                placements.append((R, p, _skew_batch(p)))
                continue
            theta = j.multiplier * Q[:, j.iq] + j.offset
            R, p = j.model.placement_arrays(j.R0, j.t0, j.u, theta, j.pitch)
            placements.append((R, p, j.P0 if p is j.t0 else _skew_batch(p)))
        return placements

    def _motion(self, Q, V, A):
        """Newton-Euler's forward pass: each body's placement (R, p, [p]x) in its parent, and
        its angular velocity w, angular acceleration dw and origin's acceleration a (up by g:
        the ground accelerates up, gravity's trick), body axes; V, A None: zero."""
        count = len(Q)
        placements = self._kinematics(Q)
        zero = np.zeros((count, 3))
        w, dw, acc = [], [], []
        for i, j in enumerate(self._joints):
            R, p, P = placements[i]
            if j.free:  # the floating base: its twist (v, w) and its derivative, in its axes
                w.append(zero if V is None else V[:, 3:6])
                dw.append(zero if A is None else A[:, 3:6])
                # the origin's acceleration: v_dot + w x v, and up by g (gravity's trick)
                acc.append(_apply_transpose(R, np.broadcast_to(self._up, (count, 3)))
                           + (0.0 if A is None else A[:, :3])
                           + (0.0 if V is None else _cross(V[:, 3:6], V[:, :3])))
                continue
            if j.parent < 0:  # the ground: at rest, accelerating up by g
                w_in = dw_in = zero
                a_i = _apply_transpose(R, np.broadcast_to(self._up, (count, 3)))
            else:
                wl, dwl, al = w[j.parent], dw[j.parent], acc[j.parent]
                w_in = _apply_transpose(R, wl)
                dw_in = _apply_transpose(R, dwl)
                # a + dw x p + w x (w x p), with y x p = [p]x^T y
                a_i = _apply_transpose(R, al + _apply_transpose(P, dwl)
                                       + _cross(wl, _apply_transpose(P, wl)))
            if j.inner:  # the relative twist (v_r, w_r) and its rate (a_r, dw_r), body axes
                w_i, dw_i = w_in, dw_in
                if V is not None:  # the origin slides at R v_r in the parent: Coriolis and turn
                    v_r, w_r = V[:, j.iv:j.iv + 3], V[:, j.iv + 3:j.iv + 6]
                    w_i = w_in + w_r
                    dw_i = dw_in + _cross(w_in, w_r)
                    a_i = a_i + 2.0 * _cross(w_in, v_r) + _cross(w_r, v_r)
                if A is not None:
                    a_i = a_i + A[:, j.iv:j.iv + 3]
                    dw_i = dw_i + A[:, j.iv + 3:j.iv + 6]
            elif j.ball:  # w += w_rel, dw += w x w_rel + dw_rel (S = 1 on the angular rows)
                w_i, dw_i = w_in, dw_in
                if V is not None:
                    w_i = w_in + V[:, j.iv:j.iv + 3]
                    dw_i = dw_in + _cross(w_in, V[:, j.iv:j.iv + 3])
                if A is not None:
                    dw_i = dw_i + A[:, j.iv:j.iv + 3]
            else:
                rate = None if V is None else j.multiplier * V[:, j.iv, None]
                w_i, dw_i = w_in, dw_in
                if rate is not None and j.s_w is not None:
                    w_i = w_in + rate * j.s_w
                    dw_i = dw_in + _cross(w_in, rate * j.s_w)
                if rate is not None and j.s_v is not None:
                    a_i = a_i + 2.0 * _cross(w_i, rate * j.s_v)
                if A is not None:
                    accel = j.multiplier * A[:, j.iv, None]
                    if j.s_w is not None:
                        dw_i = dw_i + accel * j.s_w
                    if j.s_v is not None:
                        a_i = a_i + accel * j.s_v
            w.append(w_i)
            dw.append(dw_i)
            acc.append(a_i)
        return placements, w, dw, acc

    def _newton_euler(self, Q, V, A):
        """tau (N, n) for q, q_dot, q_ddot, minus the actuator parameters (V, A None: zero)."""
        count = len(Q)
        placements, w, dw, acc = self._motion(Q, V, A)
        f, n = [], []
        for j, w_i, dw_i, a_i in zip(self._joints, w, dw, acc, strict=True):
            # about the body's origin: f = m a + dw x h + w x (w x h), n = J dw + w x J w + h x a
            f.append(j.m * a_i - _apply(j.H, dw_i) - _cross(w_i, _apply(j.H, w_i)))
            n.append(_apply(j.J, dw_i) + _cross(w_i, _apply(j.J, w_i)) + _apply(j.H, a_i))
        tau = np.zeros((count, self.n), dtype=np.result_type(Q, *(x for x in (V, A)
                                                                  if x is not None)))
        for i in reversed(range(len(self._joints))):
            j = self._joints[i]
            if j.free:  # the wrench on the base, force then moment, in its axes
                tau[:, :3] += f[i]
                tau[:, 3:6] += n[i]
                continue
            if j.ball:  # the moment on the body about its joint, in its axes
                tau[:, j.iv:j.iv + 3] += n[i]
            elif j.inner:  # the wrench on the body, force then moment, in its axes
                tau[:, j.iv:j.iv + 3] += f[i]
                tau[:, j.iv + 3:j.iv + 6] += n[i]
            else:
                tau[:, j.iv] += j.multiplier * _project(j, n[i], f[i])
            if j.parent >= 0:
                R, p, P = placements[i]
                force = _apply(R, f[i])
                f[j.parent] = f[j.parent] + force
                n[j.parent] = n[j.parent] + _apply(R, n[i]) + _apply(P, force)
        return tau - self._actuators

    def _composite_rigid_body(self, Q):
        """M (N, n, n) by the composite-rigid-body algorithm."""
        count = len(Q)
        placements = self._kinematics(Q)
        joints = self._joints
        mass = [j.m for j in joints]
        h = [j.h for j in joints]
        J = [j.J for j in joints]
        # float, or the entries' own type (complex; casadi SX in an object array)
        M = np.zeros((count, self.n, self.n), dtype=np.result_type(Q, float))
        for i in reversed(range(len(joints))):
            j = joints[i]
            if j.free:  # the floating base: the composite inertia itself, [[m, -[h]x], [[h]x, J]]
                M[:, :6, :6] += _spatial_inertia(mass[i], h[i], J[i], count)
                continue
            if j.columns is not None:  # a ball joint's three, a free flyer's six
                self._several_columns(M, placements, i, mass, h, J, count)
            else:
                self._joint_column(M, placements, i, h, J, mass, count)
            self._composite_into_parent(placements, i, mass, h, J, count)
        return M

    def _joint_column(self, M, placements, i, h, J, mass, count):
        """M's column (and row) of the one-number joint i: its composite's wrench per unit
        rate, projected on each joint from i up to the root."""
        joints = self._joints
        j = joints[i]
        # unit rate along S: f = m s_v + s_w x h, n = J s_w + h x s_v
        force, moment = np.zeros(3), np.zeros(3)
        if j.s_w is not None:
            force, moment = force + np.cross(j.s_w, h[i]), moment + J[i] @ j.s_w
        if j.s_v is not None:
            force, moment = force + mass[i] * j.s_v, moment + np.cross(h[i], j.s_v)
        force = np.broadcast_to(force, (count, 3))
        moment = np.broadcast_to(moment, (count, 3))
        ci, ki = j.iv, j.multiplier
        M[:, ci, ci] += ki * ki * _project(j, moment, force)
        k = i
        while joints[k].parent >= 0:
            R, p, P = placements[k]
            force = _apply(R, force)
            moment = _apply(R, moment) + _apply(P, force)
            k = joints[k].parent
            ancestor = joints[k]
            if ancestor.free:  # the base's six numbers: S = 1, (force, moment)
                entry = ki * np.concatenate([force, moment], axis=-1)
                M[:, ci, :6] += entry
                M[:, :6, ci] += entry
                continue
            if ancestor.ball:  # its three angular columns: the moment itself
                entry = ki * moment
                M[:, ci, ancestor.iv:ancestor.iv + 3] += entry
                M[:, ancestor.iv:ancestor.iv + 3, ci] += entry
                continue
            if ancestor.inner:  # its six columns (S = 1): the wrench itself
                entry = ki * np.concatenate([force, moment], axis=-1)
                M[:, ci, ancestor.iv:ancestor.iv + 6] += entry
                M[:, ancestor.iv:ancestor.iv + 6, ci] += entry
                continue
            entry = ki * ancestor.multiplier * _project(ancestor, moment, force)
            M[:, ci, ancestor.iv] += entry
            M[:, ancestor.iv, ci] += entry

    def _several_columns(self, M, placements, i, mass, h, J, count):
        """M's columns (and rows) of joint i of several velocity numbers (a ball joint's three
        angular, a free flyer's three linear and three angular, in its body's axes): for each
        unit rate (s_w, s_v), the composite's wrench (f = m s_v + s_w x h, n = J s_w + h x s_v),
        projected on its own columns and on each joint up the tree."""
        joints = self._joints
        j = joints[i]
        for col, (s_w, s_v) in enumerate(j.columns):
            force, moment = np.zeros(3), np.zeros(3)
            if s_w is not None:
                force, moment = force + np.cross(s_w, h[i]), moment + J[i] @ s_w
            if s_v is not None:
                force, moment = force + mass[i] * s_v, moment + np.cross(h[i], s_v)
            force = np.broadcast_to(force, (count, 3))
            moment = np.broadcast_to(moment, (count, 3))
            c = j.iv + col
            for row, (r_w, r_v) in enumerate(j.columns):
                M[:, j.iv + row, c] += ((0.0 if r_w is None else moment @ r_w)
                                        + (0.0 if r_v is None else force @ r_v))
            k = i
            while joints[k].parent >= 0:
                R, p, P = placements[k]
                force = _apply(R, force)
                moment = _apply(R, moment) + _apply(P, force)
                k = joints[k].parent
                ancestor = joints[k]
                if ancestor.free or ancestor.inner:  # its six numbers: the wrench itself
                    entry = np.concatenate([force, moment], axis=-1)
                    first = 0 if ancestor.free else ancestor.iv
                    M[:, c, first:first + 6] += entry
                    M[:, first:first + 6, c] += entry
                elif ancestor.ball:
                    M[:, c, ancestor.iv:ancestor.iv + 3] += moment
                    M[:, ancestor.iv:ancestor.iv + 3, c] += moment
                else:
                    entry = ancestor.multiplier * _project(ancestor, moment, force)
                    M[:, c, ancestor.iv] += entry
                    M[:, ancestor.iv, c] += entry

    def _composite_into_parent(self, placements, i, mass, h, J, count):
        """Body i's composite inertia (m, h, J_O) added to its parent's, in the parent's axes."""
        j = self._joints[i]
        eye = np.eye(3)
        if j.parent >= 0:  # the composite inertia of body i, moved into its parent's axes
            R, p, _ = placements[i]
            hr = _apply(R, h[i])
            p = np.broadcast_to(p, (count, 3))
            ph, pp = _dot(p, hr)[:, None, None], _dot(p, p)[:, None, None]
            outer = p[:, :, None] * hr[..., None, :]
            # J' = R J R^T + m (|p|^2 1 - p p^T) + 2 (p.h) 1 - p h^T - h p^T
            shifted = (R @ J[i] @ np.swapaxes(R, -1, -2)
                       + mass[i] * (pp * eye - p[:, :, None] * p[:, None, :])
                       + 2.0 * ph * eye - outer - np.swapaxes(outer, -1, -2))
            J[j.parent] = J[j.parent] + shifted
            h[j.parent] = h[j.parent] + hr + mass[i] * p
            mass[j.parent] = mass[j.parent] + mass[i]

    def _velocities(self, Q, V):
        placements = self._kinematics(Q)
        zero = np.zeros((len(Q), 3))
        w, vel = [], []
        for i, j in enumerate(self._joints):
            R, p, P = placements[i]
            if j.free:  # the floating base's own twist
                w.append(V[:, 3:6])
                vel.append(V[:, :3])
                continue
            wl, vl = (zero, zero) if j.parent < 0 else (w[j.parent], vel[j.parent])
            if j.ball:  # its own angular velocity added in its axes; its origin is fixed
                w.append(_apply_transpose(R, wl) + V[:, j.iv:j.iv + 3])
                vel.append(_apply_transpose(R, vl + _apply_transpose(P, wl)))
                continue
            if j.inner:  # its own twist added, linear then angular, in its axes
                w.append(_apply_transpose(R, wl) + V[:, j.iv + 3:j.iv + 6])
                vel.append(_apply_transpose(R, vl + _apply_transpose(P, wl)) + V[:, j.iv:j.iv + 3])
                continue
            rate = (j.multiplier * V[:, j.iv])[:, None]
            w_i = _apply_transpose(R, wl)
            v_i = _apply_transpose(R, vl + _apply_transpose(P, wl))
            if j.s_w is not None:
                w_i = w_i + rate * j.s_w
            if j.s_v is not None:
                v_i = v_i + rate * j.s_v
            w.append(w_i)
            vel.append(v_i)
        return w, vel

    def _kinetic(self, Q, V):
        w, vel = self._velocities(Q, V)
        total = np.zeros(len(Q))
        for j, w_i, v_i in zip(self._joints, w, vel, strict=True):
            total += (j.m * _dot(v_i, v_i) - 2.0 * _dot(v_i, _apply(j.H, w_i))
                      + _dot(w_i, _apply(j.J, w_i)))
        return 0.5 * total

    def _potential(self, Q):
        placements = self._kinematics(Q)
        count = len(Q)
        up_world = np.broadcast_to(-np.array(self.tree.gravity_direction, dtype=float),
                                   (count, 3))
        up, height = [], []
        total = np.zeros(count)
        for i, j in enumerate(self._joints):
            R, p, _ = placements[i]
            up_l, height_l = (up_world, 0.0) if j.parent < 0 else (up[j.parent],
                                                                   height[j.parent])
            up.append(_apply_transpose(R, up_l))
            height.append(height_l + _dot(up_l, p))
            total += j.m * height[i] + _dot(up[i], j.h)
        return self._g * total

    def _forward(self, Q, V, TAU):
        """q_ddot = M^-1 (tau - b) by Cholesky; LinAlgError where M is not positive definite."""
        mass = self._composite_rigid_body(Q)
        rhs = TAU - self._newton_euler(Q, V, None)
        try:
            L = np.linalg.cholesky(mass)
        except np.linalg.LinAlgError:
            bad = next(k for k in range(len(mass)) if not _positive_definite(mass[k]))
            raise np.linalg.LinAlgError(
                f"the mass matrix is not positive definite (state {bad})") from None
        y = np.linalg.solve(L, rhs[..., None])
        return np.linalg.solve(np.swapaxes(L, -1, -2), y)[..., 0]


class _TreeKernel:
    """NumericSystem's kernel over the numpy recursions (no constraints: m = 0)."""

    backend = "numpy"

    def __init__(self, dynamics: TreeRecursions):
        self.dynamics = dynamics
        self.n = dynamics.n

    def parts(self, Q, V, T):
        d, count = self.dynamics, len(Q)
        return (d._composite_rigid_body(Q), -d._newton_euler(Q, V, None),
                np.zeros((count, 0, self.n)), np.zeros((count, 0)))

    def residual(self, Q, V, T):
        return np.zeros((len(Q), 0))

    def energy(self, Q, V, T):
        return self.dynamics._kinetic(Q, V) + self.dynamics._potential(Q)

    def accelerations(self, Q, V, T):
        return self.dynamics._forward(Q, V, np.zeros_like(Q)), np.zeros((len(Q), 0))

    def rhs(self, t, y):
        y = np.asarray(y, dtype=float)
        n = self.n
        if y.shape != (2 * n,):
            raise ValueError(f"y must hold {2 * n} numbers [q, q_dot]")
        q, v = y[None, :n], y[None, n:]
        return np.concatenate([y[n:], self.dynamics._forward(q, v, np.zeros_like(q))[0]])


__all__ = ["TreeRecursions"]
