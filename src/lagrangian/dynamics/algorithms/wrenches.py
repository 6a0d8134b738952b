"""External wrenches at frames as generalized forces: tau_ext = sum over frames of J^T w.

A wrench is w = [f; m] (N; N m) acting on the body that carries the frame, with f applied at
the frame's origin and both vectors in world axes (the LOCAL_WORLD_ALIGNED convention of the
frame Jacobian, whose J^T takes it to joint space). Inverse dynamics then gives the joint
forces with the wrench acting (tau = M a + b - tau_ext); forward dynamics adds tau_ext to tau.
(Pinocchio's f_ext is per joint, in the joint's own axes about its origin: the same wrench is
R_j^T f and R_j^T (m + (p - o_j) x f) there.) On a floating base the base's six numbers take
the wrench carried to the base: its force and its moment about the base's origin, base axes.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ...errors import InputError, did_you_mean_or_list


def wrench_arrays(kinematics, f_ext) -> dict[str, np.ndarray]:
    """Each frame's wrench as an array (..., 6), its name checked: one line naming
    ``f_ext`` (an unknown frame, with a suggestion) or ``f_ext.<frame>`` (not six numbers)."""
    if not isinstance(f_ext, Mapping):
        raise InputError("expected a mapping of frame names to wrenches [fx, fy, fz, mx, my, "
                         f"mz], got {type(f_ext).__name__}", field="f_ext")
    frames = kinematics.frames
    out = {}
    for name, value in f_ext.items():
        if name not in frames:
            raise InputError(f"no frame named '{name}'{did_you_mean_or_list(str(name), frames)}",
                             field="f_ext")
        try:
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise InputError("a wrench is 6 numbers [fx, fy, fz, mx, my, mz] (N, N m)",
                             field=f"f_ext.{name}") from None
        if array.ndim == 0 or array.shape[-1] != 6:
            shape = "()" if array.ndim == 0 else str(array.shape)
            raise InputError("a wrench is 6 numbers [fx, fy, fz, mx, my, mz] (N, N m) along "
                             f"the last axis, got shape {shape}", field=f"f_ext.{name}")
        out[name] = array
    return out


def wrench_forces(kinematics, q, f_ext) -> np.ndarray:
    """tau_ext = sum J_frame(q)^T w_frame (N m or N per coordinate), shape (..., n): the
    generalized forces of wrenches at frames (world axes, at each frame's origin). Each wrench
    is carried to the world's origin (m_O = m + p x f) and projected on the joint motions S
    there: tau_j = k (s_v . f + s_w . m_O) for the joints above the frame's body (a free
    flyer's six columns S: its force and moment about the base's origin, base axes)."""
    from .centroidal import require_known_joints, world_columns
    from .recursions import _cross

    tree = getattr(kinematics, "tree", None)
    if tree is not None:
        require_known_joints(tree, "wrenches at frames", "f_ext")
    wrenches = wrench_arrays(kinematics, f_ext)
    Q, batch = kinematics._q(q)
    for w in wrenches.values():
        batch = np.broadcast_shapes(batch, w.shape[:-1])
    count = int(np.prod(batch, dtype=np.int64))
    if len(Q) != count:
        nq = Q.shape[-1]
        Q = np.broadcast_to(np.asarray(q, dtype=float), batch + (nq,)).reshape(count, nq)
    if tree is None:  # a model file's frames (model_frames.py): J^T w from their Jacobians
        total = np.zeros((count, kinematics.n))
        for name, w in wrenches.items():
            w = np.broadcast_to(w, batch + (6,)).reshape(count, 6)
            total += np.einsum("nij,ni->nj", kinematics.jacobian(Q, name), w)
        return total.reshape(batch + (kinematics.n,))
    bodies = kinematics._bodies(Q)
    total = np.zeros((count, kinematics.n))
    for name, w in wrenches.items():
        body = kinematics._frame(name).body
        if body < 0:
            continue  # on the ground: no joint feels it
        w = np.broadcast_to(w, batch + (6,)).reshape(count, 6)
        p = kinematics._frame_pose(Q, bodies, name)[1]
        at_origin = np.concatenate([w[:, :3], w[:, 3:] + _cross(p, w[:, :3])], axis=1)
        for k in kinematics._ancestors(body):
            S, index = world_columns(kinematics, k, kinematics.tree.joints[k], bodies[k])
            total[:, index] += (at_origin[:, None, :] @ S)[:, 0]  # S^T [f; m_O]
    return total.reshape(batch + (kinematics.n,))


__all__ = ["wrench_arrays", "wrench_forces"]
