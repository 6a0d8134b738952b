"""Faster sympy printing with the same output: memoized sub-expressions and term order.

Printing, not deriving, dominated `derive` for chains (the 30-link pendulum: 1 s to derive,
8 s to print): every sum in every entry was ordered again with sympy's
``Expr.as_ordered_terms``, which evaluates each rational coefficient with ``evalf``, and the
mass sums (m2 + ... + m30) recur in hundreds of entries. ``ordered_terms`` is that ordering
(sympy's own algorithm, order=None) with rationals converted directly to float (the correctly
rounded value evalf gives too), and ``MemoizedPrinting`` prints each distinct sub-expression
once. The strings are the ones sympy's printers give.
"""

from __future__ import annotations

import sympy as sp
from sympy.core.exprtools import decompose_power
from sympy.core.sorting import default_sort_key
from sympy.printing.str import StrPrinter

_MEMO_LIMIT = 200_000  # printed sub-expressions kept per printer before the memo is cleared


def _complex(x: sp.Expr) -> complex:
    if x.is_Rational:
        return complex(float(x))
    return complex(x)


def _not_number(x: sp.Expr) -> bool:
    return not isinstance(x, sp.Number | sp.NumberSymbol)


def ordered_terms(expr: sp.Expr) -> list[sp.Expr]:
    """The terms of a sum in the order sympy's printers use (``as_ordered_terms()``)."""
    if not expr.is_Add or any(term.is_Order for term in expr.args):
        return list(expr.as_ordered_terms())
    # sympy's special case: a positive number and a negative multiple print number first.
    first = sorted(expr.args, key=_not_number)
    if len(first) == 2 and not _not_number(first[0]) and isinstance(first[1], sp.Mul):
        factors = sorted(sp.Mul.make_args(first[1]), key=_not_number)
        if (len(factors) == 2 and isinstance(factors[0], sp.Number)
                and first[0].is_positive and factors[0].is_negative):
            return first
    generators: set[sp.Expr] = set()
    terms = []
    for term in expr.args:
        coefficient, rest = term.as_coeff_Mul()
        coefficient = _complex(coefficient)
        powers, noncommutative = {}, []
        if rest is not sp.S.One:
            for factor in sp.Mul.make_args(rest):
                if factor.is_number:
                    try:
                        coefficient *= _complex(factor)
                    except (TypeError, ValueError):
                        pass
                    else:
                        continue
                if factor.is_commutative:
                    base, exponent = decompose_power(factor)
                    powers[base] = exponent
                    generators.add(base)
                else:
                    noncommutative.append(factor)
        terms.append((term, coefficient, powers, noncommutative))
    index = {g: i for i, g in enumerate(sorted(generators, key=default_sort_key))}
    keyed = []
    for term, coefficient, powers, noncommutative in terms:
        monomial = [0] * len(index)
        for base, exponent in powers.items():
            monomial[index[base]] = -exponent  # sympy sorts the negated lex monomial
        re, im = coefficient.real, coefficient.imag
        keyed.append(((tuple(monomial), tuple(e.sort_key() for e in noncommutative),
                       ((bool(im), im), (re, im))), term))
    keyed.sort(key=lambda item: item[0])
    return [term for _, term in keyed]


class MemoizedPrinting:
    """Mixin for a sympy Printer: each sub-expression printed once, sums ordered fast.

    A sub-expression's text does not depend on where it appears (parentheses are added by the
    caller), so a printer with fixed settings may reuse it.
    """

    def _print(self, expr, **kwargs):
        if kwargs:
            return super()._print(expr, **kwargs)
        memo = self.__dict__.get("_memo")
        if memo is None or len(memo) > _MEMO_LIMIT:
            memo = self.__dict__["_memo"] = {}
        try:
            found = memo.get(expr)
        except TypeError:  # unhashable (a mutable matrix)
            return super()._print(expr)
        if found is None:
            found = memo[expr] = super()._print(expr)
        return found

    def _as_ordered_terms(self, expr, order=None):
        if (order or self.order) is None:
            return ordered_terms(expr)
        return super()._as_ordered_terms(expr, order=order)


# -- the model grammar, printed back ----------------------------------------------------

class _GrammarPrinter(MemoizedPrinting, StrPrinter):
    """Prints sympy back into the model-file grammar (what :func:`parse_expression` reads)."""

    def _print_Abs(self, expr):
        return f"abs({self._print(expr.args[0])})"

    def _print_Exp1(self, expr):
        return "exp(1)"

    def _print_Pi(self, expr):
        return "pi"

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Pow(self, expr, rational=False):
        base, exponent = expr.args
        if exponent is sp.S.Half:
            return f"sqrt({self._print(base)})"
        if exponent == -sp.S.Half:
            return f"1/sqrt({self._print(base)})"
        return super()._print_Pow(expr, rational)


_PRINTER = _GrammarPrinter({"order": None})


def as_expression(value: object) -> sp.Basic:
    """A sympy object or a Python number as a sympy object.

    Strings are refused: user text goes through :func:`parse_expression` only.
    """
    if isinstance(value, sp.Basic):
        return value
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise TypeError(f"expected a sympy object or a number, got {type(value).__name__}")
    return sp.Integer(value) if isinstance(value, int) else sp.Float(value)


def format_expression(expr: sp.Expr) -> str:
    """Format a sympy expression as a string of the model-file grammar."""
    return _PRINTER.doprint(as_expression(expr))


def shown_expression(expr: sp.Expr) -> str:
    """``format_expression`` for a message, an exact number of over 20 digits shown to 3
    figures (1/10^600 as 1.00e-600, not its 600 digits): display only, not read back."""
    long = {a: sp.sign(a) * sp.Symbol(str(sp.Float(abs(a), 3)))
            for a in sp.sympify(expr).atoms(sp.Rational) if len(str(abs(a))) > 20}  # safe: sympy
    return format_expression(expr.xreplace(long) if long else expr)
