"""A floating base's orientation as a unit quaternion (x, y, z, w, Pinocchio's order): its
rotation matrix and the check of its norm, shared by the dynamics' free flyer and the
simulation's integration on the manifold."""

from __future__ import annotations

import numpy as np

from ..errors import InputError

# |quaternion| may differ from 1 by this much (float32 data are ~6e-8 off); beyond, refused.
QUATERNION_TOLERANCE = 1e-6


def quaternion_matrix(quaternion) -> np.ndarray:
    """The rotation (..., 3, 3) of quaternions (..., 4) in the order x, y, z, w, normalized."""
    quaternion = np.asarray(quaternion, dtype=np.result_type(quaternion, float))
    # the complex step (|q| analytic, sqrt(q . q), not |q|) and symbolic entries (casadi SX)
    if quaternion.dtype.kind in "cO":
        norm = np.sqrt((quaternion * quaternion).sum(axis=-1, keepdims=True))
    else:
        norm = np.linalg.norm(quaternion, axis=-1, keepdims=True)
    x, y, z, w = np.moveaxis(quaternion / norm, -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1)], -2)


def check_quaternions(Q: np.ndarray, field: str = "q") -> None:
    """Refuse, in one line, a configuration (N, nq) whose base quaternion (entries 3..6) has a
    norm off 1 by more than QUATERNION_TOLERANCE; a state whose q is not all finite is not
    refused (its row of every function is NaN, as the compiled modules give)."""
    with np.errstate(invalid="ignore", over="ignore"):
        norms = np.linalg.norm(Q[:, 3:7], axis=-1)
    finite = np.isfinite(Q).all(axis=-1)
    bad = np.flatnonzero(finite & (np.abs(norms - 1.0) > QUATERNION_TOLERANCE))
    if bad.size:
        raise InputError(
            f"the base quaternion (base_qx, base_qy, base_qz, base_qw) has norm "
            f"{norms[bad[0]]:.9g}" + (f" in state {bad[0]}" if len(Q) > 1 else "")
            + f"; a unit quaternion is needed (|q| within {QUATERNION_TOLERANCE:g} of 1)",
            field=field)


__all__ = ["QUATERNION_TOLERANCE", "check_quaternions", "quaternion_matrix"]
