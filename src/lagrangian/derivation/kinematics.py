"""Partial-derivative kinematics on plain symbols (q, q_dot and t are independent symbols).

Derivatives go through a memoized structural differentiator: in a chain of bodies every position
repeats the terms of the one before, so each distinct sub-expression is differentiated once
(sympy's own ``diff`` recomputes them and dominates the derivation time otherwise).
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

_ZERO, _ONE = sp.S.Zero, sp.S.One


class Differentiator:
    """d expr / d x with memoized free symbols and derivatives of sub-expressions."""

    def __init__(self) -> None:
        self._free: dict[sp.Basic, frozenset] = {}
        self._memo: dict[tuple[sp.Basic, sp.Symbol], sp.Expr] = {}

    def free_symbols(self, expr: sp.Basic) -> frozenset:
        found = self._free.get(expr)
        if found is None:
            if expr.is_Symbol:
                found = frozenset((expr,))
            elif not expr.args:
                found = frozenset()
            else:
                found = frozenset().union(*(self.free_symbols(a) for a in expr.args))
            self._free[expr] = found
        return found

    def __call__(self, expr: sp.Expr, x: sp.Symbol) -> sp.Expr:
        if x not in self.free_symbols(expr):
            return _ZERO
        key = (expr, x)
        found = self._memo.get(key)
        if found is None:
            found = self._memo[key] = self._derivative(expr, x)
        return found

    def _derivative(self, expr: sp.Expr, x: sp.Symbol) -> sp.Expr:
        if expr is x:
            return _ONE
        if expr.is_Add:
            return sp.Add(*(self(a, x) for a in expr.args if x in self.free_symbols(a)))
        if expr.is_Mul:
            args = expr.args
            terms = []
            for k, factor in enumerate(args):
                if x in self.free_symbols(factor):
                    terms.append(sp.Mul(*args[:k], self(factor, x), *args[k + 1:]))
            return sp.Add(*terms)
        if expr.is_Pow:
            base, exponent = expr.args
            if x not in self.free_symbols(exponent):
                inner = self(base, x)
                if inner.is_Add:
                    # sqrt(u) with u = (x1 - x2)^2 + ...: 1/2 * (2 x1 - 2 x2) is written
                    # (x1 - x2), not (2*x1 - 2*x2)/2 (sympy spreads a number over a sum).
                    content, inner = inner.primitive()
                    return exponent * content * base ** (exponent - 1) * inner
                return exponent * base ** (exponent - 1) * inner
        elif isinstance(expr, sp.sin):
            return sp.cos(expr.args[0]) * self(expr.args[0], x)
        elif isinstance(expr, sp.cos):
            return -sp.sin(expr.args[0]) * self(expr.args[0], x)
        elif isinstance(expr, sp.Abs):
            # Model symbols carry no 'real' assumption, so sympy would answer with re()/im();
            # every model quantity is real, where d|u| = sign(u) du.
            return sp.sign(expr.args[0]) * self(expr.args[0], x)
        elif isinstance(expr, sp.sign):
            return sp.S.Zero  # almost everywhere
        return expr.diff(x)

    def row(self, expr: sp.Expr, variables: Sequence[sp.Symbol]) -> list[sp.Expr]:
        """[d expr / d v for v in variables]."""
        return [self(expr, v) for v in variables]

    def rate(
        self, expr: sp.Expr, q: Sequence[sp.Symbol], q_dot: Sequence[sp.Symbol], t: sp.Symbol
    ) -> sp.Expr:
        """d/dt of expr(q, q_dot, t) along the motion with q_ddot = 0.

        For a position r(q, t) this is its velocity; for a velocity J(q, t) q_dot + r_t it is the
        velocity-product (centripetal, Coriolis) and explicit-time part of the acceleration.
        """
        present = self.free_symbols(expr)
        # Distributed over each partial derivative that is a sum, so a velocity-product term
        # stays a sum of products (which the trig identities work on term by term).
        terms = [term * vi for qi, vi in zip(q, q_dot, strict=True) if qi in present
                 for term in sp.Add.make_args(self(expr, qi))]
        if t in present:
            terms.append(self(expr, t))
        return sp.Add(*terms)


def jacobian_row(expr: sp.Expr, variables: Sequence[sp.Symbol]) -> list[sp.Expr]:
    """[d expr / d v for v in variables] (one-off; use a shared Differentiator in loops)."""
    return Differentiator().row(expr, variables)


def time_rate(
    expr: sp.Expr, q: Sequence[sp.Symbol], q_dot: Sequence[sp.Symbol], t: sp.Symbol
) -> sp.Expr:
    """d/dt of expr(q, q_dot, t) along the motion with q_ddot = 0 (see Differentiator.rate)."""
    return Differentiator().rate(expr, q, q_dot, t)
