"""A robot's state between MuJoCo's layout and ours.

MuJoCo's qpos holds every joint in document order, a free joint as x y z (m) and its quaternion
w x y z; qvel a free joint's linear velocity in world axes (m/s) and its angular velocity in
body axes (rad/s). A ball joint is the same in both: its quaternion w x y z in q, its body's
angular velocity in its own axes in v (and its moment in tau), so its numbers are copied; so is
a free joint read without floating_base (three slides and a ball, model/mjcf_free.py), its
force the world force and the moment in body axes in both. With floating_base ours holds the
free joint as the tree's free flyer, x y z and the quaternion x y z w, its velocity v
= (R^T p_dot, w) all in body axes, and no entry for a mimic joint (an MJCF joint equality:
q_mimic = k q_master + offset). With G = d qvel / d v (R on the base's linear rows, k on a
mimic's), the maps are

    qvel = G v,   qacc = G a + G' v   (G' v: R (w x v_b) on the base's linear rows),
    tau = G^T qfrc   (the same power: qfrc . qvel = tau . v),

so MuJoCo's M and bias become ours as M = G^T M_mj G and b = G^T (M_mj G' v + b_mj). Going back,
a mimic's qpos is k q + offset and a generalized force is put on the master joints only (the
forces that give one tau are many). A robot loaded with ``lock`` has fewer joints than MuJoCo's
qpos: its widths are refused in one line.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, ModelError
from ..kinds import JointKind
from .quaternions import check_quaternions, quaternion_matrix


class MujocoLayout:
    """MuJoCo's qpos, qvel, qacc and qfrc against our q, v, a and tau for one robot (module
    docstring); arrays of shape (n,) or batches (N, n)."""

    def __init__(self, model):
        model = getattr(model, "model", model)  # a System or its Model
        tree = getattr(model, "kinematic_tree", None)
        if tree is None:
            raise ModelError("only a robot read from MJCF or URDF has MuJoCo's layout",
                             field="mujoco_layout")
        self.floating = tree.floating_base
        masters = {joint for _, joint in model.source_names}
        # per MuJoCo hinge or slide joint, in order: (our coordinate, multiplier, offset,
        # whether it is the coordinate's own joint)
        moving = [j for j in tree.joints
                  if j.kind not in (JointKind.FREE_FLYER, JointKind.SPHERICAL)]
        self.joints = [(j.coordinate, j.multiplier, j.offset, j.name in masters) for j in moving]
        self.names = [j.name for j in tree.joints if j.kind != JointKind.FREE_FLYER]
        self.n = len(tree.coordinates)
        # per hinge or slide joint: (MuJoCo's q and v index, ours), after the base's numbers;
        # per ball joint: the same for its 4 and 3 numbers
        self._slots, self._balls = [], []
        mq = mv = 0
        for j in tree.joints:
            if j.kind == JointKind.FREE_FLYER:
                continue
            ours = (j.coordinate, tree.velocity_index(j.coordinate))
            if j.kind == JointKind.SPHERICAL:
                self._balls.append((mq, mv, *ours))
                mq, mv = mq + 4, mv + 3
            else:
                self._slots.append((mq, mv, *ours))
                mq, mv = mq + 1, mv + 1
        base = 7 if self.floating else 0
        self.nq, self.nv = base + mq, base - bool(base) + mv
        self.our_nq, self.our_nv = tree.nq, tree.nv

    def __repr__(self) -> str:
        return (f"MujocoLayout(nq={self.nq}, nv={self.nv} <-> nq={self.our_nq}, "
                f"nv={self.our_nv})")

    # -- checks ---------------------------------------------------------------------------

    def _array(self, values, width: int, field: str) -> np.ndarray:
        try:
            array = np.array(values, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"expected numbers, got {type(values).__name__}",
                             field=field) from None
        if array.ndim not in (1, 2) or array.shape[-1] != width:
            raise InputError(f"expected {width} numbers a state, got shape {array.shape}"
                             + (" (a joint locked on loading is not in our state: load "
                                "without lock)" if field.startswith("q") else ""), field=field)
        return array

    def _rotation(self, quaternion_xyzw: np.ndarray, field: str) -> np.ndarray:
        check_quaternions(np.atleast_2d(np.r_["-1", np.zeros(quaternion_xyzw.shape[:-1] + (3,)),
                                              quaternion_xyzw]), field=field)
        return quaternion_matrix(quaternion_xyzw)

    # -- MuJoCo -> ours ---------------------------------------------------------------------

    def from_mujoco(self, qpos, qvel=None, qacc=None):
        """(q, v, a) of MuJoCo's (qpos, qvel, qacc), as many as given (q alone for qpos); a
        mimic joint's entries are dropped (MuJoCo holds an equality softly, we exactly)."""
        qpos = self._array(qpos, self.nq, "qpos")
        q = np.zeros(qpos.shape[:-1] + (self.our_nq,))
        base = 7 if self.floating else 0
        if self.floating:
            q[..., :3] = qpos[..., :3]
            q[..., 3:6], q[..., 6] = qpos[..., 4:7], qpos[..., 3]
        for (c, _, _, own), (k, _, _, _) in zip(self.joints, self._slots, strict=True):
            if own:
                q[..., base + c] = qpos[..., base + k]
        for k, _, c, _ in self._balls:
            q[..., base + c:base + c + 4] = qpos[..., base + k:base + k + 4]
        if qvel is None:
            return q
        R = self._rotation(q[..., 3:7], "qpos") if self.floating else None
        v = self._velocity_from(self._array(qvel, self.nv, "qvel"), R)
        if qacc is None:
            return q, v
        a = self._velocity_from(self._array(qacc, self.nv, "qacc"), R)
        if self.floating:  # d/dt (R^T p_dot) = R^T p_ddot - w x v_b
            a[..., :3] -= np.cross(v[..., 3:6], v[..., :3])
        return q, v, a

    def _velocity_from(self, qvel: np.ndarray, R) -> np.ndarray:
        v = np.zeros(qvel.shape[:-1] + (self.our_nv,))
        base = 6 if self.floating else 0
        if self.floating:
            v[..., :3] = np.einsum("...ji,...j->...i", R, qvel[..., :3])
            v[..., 3:6] = qvel[..., 3:6]
        for (_, _, _, own), (_, k, _, c) in zip(self.joints, self._slots, strict=True):
            if own:
                v[..., base + c] = qvel[..., base + k]
        for _, k, _, c in self._balls:
            v[..., base + c:base + c + 3] = qvel[..., base + k:base + k + 3]
        return v

    def force_from_mujoco(self, qpos, qfrc) -> np.ndarray:
        """tau = G^T qfrc: our generalized force (N, N m; a base's wrench in its own axes) of
        MuJoCo's (qfrc_applied, qfrc_bias, qfrc_inverse, ...) at qpos."""
        q = self.from_mujoco(qpos)
        qfrc = self._array(qfrc, self.nv, "qfrc")
        tau = np.zeros(qfrc.shape[:-1] + (self.our_nv,))
        base = 6 if self.floating else 0
        if self.floating:
            R = self._rotation(q[..., 3:7], "qpos")
            tau[..., :3] = np.einsum("...ji,...j->...i", R, qfrc[..., :3])
            tau[..., 3:6] = qfrc[..., 3:6]
        for (_, multiplier, _, _), (_, k, _, c) in zip(self.joints, self._slots, strict=True):
            tau[..., base + c] += multiplier * qfrc[..., base + k]
        for _, k, _, c in self._balls:
            tau[..., base + c:base + c + 3] = qfrc[..., base + k:base + k + 3]
        return tau

    # -- ours -> MuJoCo ---------------------------------------------------------------------

    def to_mujoco(self, q, v=None, a=None):
        """(qpos, qvel, qacc) of our (q, v, a), as many as given (qpos alone for q); a mimic
        joint's entries k q + offset, k v, k a."""
        q = self._array(q, self.our_nq, "q")
        qpos = np.zeros(q.shape[:-1] + (self.nq,))
        base = 7 if self.floating else 0
        R = None
        if self.floating:
            R = self._rotation(q[..., 3:7], "q")
            qpos[..., :3] = q[..., :3]
            qpos[..., 3], qpos[..., 4:7] = q[..., 6], q[..., 3:6]
        for (c, multiplier, offset, _), (k, _, _, _) in zip(self.joints, self._slots, strict=True):
            qpos[..., base + k] = multiplier * q[..., base + c] + offset
        for k, _, c, _ in self._balls:
            qpos[..., base + k:base + k + 4] = q[..., base + c:base + c + 4]
        if v is None:
            return qpos
        v = self._array(v, self.our_nv, "v")
        qvel = self._velocity_to(v, R)
        if a is None:
            return qpos, qvel
        a = self._array(a, self.our_nv, "a")
        qacc = self._velocity_to(a, R)
        if self.floating:  # p_ddot = R (v_b' + w x v_b)
            qacc[..., :3] += np.einsum("...ij,...j->...i", R,
                                       np.cross(v[..., 3:6], v[..., :3]))
        return qpos, qvel, qacc

    def _velocity_to(self, v: np.ndarray, R) -> np.ndarray:
        qvel = np.zeros(v.shape[:-1] + (self.nv,))
        base = 6 if self.floating else 0
        if self.floating:
            qvel[..., :3] = np.einsum("...ij,...j->...i", R, v[..., :3])
            qvel[..., 3:6] = v[..., 3:6]
        for (_, multiplier, _, _), (_, k, _, c) in zip(self.joints, self._slots, strict=True):
            qvel[..., base + k] = multiplier * v[..., base + c]
        for _, k, _, c in self._balls:
            qvel[..., base + k:base + k + 3] = v[..., base + c:base + c + 3]
        return qvel

    def force_to_mujoco(self, q, tau) -> np.ndarray:
        """A MuJoCo generalized force (qfrc_applied) with G^T qfrc = tau: the base's wrench
        turned to world axes for its force, each coordinate's on its own joint, 0 on a mimic."""
        q = self._array(q, self.our_nq, "q")
        tau = self._array(tau, self.our_nv, "tau")
        qfrc = np.zeros(tau.shape[:-1] + (self.nv,))
        base = 6 if self.floating else 0
        if self.floating:
            R = self._rotation(q[..., 3:7], "q")
            qfrc[..., :3] = np.einsum("...ij,...j->...i", R, tau[..., :3])
            qfrc[..., 3:6] = tau[..., 3:6]
        for (_, _, _, own), (_, k, _, c) in zip(self.joints, self._slots, strict=True):
            if own:
                qfrc[..., base + k] = tau[..., base + c]
        for _, k, _, c in self._balls:
            qfrc[..., base + k:base + k + 3] = tau[..., base + c:base + c + 3]
        return qfrc


def mujoco_layout(system) -> MujocoLayout:
    """The conversions between MuJoCo's qpos/qvel/qacc/qfrc and our q/v/a/tau of a robot
    (a System or Model read from MJCF or URDF): module docstring."""
    return MujocoLayout(system)


__all__ = ["MujocoLayout", "mujoco_layout"]
