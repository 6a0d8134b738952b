"""Probabilistic identity testing: two expressions are equal if they agree at random points.

Both sides are evaluated with mpmath at 30 significant digits at a handful of random points
(Schwartz-Zippel: a non-identity agrees at random points with probability ~0), so no
``simplify`` is ever called on a large expression. Every parameter gets a random value too:
a parameter that happens to be 0 (a load switched off) must not hide a mistake.
"""

from __future__ import annotations

import functools
import random
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import mpmath
import sympy as sp

from ..compile.lambdified import mpmath_function, operations_exceed
from ..derivation.readable import readable
from ..model.model import Model

DIGITS = 30
TOLERANCE = mpmath.mpf(10) ** -18  # relative: rounding at 30 digits leaves ~1e-28
FLOAT_TOLERANCE = mpmath.mpf(10) ** -12  # model values are floats (pi/6 vs 0.5235987755982988)
SMALL = 120  # expressions with fewer operations than this may be simplified for display


@dataclass(frozen=True)
class Points:
    """Random values for every symbol; ``groups`` of points share their parameter values."""

    symbols: tuple[sp.Symbol, ...]
    values: tuple[tuple[mpmath.mpf, ...], ...]
    groups: tuple[tuple[int, ...], ...]
    tolerance: mpmath.mpf = TOLERANCE  # looser where model values (16-digit floats) are used

    def evaluate(self, expressions: Sequence[sp.Expr]) -> list[list[mpmath.mpc]]:
        """values[point][expression], each expression compiled once (mpmath, 30 digits)."""
        exprs = [sp.sympify(e) for e in expressions]  # safe: sympy objects, not user text
        missing = set().union(*(e.free_symbols for e in exprs)) - set(self.symbols) if exprs else set()
        if missing:
            raise ValueError(f"no random values for {sorted(map(str, missing))}")
        with mpmath.workdps(DIGITS):
            function = mpmath_function(self.symbols, exprs)
            rows = []
            for point in self.values:
                try:
                    row = [mpmath.mpc(v) for v in function(*point)]
                except (ZeroDivisionError, ValueError, OverflowError):
                    row = [mpmath.mpc(mpmath.nan)] * len(exprs)
                rows.append(row)
        return rows


def random_points(model: Model, extra: Iterable[sp.Symbol] = (), *, count: int = 6,
                  groups: int = 2, seed: int = 2718, model_values: bool = False) -> Points:
    """``count`` points per group: within a group the parameters are fixed and the state
    (q, q_dot, q_ddot, t, multipliers, extra symbols) varies. ``model_values``: parameters
    that have a value keep it (for answers that write numbers in place of parameters)."""
    rng = random.Random(seed)
    parameters = [p.symbol for p in model.parameters]
    state: list[sp.Symbol] = []
    for c in model.coordinates:
        state += [c.symbol, c.velocity, c.acceleration]
    state.append(model.time)
    state += [sp.Symbol(f"lambda_{c.name}") for c in model.constraints]
    for symbol in sorted(set(extra) - set(parameters) - set(state), key=str):
        state.append(symbol)
    symbols = tuple(parameters + state)
    values, index_groups = [], []
    with mpmath.workdps(DIGITS):
        for _ in range(groups):
            fixed = [mpmath.mpf(rng.uniform(0.6, 1.8)) for _ in parameters]
            if model_values:
                fixed = [mpmath.mpf(repr(p.value)) if p.value is not None else value
                         for p, value in zip(model.parameters, fixed, strict=True)]
            members = []
            for _ in range(count):
                members.append(len(values))
                values.append(tuple(fixed + [mpmath.mpf(rng.uniform(-1.2, 1.2)) for _ in state]))
            index_groups.append(tuple(members))
    tolerance = FLOAT_TOLERANCE if model_values else TOLERANCE
    return Points(symbols, tuple(values), tuple(index_groups), tolerance)


def close(a, b, tolerance=TOLERANCE) -> bool:
    """Equal to within rounding (nan never equals)."""
    if mpmath.isnan(a.real) or mpmath.isnan(b.real):
        return False
    scale = max(mpmath.mpf(1), abs(a), abs(b))
    return abs(a - b) <= tolerance * scale


def all_close(values, tolerance=TOLERANCE) -> bool:
    values = list(values)
    return all(close(v, values[0], tolerance) for v in values[1:])


def identical(a: sp.Expr, b: sp.Expr, points: Points) -> bool:
    """a == b identically (at every random point)."""
    difference = sp.expand(a - b) if is_small(a) and is_small(b) else a - b
    if difference == 0:
        return True
    rows = points.evaluate([a, b])
    return all(close(row[0], row[1], points.tolerance) for row in rows)


