"""The derivation's expressions as `derive` writes them (text, JSON and LaTeX alike): their
readable forms (_Display), in named intermediate quantities where they would be large, and the
letters of the labels. Apart from output/derivation.py, so that output/latex.py builds on them
without importing the module that calls it."""

from __future__ import annotations

import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..derivation.intermediates import (
    LARGE_TREE_NODES,
    Intermediates,
    intermediates,
    is_large,
    with_entries,
)
from ..derivation.readable import readable, readable_matrix
from ..model.expressions import format_expression, tree_size


class _Display:
    """The readable form of the derivation's expressions (derivation/readable.py: equal to the
    derived ones, grouped by products of the rates), as text in the model-file grammar."""

    def __init__(self, eom: EquationsOfMotion, expand: bool = False):
        model = eom.model
        self.rates = frozenset([*model.q_dot, *model.q_ddot, *eom.multipliers])
        self.ranges = {c.symbol: tuple(c.range) for c in model.coordinates if c.range}
        self.intermediates = None if expand else _named(eom)

    def form(self, expr) -> sp.Expr:
        if self.intermediates is not None:
            found = self.intermediates.reduced.get(expr)
            if found is not None:
                return found
        return readable(expr, self.rates, self.ranges)

    def plain(self, expr) -> sp.Expr:
        """The readable form in the model's own names (constraints: read by the modes)."""
        return readable(expr, self.rates, self.ranges)

    def lagrangian(self, eom: EquationsOfMotion) -> sp.Expr:
        """L = T - V from the readable T and V (grouping L again would repeat T's work)."""
        return self.form(eom.kinetic_energy) - self.form(eom.potential_energy)

    def equations(self, eom: EquationsOfMotion) -> list[sp.Expr]:
        """M q_ddot + Phi_q^T lambda - f per coordinate, from the readable M, Phi_q and f
        (regrouping the whole equation would repeat their work: 1-2 s at 30 links)."""
        M, A, f = eom.mass_matrix, eom.constraint_jacobian, eom.forcing
        rows = []
        for i in range(M.rows):
            terms = [self.form(M[i, j]) * a for j, a in enumerate(eom.model.q_ddot)
                     if M[i, j] != 0]
            terms += [self.plain(A[k, i]) * eom.multipliers[k] for k in range(A.rows)
                      if A[k, i] != 0]
            rows.append(sp.Add(*terms) - self.form(f[i]))
        return rows

    def matrix(self, matrix, plain: bool = False) -> sp.ImmutableMatrix:
        if self.intermediates is not None and not plain:
            return sp.ImmutableMatrix(matrix.rows, matrix.cols, [self.form(v) for v in matrix])
        return readable_matrix(matrix, self.rates, self.ranges)

    def definitions(self) -> list[tuple[str, str]]:
        """(name, text) of each intermediate quantity, in order (none for small equations)."""
        if self.intermediates is None:
            return []
        return [(str(symbol), format_expression(expr))
                for symbol, expr in self.intermediates.definitions]

    def __call__(self, expr, plain: bool = False) -> str:
        return format_expression(self.plain(expr) if plain else self.form(expr))


def printed_expressions(eom: EquationsOfMotion) -> list[sp.Expr]:
    """Every expression derive prints but the constraints' (the Lagrangian is T - V of the
    printed T and V; Phi, Phi_q and gamma stay in the model's names)."""
    exprs = [eom.kinetic_energy, eom.potential_energy, eom.dissipation, *eom.mass_matrix,
             *eom.forcing, *eom.generalized_forces,
             *(c.expression for c in eom.load_contributions)]
    return exprs if eom.accelerations is None else [*exprs, *eom.accelerations]


def _named(eom: EquationsOfMotion) -> Intermediates | None:
    """The intermediate quantities where the equations written out would be large, else None."""
    exprs = printed_expressions(eom)
    if not is_large(exprs) or _collapses(eom, exprs):
        return None
    model = eom.model
    taken = {p.name for p in model.parameters} | {str(s) for s in eom.multipliers}
    for c in model.coordinates:
        taken |= {c.name, c.velocity.name, c.acceleration.name}
    named = intermediates(model, exprs, taken)
    names = [c.name for c in model.coordinates]
    M = eom.mass_matrix
    entries = [(f"M_{names[i]}_{names[j]}", M[i, j]) for i in range(M.rows)
               for j in range(i, M.cols) if M[i, j] != 0]
    entries += [(f"f_{name}", value) for name, value in zip(names, eom.forcing, strict=True)]
    return with_entries(named, entries, taken)


# A large derivation on few coordinates whose readable T is this many times shorter is tried
# in readable forms whole (a top built of particles: its rotation's products collapse by
# sin^2 + cos^2 = 1, 22,000-55,000 nodes to 200 in 1-2 s); a spatial chain's T does not shrink
# (its readable forms cost 40 s at 4 links), and neither does one past COLLAPSE_NODES.
COLLAPSE_RATIO = 10
COLLAPSE_COORDINATES = 3
COLLAPSE_NODES = 3 * LARGE_TREE_NODES


def _collapses(eom: EquationsOfMotion, exprs: list[sp.Expr]) -> bool:
    """Whether the readable forms of large derived expressions are small: written out then."""
    model = eom.model
    if len(model.coordinates) > COLLAPSE_COORDINATES or is_large(exprs, COLLAPSE_NODES):
        return False
    rates = frozenset([*model.q_dot, *model.q_ddot, *eom.multipliers])
    ranges = {c.symbol: tuple(c.range) for c in model.coordinates if c.range}
    T = eom.kinetic_energy
    if COLLAPSE_RATIO * tree_size(readable(T, rates, ranges)) > tree_size(T):
        return False
    return not is_large([readable(e, rates, ranges) for e in exprs])


# LaTeX: the letters of the labels, set in another alphabet when the model has a symbol of
# that name (a length L is not the Lagrangian \mathcal{L}).
_LATEX_LETTERS = {"T": r"\mathcal{T}", "V": r"\mathcal{V}", "D": r"\mathcal{D}",
                  "L": r"\mathcal{L}", "Q": r"\mathcal{Q}", "M": r"\mathbf{M}",
                  "f": r"\mathbf{f}"}


def _latex_letters(model) -> dict[str, str]:
    names = {p.name for p in model.parameters} | {c.name for c in model.coordinates}
    return {letter: (other if letter in names else letter)
            for letter, other in _LATEX_LETTERS.items()}
