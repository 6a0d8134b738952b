"""How the model's symbols are written in LaTeX: q_dot as a dot over q, multipliers as lambda."""

from __future__ import annotations

from collections.abc import Callable

import sympy as sp
from sympy.printing.latex import LatexPrinter

from .model import Model, multiplier_name
from .printing import MemoizedPrinting


def latex_symbol_names(model: Model) -> dict[sp.Symbol, str]:
    """Symbol -> LaTeX for velocities, accelerations and multipliers of ``model``."""
    names: dict[sp.Symbol, str] = {}
    for c in model.coordinates:
        base = sp.latex(c.symbol)
        names[c.velocity] = rf"\dot{{{base}}}"
        names[c.acceleration] = rf"\ddot{{{base}}}"
    for constraint in model.constraints:
        label = constraint.name.replace("_", r"\_")
        names[sp.Symbol(multiplier_name(constraint.name))] = rf"\lambda_{{\mathrm{{{label}}}}}"
    return names


class _LatexPrinter(MemoizedPrinting, LatexPrinter):
    """sympy's LaTeX printer, each sub-expression printed once."""


def latex_printer(model: Model) -> Callable[[sp.Basic], str]:
    """``expr -> LaTeX`` with the model's symbol names (as ``sp.latex(expr, symbol_names=...)``);
    one printer for a whole document, so repeated sub-expressions are printed once."""
    return _LatexPrinter({"symbol_names": latex_symbol_names(model)}).doprint
