"""The parsed expression tree (grammar._Node) to sympy, each constant carried beside its float
twin so that a value that would be infinite, non-real or above 1e300 in size is refused before
sympy computes it (model/expressions.py parses; this builds)."""

from __future__ import annotations

import math

import sympy as sp

from .grammar import (
    _FLOAT_FUNCTIONS,
    _INFINITIES,
    _LIMIT,
    _MAX_WORK_DIGITS,
    CONSTANTS,
    FUNCTIONS,
    MAX_EXACT_DIGITS,
    MAX_EXPONENT,
    MAX_NUMBER_DIGITS,
    _digits,
    _Node,
)
from .tokens import _quote


class _Converter:
    """Builds sympy from the parsed tree. Beside each constant it carries a float twin, so a
    value that would be infinite, non-real or too large is refused before sympy works on it."""

    def __init__(self, names, fail, text):
        self.names = names
        self.fail = fail
        self.text = text
        self.name_values: dict[str, float | None] = {}

    def expression(self, tree: _Node) -> sp.Expr:
        expr, _ = self.visit(tree)
        self.final_check(expr)
        return expr

    def quote(self, node: _Node) -> str:
        return _quote(self.text, node.start, node.end)

    def visit(self, node: _Node) -> tuple[sp.Expr, float | None]:
        kind = node.kind
        if kind == "number":
            return node.value, float(node.value)
        if kind == "name":
            return self.name(node.value)
        if kind == "neg":
            operand, value = self.visit(node.children[0])
            return -operand, None if value is None else -value
        if kind == "add":
            return self.sum(node)
        if kind == "mul":
            return self.product(node)
        if kind == "pow":
            return self.power(node)
        return self.call(node)

    def name(self, name: str) -> tuple[sp.Expr, float | None]:
        expr = self.names[name] if name in self.names else CONSTANTS[name]
        if name not in self.name_values:
            self.name_values[name] = _float_of_constant(expr)
        return expr, self.name_values[name]

    def sum(self, node: _Node) -> tuple[sp.Expr, float | None]:
        terms, values = [], []
        for negative, child in node.children:
            expr, value = self.visit(child)
            terms.append(-expr if negative else expr)
            values.append(None if value is None else (-value if negative else value))
        self.check_work(terms, node)
        value = None
        if None not in values:
            value = math.fsum(values)
            if not abs(value) < _LIMIT:
                raise self.fail(f"the sum {self.quote(node)} is too large a number "
                                f"(beyond 1e{MAX_NUMBER_DIGITS})")
        result = sp.Add(*terms)
        self.check(result, node)
        return result, value if value is not None else _float_of_number(result)

    def product(self, node: _Node) -> tuple[sp.Expr, float | None]:
        factors, values = [], []
        for inverse, child in node.children:
            expr, value = self.visit(child)
            if inverse:
                if expr == 0:
                    raise self.fail(f"division by zero in {_quote(self.text)}")
                expr, value = 1 / expr, (1 / value) if value else None
            factors.append(expr)
            values.append(value)
        self.check_work(factors, node)
        value = None
        if None not in values:
            value = math.prod(values)
            if not abs(value) < _LIMIT:
                raise self.fail(f"the product {self.quote(node)} is too large a number "
                                f"(beyond 1e{MAX_NUMBER_DIGITS})")
        result = sp.Mul(*factors)
        self.check(result, node)
        return result, value if value is not None else _float_of_number(result)

    def check_work(self, operands: list[sp.Expr], node: _Node) -> None:
        """An exact sum or product of many rationals: refuse before sympy multiplies it out."""
        digits = sum(_digits(e.p) + _digits(e.q) for e in operands if e.is_Rational)
        if digits > _MAX_WORK_DIGITS:
            raise self.fail(f"the exact value of {self.quote(node)} has too many digits "
                            f"(more than {MAX_EXACT_DIGITS}): write it as a decimal number")

    def power(self, node: _Node) -> tuple[sp.Expr, float | None]:
        base, base_value = self.visit(node.children[0])
        exponent, exponent_value = self.visit(node.children[1])
        if exponent.is_Number and abs(exponent) > MAX_EXPONENT:
            raise self.fail(f"the exponent {exponent} is too large (at most {MAX_EXPONENT})")
        if base == 0 and (exponent.is_negative or (exponent_value or 0) < 0):
            raise self.fail(f"division by zero in {_quote(self.text)}")
        value: float | complex | None = None
        if base_value is not None and exponent_value is not None:
            try:
                value = base_value**exponent_value
            except OverflowError:
                value = math.inf
            except ZeroDivisionError:  # a base that underflowed to 0.0 (exp(-800)^-1)
                value = math.inf
            if not abs(value) < _LIMIT:
                raise self.fail(f"the power {self.quote(node)} is too large a number "
                                f"(beyond 1e{MAX_NUMBER_DIGITS})")
        self.check_power_cost(base, exponent, value, node)
        result = base**exponent
        if isinstance(value, complex):
            if not result.is_Number:  # rounding can make a zero base slightly negative
                raise self.fail(f"{self.quote(node)} is not a real number")
            value = float(result)
        self.check(result, node)
        return result, value if value is not None else _float_of_number(result)

    def check_power_cost(self, base, exponent, value, node) -> None:
        """Exact powers of rationals grow by digits, not by size: 1.0000001^1000 has 7000."""
        if not exponent.is_Rational or exponent.is_zero:
            return
        numerator, denominator = _exact_digits(base)
        if numerator + denominator == 0:
            return
        about = f" (about {value:.6g})" if isinstance(value, float) else ""
        size = round(math.ceil(abs(exponent)) * max(numerator, denominator))
        if size > MAX_EXACT_DIGITS:
            raise self.fail(f"the exact value of {self.quote(node)} has about {size} digits "
                            f"(at most {MAX_EXACT_DIGITS}): write it as a decimal number{about}")
        if exponent.q != 1 and exponent.q * (numerator + denominator) > _MAX_WORK_DIGITS:
            raise self.fail(f"the exact value of {self.quote(node)} is too costly to compute "
                            f"(a rational power with a {_digits(exponent.q)}-digit denominator): "
                            f"write it as a decimal number{about}")

    def call(self, node: _Node) -> tuple[sp.Expr, float | None]:
        name = node.value
        function = FUNCTIONS[name][0]
        visited = [self.visit(child) for child in node.children]
        args = [expr for expr, _ in visited]
        values = [value for _, value in visited]
        value = None
        outside_domain = False
        if None not in values:
            try:
                value = float(_FLOAT_FUNCTIONS[name](*values))
            except OverflowError:
                value = math.inf
            except (ValueError, ZeroDivisionError):
                outside_domain = True
            if value is not None and not abs(value) < _LIMIT:
                raise self.fail(f"the value of {self.quote(node)} is too large a number "
                                f"(beyond 1e{MAX_NUMBER_DIGITS})")
        result = function(*args)
        if outside_domain:
            # the float twin says log(0), sqrt(-1), asin(2), ...: sympy's exact value decides
            self.check(result, node)
            if not result.is_Number:
                raise self.fail(f"{self.quote(node)} is not a real number")
            value = float(result)
        self.check(result, node)
        return result, value if value is not None else _float_of_number(result)

    def check(self, expr: sp.Expr, node: _Node) -> None:
        """The value (or the numeric coefficient) of ``expr`` must be a finite real number."""
        candidates = [expr]
        if expr.is_Add or expr.is_Mul:
            candidates = list(expr.args[:2])
        for c in candidates:
            if any(c is infinity for infinity in _INFINITIES):
                raise self.fail(f"{self.quote(node)} is infinite")
            if c is sp.nan:
                raise self.fail(f"{self.quote(node)} is undefined (0/0, infinity - infinity, "
                                f"0*infinity or similar)")
            if c is sp.I:
                raise self.fail(f"{self.quote(node)} is not a real number")
            if c.is_Rational:
                if max(_digits(c.p), _digits(c.q)) > MAX_EXACT_DIGITS:
                    raise self.fail(f"the exact value of {self.quote(node)} has more than "
                                    f"{MAX_EXACT_DIGITS} digits: write it as a decimal number")
                if _digits(c.p) - _digits(c.q) > MAX_NUMBER_DIGITS:
                    raise self.fail(f"a number in {self.quote(node)} is too large "
                                    f"(beyond 1e{MAX_NUMBER_DIGITS})")
            elif c.is_Float and not math.isfinite(float(c)):
                raise self.fail(f"{self.quote(node)} is not finite")

    def final_check(self, expr: sp.Expr) -> None:
        """A last walk: no infinity, NaN or imaginary unit anywhere (from cancellations such
        as log(theta - theta))."""
        for part in sp.preorder_traversal(expr):
            if any(part is infinity for infinity in _INFINITIES):
                raise self.fail(f"{_quote(self.text)} is infinite")
            if part is sp.nan:
                raise self.fail(f"{_quote(self.text)} is undefined (NaN)")
            if part is sp.I:
                raise self.fail(f"{_quote(self.text)} is not a real number")


