"""Derivatives of the dynamics: d tau/dq, d tau/dq_dot of inverse dynamics, and of forward
dynamics d q_ddot/dq = -M^-1 d tau/dq, d q_ddot/dq_dot = -M^-1 d tau/dq_dot, d q_ddot/d tau =
M^-1 (tau evaluated at q_ddot = FD(q, q_dot, tau)), as Pinocchio's computeABADerivatives.

- A model file: generated from the derived equations (tau = M(q) q_ddot - f(q, q_dot)):
  d tau/dq_k = dM/dq_k q_ddot - df/dq_k, d tau/dq_dot = -df/dq_dot, differentiated by sympy
  once and compiled (numpy), exact.
- A URDF tree without its compiled module: the complex step through the numpy reference's
  recursive Newton-Euler: tau(q (+) i h e_k) with h = 1e-40 gives d tau/dq_k = Im tau / h,
  exact to rounding (no difference is taken, so nothing cancels: this is not a finite
  difference), along the tangent of every joint's chart (ball joints and free flyers too).
  Units SI.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..compile.lambdified import StateFunction
from ..model.expressions import as_expression
from ..model.quaternions import quaternion_matrix

# The complex step: small enough that h^2 terms vanish beside 1 in double precision, large
# enough that h times the largest derivative is no subnormal.
STEP = 1e-40


def tangent_steps(recursions, Q, h: float) -> np.ndarray:
    """Q (N, nq) moved by i h along each of the nv velocity numbers, (N, nv, nq) complex: q (+)
    i h e_k to first order in h, on the tree's own charts (a one-number joint: q_c + i h; a ball
    joint's quaternion w x y z, q (x) (0, i h e_r / 2), its turn in its body's axes; a free
    flyer's, the base's or one below the root's: x y z + R(q) i h e_r, its quaternion x y z w
    (x) (i h e_r / 2, 0)), as Pinocchio's integrate (q (x) exp(dq)), so that the slopes are
    its derivatives along the tangent."""
    count, nq = Q.shape
    out = np.repeat(Q[:, None, :].astype(complex), recursions.n, axis=1)
    step = 1j * h
    units = np.eye(3)
    seen = set()
    for j in recursions._joints:
        if j.free or j.inner:  # x y z, then x y z w
            iq, iv = (0, 0) if j.free else (j.iq, j.iv)
            quaternion = Q[:, iq + 3:iq + 7]
            vector, scalar = quaternion[:, :3], quaternion[:, 3:]
            R = quaternion_matrix(quaternion)
            for r in range(3):
                out[:, iv + r, iq:iq + 3] += step * R[:, :, r]
                turn = scalar * units[r] + np.cross(vector, units[r])  # q (x) (e_r, 0), vector
                out[:, iv + 3 + r, iq + 3:iq + 6] += 0.5 * step * turn
                out[:, iv + 3 + r, iq + 6] -= 0.5 * step * vector[:, r]
        elif j.ball:  # w x y z
            quaternion = Q[:, j.iq:j.iq + 4]
            scalar, vector = quaternion[:, :1], quaternion[:, 1:]
            for r in range(3):
                out[:, j.iv + r, j.iq] -= 0.5 * step * vector[:, r]
                out[:, j.iv + r, j.iq + 1:j.iq + 4] += 0.5 * step * (
                    scalar * units[r] + np.cross(vector, units[r]))
        elif (j.iq, j.iv) not in seen:  # mimic joints share their coordinate's one step
            seen.add((j.iq, j.iv))
            out[:, j.iv, j.iq] += step
    return out


def tree_inverse_dynamics_derivatives(recursions, Q, V, A):
    """(d tau/dq, d tau/dq_dot), (N, nv, nv) each, by the complex step through the numpy
    reference's Newton-Euler (recursive_numpy.NumpyBackend: one batched pass over 2 nv moved
    copies of each state); d/dq along the tangent of q's charts (tangent_steps), as
    Pinocchio's computeRNEADerivatives for every joint kind."""
    count, n = V.shape
    nq = Q.shape[1]
    Qc = np.concatenate([tangent_steps(recursions, Q, STEP),
                         np.repeat(Q[:, None, :].astype(complex), n, axis=1)], axis=1)
    Vc = V[:, None, :] + np.concatenate([np.zeros((n, n)), 1j * STEP * np.eye(n)])
    Ac = np.broadcast_to(A[:, None, :], Vc.shape).astype(complex)
    tau = recursions._newton_euler(Qc.reshape(-1, nq), Vc.reshape(-1, n), Ac.reshape(-1, n))
    slopes = tau.imag.reshape(count, 2 * n, n) / STEP  # [k, i] = d tau_i / d x_k
    return np.swapaxes(slopes[:, :n], -1, -2), np.swapaxes(slopes[:, n:], -1, -2)


class ModelDerivatives:
    """d tau/dq and d tau/dq_dot of a model file's tau = M(q) q_ddot - f(q, q_dot), from the
    derived M and f differentiated symbolically once (numpy functions of the state, t = 0)."""

    def __init__(self, eom, values: dict):
        model = eom.model
        n = len(model.q)
        substitution = {p.symbol: sp.Float(float(values[p.name])) for p in model.parameters
                        if values.get(p.name) is not None}
        mass = [as_expression(e) for e in eom.mass_matrix]
        forcing = [as_expression(e) for e in eom.forcing]
        self.n = n
        # dM_ij/dq_k as [k][i][j], df_i/dq_k as [i][k], df_i/dq_dot_k as [i][k]
        self._mass = StateFunction(model, [e.diff(q) for q in model.q for e in mass],
                                   substitution)
        self._position = StateFunction(model, [f.diff(q) for f in forcing for q in model.q],
                                       substitution)
        self._velocity = StateFunction(model, [f.diff(v) for f in forcing for v in model.q_dot],
                                       substitution)

    def __call__(self, Q, V, A):
        count, n = len(Q), self.n
        mass = self._mass(Q, V, 0.0).reshape(count, n, n, n)  # [N, k, i, j]
        by_position = np.einsum("nkij,nj->nik", mass, A) \
            - self._position(Q, V, 0.0).reshape(count, n, n)
        return by_position, -self._velocity(Q, V, 0.0).reshape(count, n, n)
