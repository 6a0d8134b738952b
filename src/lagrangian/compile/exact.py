"""Exact numbers made machine numbers, once, before a printer or numpy sees them.

A model's exact integers and rationals stay exact through the derivation; numpy's ufuncs take
no Python int past int64 (cos(10**24) raised TypeError), and C's p/q in doubles overflows where
the quotient does not (10**-600 raised OverflowError). Every function that prints or lambdifies
an expression (codegen.py's statements, before their common subexpressions are taken out,
and lambdified.py's numpy functions) passes it through ``machine_numbers`` first.
"""

from __future__ import annotations

import math

import sympy as sp

from ..errors import ModelError

# An integer up to this is exact in a double and an int64: numpy and C take it as it is.
LARGEST_EXACT = 2 ** 53


def machine_numbers(expr: sp.Expr) -> sp.Expr:
    """``expr`` with each integer past 2^53 in size, and each rational whose numerator or
    denominator is (a power of one too), as the nearest double (mpmath's quotient, rounded; a
    value below double range is 0.0); a number past double range (about 1.8e308) refused.
    Each distinct node is looked at once (a deep chain's shared subtrees, visited as a tree,
    cost minutes), and the expression is rebuilt only where a number changes."""
    if not isinstance(expr, sp.Basic):
        return expr
    swaps = {}
    for node in distinct_nodes([expr]):
        if node.is_Rational and (abs(node.p) > LARGEST_EXACT or node.q > LARGEST_EXACT):
            swaps[node] = _double(node)
        elif node.is_Pow and node.args[0].is_Rational and node.args[1].is_Integer:
            base, exponent = node.args  # 1/10**600 held as a power: its value, not its parts
            if abs(base.p) > LARGEST_EXACT or base.q > LARGEST_EXACT:
                swaps[node] = _double(sp.Rational(base) ** int(exponent))
    if not swaps:
        return expr
    powers = {k: v for k, v in swaps.items() if k.is_Pow}
    expr = expr.xreplace(powers) if powers else expr
    rest = {k: v for k, v in swaps.items() if not k.is_Pow}
    return expr.xreplace(rest) if rest else expr


def distinct_nodes(exprs) -> set:
    """Every distinct sub-expression of ``exprs``, each visited once (sympy's own walks visit a
    shared sub-expression once per occurrence: exponential in the depth of nested rotations)."""
    seen: set = set()
    stack = list(exprs)
    while stack:
        node = stack.pop()
        if node not in seen:
            seen.add(node)
            stack.extend(node.args)
    return seen


def _double(number: sp.Rational) -> sp.Float:
    value = float(number.evalf(20))  # p / q in mpmath: float(p) / float(q) overflowed
    if not math.isfinite(value):
        raise ModelError(f"the number {sp.Float(number, 6)} is beyond double precision's range "
                         "(about 1.8e308): no computation can hold it")
    return sp.Float(value)


__all__ = ["LARGEST_EXACT", "distinct_nodes", "machine_numbers"]
