"""Constraint terms: Jacobian Phi_q (or A), velocity bias and the acceleration-level right side.

Holonomic Phi(q, t) = 0 gives Phi_q q_dot + Phi_t = 0 and Phi_q q_ddot = gamma; a velocity
constraint A(q, t) q_dot + b(q, t) = 0 enters only through A^T lambda, never substituted into L.
"""

from __future__ import annotations

import sympy as sp

from ..kinds import ConstraintKind
from ..model.model import Model
from .kinematics import jacobian_row, time_rate


def constraint_terms(
    model: Model,
) -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix, sp.ImmutableMatrix]:
    """(Jacobian m x n, velocity bias b m x 1, gamma m x 1) with Jacobian q_dot + b = 0."""
    q, q_dot, t = model.q, model.q_dot, model.time
    n = len(q)
    rows, biases, gammas = [], [], []
    zero_velocity = {v: sp.S.Zero for v in q_dot}
    for constraint in model.constraints:
        if constraint.kind == ConstraintKind.HOLONOMIC:
            row = jacobian_row(constraint.expression, q)
            velocity_level = time_rate(constraint.expression, q, q_dot, t)
            bias = constraint.expression.diff(t) if t in constraint.expression.free_symbols \
                else sp.S.Zero
        else:
            row = jacobian_row(constraint.expression, q_dot)
            velocity_level = constraint.expression
            bias = constraint.expression.xreplace(zero_velocity)
        rows.append(row)
        biases.append(bias)
        # d/dt(A q_dot + b) = A q_ddot + (rest) = 0  =>  A q_ddot = -(rest)
        gammas.append(-time_rate(velocity_level, q, q_dot, t))
    m = len(rows)
    return (
        sp.ImmutableMatrix(m, n, [x for row in rows for x in row]),
        sp.ImmutableMatrix(m, 1, biases),
        sp.ImmutableMatrix(m, 1, gammas),
    )
