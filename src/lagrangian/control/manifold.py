"""A constrained run's linearization on its constraint manifold, in the states [q_i; q_dot_i] of
n - m independent coordinates; the dependent ones follow from Phi(q, t) = 0 and c = Phi_q q_dot
+ Phi_t = 0 to first order:

    dq = T dq_i,  T = [I; -Phi_d^-1 Phi_i],   dq_dot = T dq_dot_i + W dq_i,  W = [0; -Phi_d^-1 c_q T]

(rows in the order of q), so dx = S dz with S = [[T, 0], [W, T]]. The index-1 form keeps
Phi and c constant along every run, so the variations stay in the range of S and, P picking the
independent rows (P S = 1), z_dot = P A S z and A_r = P A S, B_r = P B exactly, with the choice
of coordinates held fixed along the run (no rate of the basis enters). A sample where Phi_d is
singular (the chosen coordinates do not fix the others there) is refused."""

from __future__ import annotations

import numpy as np

from ..errors import InputError, ModelError
from ..kinds import ConstraintKind

# cond(Phi_d) above this: the dependent coordinates are not fixed by the independent ones
SINGULAR_CONDITION = 1e8


def choose_independent(jacobians: np.ndarray, names: tuple[str, ...]) -> tuple[str, ...]:
    """The n - m coordinates whose dependent partners are best conditioned over every sample:
    each sample's QR with column pivoting proposes one split (its first m pivots dependent); the
    split whose worst cond(Phi_d) along the run is least wins."""
    import scipy.linalg

    count, m, n = jacobians.shape
    candidates = []
    for J in jacobians[:: max(1, count // 16)]:  # a few samples propose; every sample judges
        if not np.all(np.isfinite(J)):
            continue
        pivots = tuple(sorted(scipy.linalg.qr(J, pivoting=True, mode="r")[1][:m]))
        if pivots not in candidates:
            candidates.append(pivots)
    if not candidates:
        raise InputError("the run has no finite constraint Jacobian to choose coordinates from",
                         field="independent")
    worst = [max(np.linalg.cond(jacobians[:, :, list(d)]).max(), 1.0) for d in candidates]
    dependent = candidates[int(np.argmin(worst))]
    return tuple(name for k, name in enumerate(names) if k not in dependent)


def reduce_to_manifold(dynamics, along, q, v, t, independent):
    """``along`` (TrajectoryLinearization in all n coordinates, constrained ``dynamics``)
    on the manifold: A_r (N, 2r, 2r), B_r (N, 2r, inputs) in the states of ``independent``
    (r = n - m coordinate names, or "auto")."""
    names = tuple(dynamics.coordinates)
    m, n = getattr(dynamics, "m", 0), len(names)
    if m == 0:
        raise InputError("this model has no constraints: its coordinates are independent "
                         "already", field="independent")
    kinds = tuple(dynamics.functions.constraint_kinds)
    if any(kind != ConstraintKind.HOLONOMIC for kind in kinds):
        velocity = [c for c, kind in zip(dynamics.constraint_names, kinds, strict=True)
                    if kind != ConstraintKind.HOLONOMIC]
        raise ModelError(f"a velocity constraint ({', '.join(velocity)}) takes rates, not "
                         "coordinates, out of the state: there is no reduction to independent "
                         "coordinates; A(t) is given in all of them", field="independent")
    jacobian, rate = dynamics.constraint_rows(q, v, t=t)
    if isinstance(independent, str) and independent == "auto":
        independent = choose_independent(jacobian, names)
    independent = tuple(independent)
    unknown = [name for name in independent if name not in names]
    if unknown:
        raise InputError(f"'{unknown[0]}' is not a coordinate (they are: {', '.join(names)})",
                         field="independent")
    if len(set(independent)) != n - m:
        raise InputError(f"{m} constraint(s) on {n} coordinates leave {n - m} independent; "
                         f"{len(set(independent))} named", field="independent")
    free = [names.index(name) for name in independent]
    tied = [k for k in range(n) if k not in free]
    phi_d, phi_i = jacobian[:, :, tied], jacobian[:, :, free]
    condition = np.linalg.cond(phi_d)
    bad = ~(condition < SINGULAR_CONDITION)
    if bad.any():
        k = int(np.argmax(bad))
        raise InputError(f"at t = {along.t[k]:.9g} s the coordinates {', '.join(independent)} "
                         f"do not fix {', '.join(names[i] for i in tied)} (Phi's Jacobian in "
                         f"those is singular there, condition {condition[k]:.3g}): name others",
                         field="independent")
    count, r = len(q), n - m
    T = np.zeros((count, n, r))
    T[:, free, :] = np.eye(r)
    T[:, tied, :] = -np.linalg.solve(phi_d, phi_i)
    W = np.zeros((count, n, r))
    W[:, tied, :] = -np.linalg.solve(phi_d, rate @ T)
    S = np.zeros((count, 2 * n, 2 * r))
    S[:, :n, :r], S[:, n:, :r], S[:, n:, r:] = T, W, T
    rows = [*free, *(n + k for k in free)]
    A = along.A[:, rows, :] @ S
    B = along.B[:, rows, :]
    # what is printed holds the linearized constraints: Phi_q dq = 0 and c_q dq + Phi_q dq_dot = 0
    held = np.concatenate([jacobian @ T, rate @ T + jacobian @ W], axis=-2)
    scale = 1.0 + np.abs(jacobian).max() * (1.0 + np.abs(S).max()) + np.abs(rate).max()
    if not np.abs(held).max() <= 1e-9 * scale:
        raise ModelError("the tangent basis does not hold the linearized constraints "
                         f"(residual {np.abs(held).max():.3g}); the run is far from them",
                         field="independent")
    return A, B, independent, tuple(names[i] for i in tied)
