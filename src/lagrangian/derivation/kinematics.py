"""Partial-derivative kinematics on plain symbols (q, q_dot and t are independent symbols)."""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp


def jacobian_row(expr: sp.Expr, variables: Sequence[sp.Symbol]) -> list[sp.Expr]:
    """[d expr / d v for v in variables], skipping variables the expression does not contain."""
    present = expr.free_symbols
    return [expr.diff(v) if v in present else sp.S.Zero for v in variables]


def time_rate(
    expr: sp.Expr, q: Sequence[sp.Symbol], q_dot: Sequence[sp.Symbol], t: sp.Symbol
) -> sp.Expr:
    """d/dt of expr(q, q_dot, t) along the motion with q_ddot = 0: sum_i dexpr/dq_i q_dot_i + dexpr/dt.

    For a position r(q, t) this is its velocity; for a velocity J(q, t) q_dot + r_t it is the
    velocity-product (centripetal, Coriolis) and explicit-time part of the acceleration.
    """
    present = expr.free_symbols
    terms = [expr.diff(qi) * vi for qi, vi in zip(q, q_dot, strict=True) if qi in present]
    if t in present:
        terms.append(expr.diff(t))
    return sp.Add(*terms)