def identical_pairs(pairs: Sequence[tuple[sp.Expr, sp.Expr]], points: Points) -> list[bool]:
    """a == b identically for each pair: the large ones evaluated together, so that one
    compiled function shares their common subexpressions (the bicycle's Newton-Euler rows)."""
    same: list[bool | None] = []
    large = []
    for a, b in pairs:
        difference = sp.expand(a - b) if is_small(a) and is_small(b) else a - b
        same.append(True if difference == 0 else None)
        if difference != 0:
            large += [a, b]
    rows = points.evaluate(large) if large else []
    k = 0
    for i, known in enumerate(same):
        if known is None:
            same[i] = all(close(row[k], row[k + 1], points.tolerance) for row in rows)
            k += 2
    return [bool(x) for x in same]


def constant_in_state(expression: sp.Expr, points: Points) -> bool:
    """True when ``expression`` depends on parameters only (same value across a group)."""
    rows = points.evaluate([expression])
    return all(all_close((rows[i][0] for i in group), points.tolerance) for group in points.groups)


def zero(expression: sp.Expr, points: Points) -> bool:
    if expression == 0:
        return True
    rows = points.evaluate([expression])
    return all(close(row[0], mpmath.mpc(0), points.tolerance) for row in rows)


SIMPLIFY_MAX_OPS = 40  # display only: simplify costs ~0.1-1 s beyond this


@functools.lru_cache(maxsize=512)
def display(expression: sp.Expr) -> sp.Expr:
    """A readable form for messages: simplified only when small (never on large ones)."""
    expression = sp.sympify(expression)  # safe: a sympy object or a number
    grouped = readable(expression)  # by products of the rates, as derive prints (equal)
    if sp.count_ops(expression) > SIMPLIFY_MAX_OPS:
        return grouped
    angles = {f.args[0] for f in expression.atoms(sp.sin, sp.cos, sp.tan)}
    try:
        if len(angles) > 1:  # trigsimp over several angles is where simplify spends seconds
            simpler = sp.factor_terms(sp.cancel(expression))
        else:
            simpler = sp.factor_terms(sp.simplify(expression))
    except Exception:  # noqa: BLE001 - a failed simplification only costs readability
        return grouped
    return simpler if sp.count_ops(simpler) < sp.count_ops(grouped) else grouped


def is_small(expression: sp.Expr) -> bool:
    """Small enough (fewer than SMALL operations) to expand or simplify for a message."""
    # Not count_ops to the end: on a body in space's equations it walks a tree of millions of
    # nodes (13 s of the Whipple bicycle's crosscheck) to answer "large".
    return not operations_exceed([sp.sympify(expression)], SMALL - 1)  # safe: sympy objects


def linear_system(expressions: Sequence[sp.Expr], unknowns: Sequence[sp.Symbol]):
    """(A, b) with expressions = A u + b, by differentiation (exact when linear)."""
    A = sp.Matrix([[e.diff(u) for u in unknowns] for e in expressions])
    zero_point = {u: 0 for u in unknowns}
    b = sp.Matrix([e.xreplace(zero_point) for e in expressions])
    return A, b


def is_linear(expressions: Sequence[sp.Expr], unknowns: Sequence[sp.Symbol], points: Points) -> bool:
    """Every expression is linear in the unknowns (its Jacobian does not contain them)."""
    A, _ = linear_system(expressions, unknowns)
    dependent = [a.diff(u) for a in A for u in unknowns if a.has(u)]
    return all(zero(d, points) for d in dependent)


def solve_at_points(A: sp.Matrix, b: sp.Matrix, points: Points, count: int | None = None):
    """Solve A u = -b at each point (mpmath LU); None where singular. ``count``: keep first
    ``count`` unknowns."""
    n_rows, n_cols = A.shape
    rows = points.evaluate(list(A) + list(b))
    solutions = []
    with mpmath.workdps(DIGITS):
        for row in rows:
            matrix = mpmath.matrix(n_rows, n_cols)
            for k in range(n_rows * n_cols):
                matrix[k // n_cols, k % n_cols] = row[k]
            rhs = mpmath.matrix([-v for v in row[n_rows * n_cols:]])
            try:
                if n_rows != n_cols:
                    solutions.append(None)
                    continue
                u = mpmath.lu_solve(matrix, rhs)
            except (ZeroDivisionError, ValueError, TypeError):  # mpmath's singular cases
                solutions.append(None)
                continue
            values = [u[i] for i in range(n_cols)]
            solutions.append(values[:count] if count is not None else values)
    return solutions
