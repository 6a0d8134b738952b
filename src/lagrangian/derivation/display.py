"""The derivation's matrices and expressions as Jupyter shows them: rates with dots over their
symbols."""

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

    def __getitem__(self, key):
        # one entry (M[0, 1], f[0]) is shown dotted too; rows, columns and slices stay matrices
        item = super().__getitem__(key)
        return item if isinstance(item, sp.MatrixBase) else model_scalar(item)

    def _latex(self, printer: LatexPrinter) -> str:
        names = {**names_by_suffix(self.free_symbols), **printer._settings["symbol_names"]}
        settings = {key: value for key, value in printer._settings.items()
                    if key in LatexPrinter._default_settings}
        return ModelLatexPrinter({**settings, "symbol_names": names})._print_MatrixBase(self)


def latex_with_rates(expr: sp.Basic) -> str:
    """``sp.latex(expr)`` with its rates dotted and multipliers as lambda, read from the names
    (for results that no longer carry their model: reactions, residuals)."""
    return ModelLatexPrinter({"symbol_names": names_by_suffix(expr.free_symbols)}).doprint(expr)


class _ModelScalar:
    """A model's expression that Jupyter (and ``sp.latex``) shows in the model's notation, rates
    dotted. Its class carries the plain class's ``__name__`` (Add, Mul, Pow), which sympy's
    hashing, canonical ordering and class keys read, so it is equal to, hashed and sorted as the
    plain expression; arithmetic on it gives plain expressions."""

    _plain: type = sp.Basic
    __slots__ = ()

    def __eq__(self, other):
        if self is other:
            return True
        if not isinstance(other, sp.Basic):
            return self._do_eq_sympify(other)  # safe: sympy's strict path, never parses text
        if getattr(type(other), "_plain", type(other)) is not self._plain:
            return False
        return self._hashable_content() == other._hashable_content()

    def __ne__(self, other):
        return not self == other

    __hash__ = sp.Basic.__hash__  # by the class name (the plain one) and the content

    def _latex(self, printer: LatexPrinter) -> str:
        names = {**names_by_suffix(self.free_symbols), **printer._settings["symbol_names"]}
        settings = {key: value for key, value in printer._settings.items()
                    if key in LatexPrinter._default_settings}
        model = ModelLatexPrinter({**settings, "symbol_names": names})
        return getattr(model, f"_print_{self._plain.__name__}")(self)


class ModelAdd(_ModelScalar, sp.Add):
    _plain = sp.Add
    __slots__ = ()


class ModelMul(_ModelScalar, sp.Mul):
    _plain = sp.Mul
    __slots__ = ()


class ModelPow(_ModelScalar, sp.Pow):
    _plain = sp.Pow
    __slots__ = ()


for _kind in (ModelAdd, ModelMul, ModelPow):
    _kind.__name__ = _kind._plain.__name__  # pickled by __qualname__, compared by __name__


def model_scalar(expr):
    """``expr`` shown with its rates dotted (equal to it); other kinds are returned as they
    are (a symbol, a number, a function at the top)."""
    kind = type(expr)
    if kind in (sp.Add, sp.Mul):
        wrapper = ModelAdd if kind is sp.Add else ModelMul
        return wrapper._from_args(expr.args, expr.is_commutative)
    if kind is sp.Pow:
        return ModelPow(*expr.args, evaluate=False)
    return expr
