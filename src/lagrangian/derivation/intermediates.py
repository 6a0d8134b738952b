"""Named intermediate quantities for printing large equations (derive on a deep chain of bodies).

Written out in full, the equations of a chain of rigid bodies grow like the Fibonacci numbers
down the chain (a 5-body chain prints 0.37 MB, a 10-body one 46 MB), although the derivation
holds them as shared sub-expressions. Where they are large (``is_large``: more than
``LARGE_TREE_NODES`` nodes written out as a tree, counted without expanding) they are printed
through named quantities, body by body, parents first:

    R_<body>_<row><col>   its rotation matrix (body -> world), R_parent Rot(axis, q)
    omega_<body>_<x|y|z>  its angular velocity, body axes (rad/s)
    o_<body>_<x|y|z>, p_<body>_<x|y|z>   its frame's origin and its centre of mass, world (m)
    v_<body>_<x|y|z>      the velocity of its centre of mass, world (m/s)

each written in the ones before it, then whatever else repeats (sympy's cse, named
``<prefix>_1, <prefix>_2, ...``), and the equations written in them. Every name stands for
exactly the sub-expression it replaces, so substituting the definitions back in order gives
the derived expressions (``Intermediates.expanded``).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import sympy as sp
from sympy.simplify.cse_main import tree_cse

from ..model.expressions import RESERVED, tree_size
from ..model.model import Model
from .body_jacobians import TimeRate
from .kinematics import Differentiator

# Above this many nodes written out as a tree (M, f, T, V and Q together) the equations print
# through named quantities: ~5 characters a node, so about 100 KB of text. The built-in
# examples are at most 470 nodes but for the bicycle (84,000); a chain of 3D bodies on
# alternating axes has 11,000 at 4 bodies, 35,000 at 5, 3 million at 10.
LARGE_TREE_NODES = 20_000


def is_large(expressions: Iterable[sp.Expr], limit: int = LARGE_TREE_NODES) -> bool:
    """Whether the expressions written out in full pass ``limit`` nodes (time linear in their
    distinct sub-expressions: nothing is expanded)."""
    total = 0
    for expr in expressions:
        total += tree_size(expr, limit=limit)
        if total > limit:
            return True
    return False


@dataclass(frozen=True)
class Intermediates:
    """Named quantities in order (each written in the model's symbols and the names before it)
    and the expressions written in them."""

    definitions: tuple[tuple[sp.Symbol, sp.Expr], ...]
    reduced: dict  # derived expression -> the same written in the names
    generic: frozenset = frozenset()  # the names cse gave (a prefix and a number)

    def expanded(self, expr: sp.Expr) -> sp.Expr:
        """``expr`` (in the names) with every definition substituted back, last first."""
        for symbol, definition in reversed(self.definitions):
            if symbol in expr.free_symbols:
                expr = expr.xreplace({symbol: definition})
        return expr


class _Rewriter:
    """Replace every sub-expression found in ``table`` by its name (memoized on the DAG), and
    in a sum every named sum whose terms it holds: sympy flattens sums, so a child's origin
    o_parent + R_parent at holds o_parent's terms, not o_parent."""

    def __init__(self) -> None:
        self.table: dict[sp.Expr, sp.Symbol] = {}
        self._sums: dict[sp.Expr, list[sp.Expr]] = {}  # a named sum, by its first term
        self._memo: dict[sp.Expr, sp.Expr] = {}

    def name(self, expr: sp.Expr, symbol: sp.Symbol) -> None:
        self.table[expr] = symbol
        if expr.is_Add:
            self._sums.setdefault(expr.args[0], []).append(expr)

    def __call__(self, expr: sp.Expr) -> sp.Expr:
        found = self.table.get(expr)
        return found if found is not None else self.inside(expr)

    def inside(self, expr: sp.Expr) -> sp.Expr:
        if not expr.args:
            return expr
        found = self._memo.get(expr)
        if found is None:
            found = self._memo[expr] = (self._sum(expr) if expr.is_Add else
                                        self._rebuilt(expr, expr.args))
        return found

    def _rebuilt(self, expr: sp.Expr, args) -> sp.Expr:
        new = [self(a) for a in args]
        changed = any(a is not b for a, b in zip(new, args, strict=True))
        # unevaluated: a node with a name in it needs no canonical form (printed, never
        # compared), and sympy's flattening of each rebuilt node is what costs here
        return expr.func(*new, evaluate=False) if changed else expr

    def _sum(self, expr: sp.Expr) -> sp.Expr:
        left = set(expr.args)
        names = []
        while True:
            inside = [s for a in left for s in self._sums.get(a, ())
                      if s is not expr and len(s.args) <= len(left) and left.issuperset(s.args)]
            if not inside:
                break
            largest = max(inside, key=lambda s: len(s.args))
            names.append(self.table[largest])
            left.difference_update(largest.args)
        if not names:
            return self._rebuilt(expr, expr.args)
        return sp.Add(*names, *(self(a) for a in expr.args if a in left))


def _body_quantities(model: Model) -> list[tuple[str, sp.Expr]]:
    """(name, expression) of each body's R, omega, origin, centre of mass, and (for a body
    whose motion has no explicit t) their rates along the motion at q_ddot = 0, as the
    derivation forms them (body_jacobians.TimeRate): R's and the origin's first and second,
    the centre of mass's velocity and acceleration, omega's."""
    q, q_dot, t = model.q, model.q_dot, model.time
    d = Differentiator()
    rate = TimeRate(q, q_dot, d)
    out: list[tuple[str, sp.Expr]] = []

    def vector(prefix: str, tag: str, items) -> list[tuple[str, sp.Expr]]:
        return [(f"{prefix}{tag}_{axis}", x) for axis, x in zip("xyz", items, strict=True)]

    for number, body in enumerate(model.rigid_bodies, start=1):
        tag = str(number)
        entries = [(f"{r + 1}{c + 1}", body.rotation[r][c]) for r in range(3) for c in range(3)]
        out += [(f"R{tag}_{rc}", x) for rc, x in entries]
        out += vector("omega", tag, body.angular_velocity)
        out += vector("o", tag, body.origin)
        out += vector("p", tag, body.position)
        moving = (*body.position, *body.origin, *body.angular_velocity,
                  *(x for _, x in entries))
        if any(t in d.free_symbols(x) for x in moving):
            continue
        out += [(f"dR{tag}_{rc}", rate(x)) for rc, x in entries]
        out += vector("vo", tag, map(rate, body.origin))
        out += vector("v", tag, map(rate, body.position))
        out += vector("alpha", tag, map(rate, body.angular_velocity))
        out += [(f"ddR{tag}_{rc}", rate(rate(x))) for rc, x in entries]
        out += vector("ao", tag, (rate(rate(x)) for x in body.origin))
        out += vector("a", tag, (rate(rate(x)) for x in body.position))
    return out


def _prefix(taken: set[str]) -> str:
    for prefix in ("s", "u", "w", "z", "aux"):
        pattern = re.compile(rf"^{prefix}\d+$")
        if not any(pattern.match(name) for name in taken):
            return prefix
    return "aux_s_"  # no model name is aux_s_ and digits: taken holds them all


def intermediates(model: Model, expressions: Sequence[sp.Expr], taken: Iterable[str]
                  ) -> Intermediates:
    """Name the bodies' quantities and what else repeats in ``expressions``; ``taken``: the
    names the model already uses (parameters, coordinates, rates, multipliers)."""
    taken = set(taken) | set(RESERVED)
    rewrite = _Rewriter()
    definitions: list[tuple[sp.Symbol, sp.Expr]] = []
    for name, expr in _body_quantities(model):
        if expr.is_Atom or expr in rewrite.table or name in taken:
            continue
        symbol = sp.Symbol(name)
        definitions.append((symbol, rewrite.inside(expr)))
        rewrite.name(expr, symbol)
        taken.add(name)
    written = [rewrite(e) for e in expressions]
    prefix = _prefix(taken)
    numbered = (sp.Symbol(f"{prefix}{k}") for k in range(1, 10**9))
    # tree_cse alone: cse's opt_cse (common factors of products and sums) costs as much again
    repeated, reduced = tree_cse(written, numbered, opt_subs={}, order="none")
    repeated, reduced = _inlined(repeated, reduced)
    definitions = _used(definitions + repeated, reduced)
    return Intermediates(tuple(definitions), dict(zip(expressions, reduced, strict=True)),
                         frozenset(s for s, _ in repeated))


def with_entries(named: Intermediates, entries: Sequence[tuple[str, sp.Expr]],
                 taken: Iterable[str]) -> Intermediates:
    """``named`` with each of ``entries`` (name, derived expression: M's and f's entries) named
    last (or the cse name it already has renamed), so that the
    equations read M_q0_q1*q1_ddot + ... = f_q0 (a name already taken gets a trailing
    underscore)."""
    taken = set(taken) | set(RESERVED) | {str(s) for s, _ in named.definitions}
    definitions = list(named.definitions)
    defined = {symbol: k for k, (symbol, _) in enumerate(definitions)}
    generic = named.generic
    reduced = dict(named.reduced)
    renamed: dict[sp.Symbol, sp.Symbol] = {}
    for name, expr in entries:
        written = named.reduced.get(expr, expr)
        if written.is_Number:
            continue
        while name in taken:
            name += "_"
        if written.is_Symbol and written not in generic:
            continue  # a model symbol or a body's quantity: its own name is clearer
        taken.add(name)
        symbol = sp.Symbol(name)
        if written in generic and written not in renamed:  # cse named it: rename it
            renamed[written] = symbol
            definitions[defined[written]] = (symbol, definitions[defined[written]][1])
        elif not written.is_Symbol:
            definitions.append((symbol, written))
            reduced[expr] = symbol
    if renamed:
        definitions = [(s, e.xreplace(renamed)) for s, e in definitions]
        reduced = {k: v.xreplace(renamed) for k, v in reduced.items()}
    return Intermediates(tuple(definitions), reduced,
                         frozenset(generic) - renamed.keys())


def _inlined(repeated: list[tuple[sp.Symbol, sp.Expr]], reduced: list[sp.Expr]):
    """cse names every repeated node: a name used once, or standing for a single product or
    power of names (s_3 = s_1*s_2, -s_5, q0_dot**2), is written where it is used instead, and
    the rest numbered again from 1 (a line per name costs more than it saves)."""
    uses: dict[sp.Symbol, int] = {}
    for expr in (*(e for _, e in repeated), *reduced):
        for symbol in expr.free_symbols:
            uses[symbol] = uses.get(symbol, 0) + 1
    inline: dict[sp.Symbol, sp.Expr] = {}
    kept = []
    for symbol, expr in repeated:
        expr = expr.xreplace(inline) if inline and expr.free_symbols & inline.keys() else expr
        if uses.get(symbol, 0) <= 1 or _small(expr):
            inline[symbol] = expr
        else:
            kept.append((symbol, expr))
    renamed = {symbol: sp.Symbol(f"{symbol.name.rstrip('0123456789')}{k}")
               for k, (symbol, _) in enumerate(kept, start=1)}

    def written(expr: sp.Expr) -> sp.Expr:
        # in two steps: what is inlined holds the old names of those kept, renamed after
        if expr.free_symbols & inline.keys():
            expr = expr.xreplace(inline)
        return expr.xreplace(renamed)

    return ([(renamed[s], written(e)) for s, e in kept], [written(e) for e in reduced])


def _small(expr: sp.Expr) -> bool:
    """A product or power of at most two factors, each a name or a number."""
    if expr.is_Atom:
        return True
    if not (expr.is_Mul or expr.is_Pow) or len(expr.args) > 2:
        return False
    return all(a.is_Atom for a in expr.args)


def _used(definitions: list[tuple[sp.Symbol, sp.Expr]], reduced: Sequence[sp.Expr]
          ) -> list[tuple[sp.Symbol, sp.Expr]]:
    """The definitions the expressions need, directly or through other definitions."""
    needed = set().union(*(e.free_symbols for e in reduced)) if reduced else set()
    kept = []
    for symbol, definition in reversed(definitions):
        if symbol in needed:
            kept.append((symbol, definition))
            needed |= definition.free_symbols
    return kept[::-1]


__all__ = ["LARGE_TREE_NODES", "Intermediates", "intermediates", "is_large", "with_entries"]
