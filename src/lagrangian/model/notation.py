"""How the model's symbols are written in LaTeX: q_dot as a dot over q, multipliers as lambda.

Dots go on the symbol's body, before its subscript, as sympy.physics.mechanics' ``vlatex``
writes them: ``\\dot{\\theta}_{1}^{2}``, not ``\\dot{\\theta_{1}}^{2}`` (whose exponent floats
beside the accent).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence

import sympy as sp
from sympy.printing.latex import LatexPrinter

from .model import Model, multiplier_name
from .printing import MemoizedPrinting


def dotted(base: str, dots: int) -> str:
    """``base`` (a symbol's LaTeX) with ``dots`` dots over its body, the subscript after:
    ``\\theta_{1}`` -> ``\\dot{\\theta}_{1}``."""
    depth = 0
    for i, char in enumerate(base):
        if char == "{":
            depth += 1
        elif char == "}":
            depth -= 1
        elif char in "_^" and depth == 0 and i > 0:
            body, tail = base[:i], base[i:]
            break
    else:
        body, tail = base, ""
    accent = {1: r"\dot", 2: r"\ddot", 3: r"\dddot"}[dots]
    return rf"{accent}{{{body}}}{tail}"


def latex_symbol_names(model: Model) -> dict[sp.Symbol, str]:
    """Symbol -> LaTeX for velocities, accelerations and multipliers of ``model``."""
    names: dict[sp.Symbol, str] = {}
    for c in model.coordinates:
        base = sp.latex(c.symbol)
        names[c.velocity] = dotted(base, 1)
        names[c.acceleration] = dotted(base, 2)
    for constraint in model.constraints:
        label = constraint.name.replace("_", r"\_")
        names[sp.Symbol(multiplier_name(constraint.name))] = rf"\lambda_{{\mathrm{{{label}}}}}"
    return names


_ACCENTED_WORD = re.compile(r"^\\d*dot\{(?!\\[A-Za-z]+\}$)[^{}]{2,}\}$")


class ModelLatexPrinter(MemoizedPrinting, LatexPrinter):
    """sympy's LaTeX printer with a model's symbol names, each sub-expression printed once."""

    def _print_Pow(self, expr):
        # A power of a dotted word (\dot{lean}^{2}) would be raised above the dot: set at
        # the height of a plain letter's exponent instead.
        name = self._settings["symbol_names"].get(expr.base)
        if name and _ACCENTED_WORD.match(name) and expr.exp.is_Integer and expr.exp > 1:
            return f"{name}{{}}^{{{expr.exp}}}"
        return super()._print_Pow(expr)

    def signed_terms(self, expr: sp.Expr) -> list[tuple[bool, str]]:
        """The terms of a sum in print order as (negative, LaTeX of the magnitude)."""
        return [_signed(self._print(term)) for term in self.terms_in_order(expr)]

    def terms_in_order(self, expr: sp.Expr) -> list[sp.Expr]:
        """The terms of a sum in the order this printer writes them ([expr] for a non-sum)."""
        return list(self._as_ordered_terms(expr)) if expr.is_Add else [expr]

    def _as_ordered_terms(self, expr, order=None):
        # Ordered once per sum: printing it and breaking it over lines both ask.
        if (order or self.order) is not None:
            return super()._as_ordered_terms(expr, order=order)
        memo = self.__dict__.setdefault("_ordered_memo", {})
        found = memo.get(expr)
        if found is None:
            found = memo[expr] = super()._as_ordered_terms(expr, order=order)
        return found

    def product_terms(self, pairs: Sequence[tuple[sp.Expr, sp.Symbol]]) -> list[tuple[bool, str]]:
        """sum coefficient * unknown as (negative, LaTeX) terms, the unknown after its
        coefficient (``l^{2} m \\ddot{\\theta}``), a sum coefficient in parentheses."""
        terms = []
        for coefficient, unknown in pairs:
            if coefficient == 0:
                continue
            negative = coefficient.could_extract_minus_sign()
            magnitude = -coefficient if negative else coefficient
            if magnitude == 1:
                text = self._print(unknown)
            elif magnitude.is_Add:
                text = rf"\left({self._print(magnitude)}\right) {self._print(unknown)}"
            else:
                text = f"{self._print(magnitude)} {self._print(unknown)}"
            terms.append((negative, text))
        return terms


def _signed(text: str) -> tuple[bool, str]:
    return (True, text[1:].lstrip()) if text.startswith("-") else (False, text)


def join_terms(terms: Sequence[tuple[bool, str]]) -> str:
    """(negative, LaTeX) terms as one sum: ``a - b + c``; ``0`` for none."""
    out = ""
    for negative, text in terms:
        if not out:
            out = f"- {text}" if negative else text
        else:
            out += f" - {text}" if negative else f" + {text}"
    return out or "0"


def model_latex_printer(model: Model) -> ModelLatexPrinter:
    """One printer for a whole document, so repeated sub-expressions are printed once."""
    return ModelLatexPrinter({"symbol_names": latex_symbol_names(model)})


def latex_printer(model: Model) -> Callable[[sp.Basic], str]:
    """``expr -> LaTeX`` with the model's symbol names (as ``sp.latex(expr, symbol_names=...)``);
    one printer for a whole document, so repeated sub-expressions are printed once."""
    return model_latex_printer(model).doprint
