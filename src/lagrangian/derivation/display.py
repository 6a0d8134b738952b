"""The derivation's matrices as Jupyter shows them: rates with dots over their symbols."""

from __future__ import annotations

import sympy as sp
from sympy.printing.latex import LatexPrinter

from ..model.notation import ModelLatexPrinter, dotted


def names_by_suffix(symbols) -> dict[sp.Symbol, str]:
    """LaTeX for the rate and multiplier symbols among ``symbols``, read from their names
    (NAME_dot, NAME_ddot, lambda_NAME: the names the model reserves for them)."""
    names = {}
    for symbol in symbols:
        if not isinstance(symbol, sp.Symbol):
            continue
        for suffix, dots in (("_ddot", 2), ("_dot", 1)):
            base = symbol.name.removesuffix(suffix)
            if base != symbol.name and base:
                names[symbol] = dotted(sp.latex(sp.Symbol(base)), dots)
                break
        else:
            if symbol.name.startswith("lambda_") and len(symbol.name) > 7:
                label = symbol.name[7:].replace("_", r"\_")
                names[symbol] = rf"\lambda_{{\mathrm{{{label}}}}}"
    return names


class ModelMatrix(sp.ImmutableDenseMatrix):
    """An immutable matrix of a model's expressions that Jupyter (and ``sp.latex``) shows in the
    model's notation: theta_dot as a dot over theta, not ``\\theta_{dot}``. Equal to, and
    hashed as, the same entries in a plain ``sp.ImmutableMatrix``; results of arithmetic on it
    (and copies through pickle) are ModelMatrix too."""

    @classmethod
    def of(cls, matrix: sp.MatrixBase) -> ModelMatrix:
        return cls._fromrep(sp.ImmutableMatrix(matrix)._rep)

    def __hash__(self) -> int:
        if self._mhash is None:  # Basic's cache of the hash
            self._mhash = hash(sp.ImmutableDenseMatrix._fromrep(self._rep))
        return self._mhash

    def _latex(self, printer: LatexPrinter) -> str:
        names = {**names_by_suffix(self.free_symbols), **printer._settings["symbol_names"]}
        settings = {key: value for key, value in printer._settings.items()
                    if key in LatexPrinter._default_settings}
        return ModelLatexPrinter({**settings, "symbol_names": names})._print_MatrixBase(self)


def latex_with_rates(expr: sp.Basic) -> str:
    """``sp.latex(expr)`` with its rates dotted and multipliers as lambda, read from the names
    (for results that no longer carry their model: reactions, residuals)."""
    return ModelLatexPrinter({"symbol_names": names_by_suffix(expr.free_symbols)}).doprint(expr)
