"""Derivatives of the dynamics: d tau/dq, d tau/dq_dot of inverse dynamics, and of forward
dynamics d q_ddot/dq = -M^-1 d tau/dq, d q_ddot/dq_dot = -M^-1 d tau/dq_dot, d q_ddot/d tau =
M^-1 (tau evaluated at q_ddot = FD(q, q_dot, tau)), as Pinocchio's computeABADerivatives.

- A model file: generated from the derived equations (tau = M(q) q_ddot - f(q, q_dot)):
  d tau/dq_k = dM/dq_k q_ddot - df/dq_k, d tau/dq_dot = -df/dq_dot, differentiated by sympy
  once and compiled (numpy), exact.
- A URDF tree: the complex step through the recursive Newton-Euler in numpy: tau(q + i h e_k)
  with h = 1e-40 gives d tau/dq_k = Im tau / h, exact to rounding (no difference is taken, so
  nothing cancels: this is not a finite difference). Units SI.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..compile.lambdified import StateFunction
from ..model.expressions import as_expression
from .regressor import cross_matrix, tree_motion

# The complex step: small enough that h^2 terms vanish beside 1 in double precision, large
# enough that h times the largest derivative is no subnormal.
STEP = 1e-40


def tree_inverse_dynamics(tree, gravity: float, Q, V, A) -> np.ndarray:
    """tau (N, n) by recursive Newton-Euler, real or complex inputs (the actuator parameters
    aside)."""
    count, n = Q.shape
    placements, spaces, w, dw, acc = tree_motion(tree, gravity, Q, V, A)
    dtype = np.result_type(Q, V, A, float)
    forces, moments = [], []
    for joint, w_i, dw_i, a_i in zip(tree.joints, w, dw, acc, strict=True):
        m, h, J = joint.mass, np.array(joint.first_moment), np.array(joint.inertia)
        forces.append(m * a_i + np.cross(dw_i, h) + np.cross(w_i, np.cross(w_i, h)))
        moments.append(dw_i @ J.T + np.cross(w_i, w_i @ J.T) + np.cross(h, a_i))
    tau = np.zeros((count, n), dtype=dtype)
    for i in reversed(range(len(tree.joints))):
        joint = tree.joints[i]
        s_w, s_v = spaces[i]
        if s_w is not None:
            tau[:, joint.coordinate] += joint.multiplier * (moments[i] @ s_w)
        if s_v is not None:
            tau[:, joint.coordinate] += joint.multiplier * (forces[i] @ s_v)
        if joint.parent >= 0:
            R, p = placements[i]
            force = np.einsum("nij,nj->ni", R, forces[i])
            forces[joint.parent] = forces[joint.parent] + force
            moments[joint.parent] = (moments[joint.parent] + np.einsum("nij,nj->ni", R, moments[i])
                                     + np.einsum("nij,nj->ni", cross_matrix(p), force))
    return tau


def tree_inverse_dynamics_derivatives(tree, gravity: float, Q, V, A):
    """(d tau/dq, d tau/dq_dot), (N, n, n) each, by the complex step (one batched pass over
    2 n perturbed copies of each state)."""
    count, n = Q.shape
    step = 1j * STEP * np.eye(n)
    zero = np.zeros((n, n))
    Qc = (Q[:, None, :] + np.concatenate([step, zero]))  # (N, 2n, n)
    Vc = (V[:, None, :] + np.concatenate([zero, step]))
    Ac = np.broadcast_to(A[:, None, :], Qc.shape)
    tau = tree_inverse_dynamics(tree, gravity, Qc.reshape(-1, n), Vc.reshape(-1, n),
                                Ac.reshape(-1, n).astype(complex))
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
