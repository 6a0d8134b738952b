"""Second-order Taylor jets of sympy expressions, evaluated numerically over their shared
sub-expressions.

A jet of x(t) is (x, x', x''/2) at t = 0 (three Taylor coefficients); sums, products, powers
and the elementary functions map jets to jets exactly (the chain rule truncated at second
order), so the position r(q(t)) of a body along the path q(t) = q + q_dot t + q_ddot t^2/2
gives its velocity and acceleration without any symbolic d/dt. Each coefficient is a numpy
vector over lanes (states, and directions q_dot = e_i for the Jacobians), and each distinct
sub-expression is evaluated once: a deep chain's rotations share their products down the
chain, so the walk costs the size of the expression's graph, not of its printed tree.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import sympy as sp


class UnsupportedExpression(ValueError):
    """An expression holds a function jets are not written for (the caller falls back)."""


Jet = np.ndarray  # shape (3, lanes): x, x', x''/2 (a constant is kept as a float while walking)


def constant(value: float, lanes: int) -> Jet:
    jet = np.zeros((3, lanes))
    jet[0] = value
    return jet


def _mul(a, b):
    if isinstance(a, float) or isinstance(b, float):
        return a * b
    out = np.empty_like(a)
    np.multiply(a[0], b, out=out)
    out[1] += a[1] * b[0]
    out[2] += a[1] * b[1] + a[2] * b[0]
    return out


def _chain(value, first, second, a: Jet) -> Jet:
    """f(a(t)) from f(a0), f'(a0), f''(a0): (f, f' a1, f' a2 + f'' a1^2 / 2)."""
    return np.stack((value, first * a[1], first * a[2] + 0.5 * second * a[1] ** 2))


def _power(a, exponent: float):
    if isinstance(a, float):
        with np.errstate(divide="ignore", invalid="ignore"):
            return float(np.power(a, exponent))
    if exponent == 2:
        return _mul(a, a)
    with np.errstate(divide="ignore", invalid="ignore"):
        return _chain(a[0] ** exponent, exponent * a[0] ** (exponent - 1),
                      exponent * (exponent - 1) * a[0] ** (exponent - 2), a)


def _function(expr: sp.Function, a):
    if isinstance(a, float):  # a constant: the same formulas on a constant jet, then its value
        return float(_function(expr, constant(a, 1))[0, 0])
    x = a[0]
    with np.errstate(divide="ignore", invalid="ignore"):
        if isinstance(expr, sp.sin):
            return _chain(np.sin(x), np.cos(x), -np.sin(x), a)
        if isinstance(expr, sp.cos):
            return _chain(np.cos(x), -np.sin(x), -np.cos(x), a)
        if isinstance(expr, sp.tan):
            t = np.tan(x)
            return _chain(t, 1 + t * t, 2 * t * (1 + t * t), a)
        if isinstance(expr, sp.exp):
            e = np.exp(x)
            return _chain(e, e, e, a)
        if isinstance(expr, sp.log):
            return _chain(np.log(x), 1 / x, -1 / x ** 2, a)
        if isinstance(expr, sp.Abs):
            return np.sign(x) * a
        if isinstance(expr, sp.atan):
            return _chain(np.arctan(x), 1 / (1 + x * x), -2 * x / (1 + x * x) ** 2, a)
        if isinstance(expr, sp.asin):
            r = 1 / np.sqrt(1 - x * x)
            return _chain(np.arcsin(x), r, x * r ** 3, a)
        if isinstance(expr, sp.acos):
            r = 1 / np.sqrt(1 - x * x)
            return _chain(np.arccos(x), -r, -x * r ** 3, a)
    raise UnsupportedExpression(f"no jet for {type(expr).__name__}")


class JetEvaluator:
    """Jets of expressions at given symbol jets, each shared sub-expression once."""

    def __init__(self, symbols: Mapping[sp.Symbol, Jet], lanes: int):
        self.lanes = lanes
        # Keyed by identity: a dict keyed by the expressions would compare deep, equal but
        # distinct sub-trees structurally on every hash match (minutes on a 20-body chain).
        self.memo: dict[int, Jet] = {id(s): jet for s, jet in symbols.items()}
        self.keep: list[sp.Basic] = list(symbols)  # the ids stay valid while we hold them
        self.symbols = dict(symbols)

    def __call__(self, expr) -> Jet:
        return self.jet(self._value(expr))

    def jet(self, value) -> Jet:
        """A constant as a jet over the lanes; a jet unchanged."""
        return constant(value, self.lanes) if isinstance(value, float) else value

    def _value(self, expr):
        if not isinstance(expr, sp.Basic):
            return float(expr)
        memo = self.memo
        found = memo.get(id(expr))
        if found is not None:
            return found
        # Post-order walk without recursion: a 100-body chain nests deeper than Python's stack.
        stack = [(expr, False)]
        while stack:
            node, ready = stack.pop()
            if id(node) in memo:
                continue
            if not ready and node.args and not node.is_Number:
                stack.append((node, True))
                stack.extend((arg, False) for arg in node.args if id(arg) not in memo)
                continue
            memo[id(node)] = self._node(node)
            self.keep.append(node)
        return memo[id(expr)]

    def _node(self, node: sp.Basic) -> Jet:
        if node.is_Number or node.is_NumberSymbol:
            return float(node)  # constants stay scalars: a product by them is one multiply
        if isinstance(node, sp.Symbol):
            found = self.symbols.get(node)  # an equal symbol made anew
            if found is not None:
                return found
            raise UnsupportedExpression(f"no value for the symbol {node}")
        args = [self.memo[id(arg)] for arg in node.args]
        if isinstance(node, sp.Add):
            jets = [a for a in args if not isinstance(a, float)]
            shift = sum(a for a in args if isinstance(a, float))
            if not jets:
                return shift
            out = jets[0].copy()
            for a in jets[1:]:
                out += a
            out[0] += shift  # a constant moves the value only, not the rates
            return out
        if isinstance(node, sp.Mul):
            out = args[0]
            for a in args[1:]:
                out = _mul(out, a)
            return out
        if isinstance(node, sp.Pow):
            if not node.exp.is_Number:
                raise UnsupportedExpression("a power with a symbolic exponent")
            return _power(args[0], float(node.exp))
        if isinstance(node, sp.Function) and len(args) == 1:
            return _function(node, args[0])
        raise UnsupportedExpression(f"no jet for {type(node).__name__}")


__all__ = ["JetEvaluator", "UnsupportedExpression", "constant"]
