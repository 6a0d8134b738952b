"""The model-file expression grammar's vocabulary and bounds: its functions and constants, the
limits every expression is held to (length, size, depth, digits), and the parsed tree's node."""

from __future__ import annotations

import math
import re

import sympy as sp

FUNCTIONS: dict[str, tuple[object, int]] = {
    "sin": (sp.sin, 1),
    "cos": (sp.cos, 1),
    "tan": (sp.tan, 1),
    "asin": (sp.asin, 1),
    "acos": (sp.acos, 1),
    "atan": (sp.atan, 1),
    "atan2": (sp.atan2, 2),
    "sinh": (sp.sinh, 1),
    "cosh": (sp.cosh, 1),
    "tanh": (sp.tanh, 1),
    "exp": (sp.exp, 1),
    "log": (sp.log, 1),
    "sqrt": (sp.sqrt, 1),
    "abs": (sp.Abs, 1),
    "sign": (sp.sign, 1),
}
CONSTANTS: dict[str, sp.Expr] = {"pi": sp.pi}
# A name of the grammar: a coordinate, parameter, definition or component.
IDENTIFIER = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
RESERVED = frozenset(FUNCTIONS) | frozenset(CONSTANTS) | {"t"}

MAX_LENGTH = 50_000  # parsing and converting stay under about 1 s
# An expression written out in full (definitions substituted, each use a copy): sympy walks many
# expressions as trees, so 25 definitions that each use the one before twice cost 2^25 nodes.
MAX_TREE_NODES = 20_000  # derive of such a term takes ~15 s (measured: 5,600 nodes 4 s)
MAX_DEPTH = 100  # nesting (parentheses, calls, powers, signs); flat sums and products are free
MAX_EXPONENT = 1000
MAX_NUMBER_DIGITS = 300  # every number's size is below 10**300 (and a literal above 10**-300)
MAX_EXACT_DIGITS = 1000  # numerator and denominator of an exact rational
# Digits sympy may handle on the way to an exact power or sum (a 10**5-digit product is ms).
_MAX_WORK_DIGITS = 100_000
_LIMIT = 10.0**MAX_NUMBER_DIGITS

# Float twins of the functions, to bound a constant's value before sympy computes it.
_FLOAT_FUNCTIONS = {
    "sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin, "acos": math.acos,
    "atan": math.atan, "atan2": math.atan2, "sinh": math.sinh, "cosh": math.cosh,
    "tanh": math.tanh, "exp": math.exp, "log": math.log, "sqrt": math.sqrt, "abs": abs,
    "sign": lambda x: float((x > 0) - (x < 0)),
}
_INFINITIES = (sp.zoo, sp.oo, -sp.oo)


class _Node:
    """One node of the parsed expression; ``start:end`` is its span in the user's text."""

    __slots__ = ("kind", "value", "children", "start", "end", "depth")

    def __init__(self, kind, value, children, start, end, depth=1):
        self.kind, self.value, self.children = kind, value, children
        self.start, self.end, self.depth = start, end, depth


def _digits(value: int) -> int:
    """Decimal digits of an integer, from its bit length (never printed: no 4300-digit limit)."""
    return int(abs(value).bit_length() * 0.30103) + 1


__all__ = ["CONSTANTS", "FUNCTIONS", "IDENTIFIER", "MAX_DEPTH", "MAX_EXACT_DIGITS",
           "MAX_EXPONENT", "MAX_LENGTH", "MAX_NUMBER_DIGITS", "MAX_TREE_NODES", "RESERVED"]