def _log10(value: int) -> float:
    return math.log10(abs(value)) if value else 0.0


def _exact_digits(base: sp.Expr) -> tuple[float, float]:
    """Digits (log10) of numerator and denominator of the rationals sympy multiplies out when
    it raises ``base`` to a rational power (its coefficient and rational radicals)."""
    numerator = denominator = 0.0
    for factor in (base.args if base.is_Mul else (base,)):
        if factor.is_Pow and factor.base.is_Rational and factor.exp.is_Rational:
            factor = factor.base
        if factor.is_Rational:
            numerator += _log10(factor.p)
            denominator += _log10(factor.q)
    return numerator, denominator


def _float_of_number(expr: sp.Expr) -> float | None:
    if expr.is_Number and expr.is_finite:
        value = float(expr)
        return value if math.isfinite(value) else None
    return None


def _float_of_constant(expr: object) -> float | None:
    """The float value of a name's value when it is a constant (pi, a constant definition)."""
    if not isinstance(expr, sp.Expr):
        return None
    if expr.is_Number:
        return _float_of_number(expr)
    if expr.free_symbols:
        return None
    try:
        value = complex(expr.evalf(20))
    except (TypeError, ValueError, OverflowError):
        return None
    if value.imag or not math.isfinite(value.real):
        return None
    return value.real
