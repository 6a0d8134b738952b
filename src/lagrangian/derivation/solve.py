"""Symbolic accelerations under a hard budget; past it the implicit form M q_ddot = f stands.

[[M, Phi_q^T], [Phi_q, 0]] [q_ddot; lambda] = [f; gamma] is solved by fraction-free (Bareiss)
elimination on sparse polynomials (sympy's PolyElement: sin(q), cos(q), 1/m... are independent
generators, which is exact), so q_ddot_i = N_i / det. Nothing is expanded after the fact:
sympy's LUsolve + cancel expanded nested quotients of trig sums and ran for hours on the 2-link
pendulum on a cart. Every polynomial product is checked against a work limit before it is formed
and the whole solve against a wall-clock deadline between products, so the cost is bounded
in one thread (no thread or process is left running when the budget is spent).
"""

from __future__ import annotations

import math
import random
import time
from dataclasses import dataclass

import numpy as np
import sympy as sp
from sympy.polys.domains import ZZ
from sympy.polys.rings import PolyRing, sring

# Above this many unknowns (coordinates + multipliers) the closed form is never readable.
SYMBOLIC_SOLVE_MAX_UNKNOWNS = 3
# Terms of the polynomial entries of [M | f] before solving.
SYMBOLIC_SOLVE_MAX_INPUT_TERMS = 200
# Term products one polynomial multiplication may cost, and terms any intermediate may have.
SYMBOLIC_SOLVE_MAX_WORK = 40_000
# A gcd of polynomials of higher degree is not tried: x^0.123456789 is x'^123456789 in the
# generator x' = x^(1/10^9), and cancelling it ran for hours (fuzzing find).
SYMBOLIC_SOLVE_MAX_DEGREE = 1_000
SYMBOLIC_SOLVE_MAX_TERMS = 1_500
# Terms of the printed closed form (all numerators and the denominator).
SYMBOLIC_SOLUTION_MAX_TERMS = 80
# Wall-clock budget of one solve, seconds.
SYMBOLIC_SOLVE_SECONDS = 0.5


@dataclass(frozen=True)
class SymbolicAccelerations:
    """q_ddot in closed form, or None with the reason it was not formed."""

    accelerations: sp.ImmutableMatrix | None
    note: str | None = None


class _OverBudget(Exception):
    pass


class _Budget:
    def __init__(self, seconds: float):
        self.deadline = time.perf_counter() + seconds

    def mul(self, a, b):
        if len(a) * len(b) > SYMBOLIC_SOLVE_MAX_WORK:
            raise _OverBudget("an intermediate product is too large")
        return self.check(a * b)

    def check(self, p):
        if len(p) > SYMBOLIC_SOLVE_MAX_TERMS:
            raise _OverBudget("an intermediate expression is too large")
        if time.perf_counter() > self.deadline:
            raise _OverBudget(f"the time budget ({SYMBOLIC_SOLVE_SECONDS:g} s) ran out")
        return p


_IMPLICIT = "; the equations are given in the implicit form M q_ddot = f"


def solve_accelerations(
    mass_matrix, forcing, jacobian, gamma, *, seconds: float = SYMBOLIC_SOLVE_SECONDS
) -> SymbolicAccelerations:
    """q_ddot = N / det from [[M, Phi_q^T], [Phi_q, 0]] [q_ddot; lambda] = [f; gamma], when the
    solve stays within the budget (None and a note otherwise)."""
    n, m = mass_matrix.shape[0], jacobian.shape[0]
    if all(x == 0 for x in mass_matrix):
        return SymbolicAccelerations(None, "none: the model has no inertia (statics: the "
                                     "equations are the equilibrium conditions 0 = f)")
    if n + m > SYMBOLIC_SOLVE_MAX_UNKNOWNS:
        return SymbolicAccelerations(
            None, f"not solved symbolically: {n + m} unknowns (more than "
            f"{SYMBOLIC_SOLVE_MAX_UNKNOWNS}){_IMPLICIT}")
    size = n + m
    rows = [[mass_matrix[i, j] for j in range(n)]
            + [jacobian[k, i] for k in range(m)] + [forcing[i]] for i in range(n)]
    rows += [[jacobian[k, j] for j in range(n)] + [sp.S.Zero] * m + [gamma[k]]
             for k in range(m)]
    try:
        ring, polys = _polynomials(rows)
    except (sp.PolynomialError, sp.CoercionFailed, ValueError):
        return SymbolicAccelerations(None, "not solved symbolically: the entries are not "
                                     f"polynomial in their functions{_IMPLICIT}")
    if sum(len(p) for row in polys for p in row) > SYMBOLIC_SOLVE_MAX_INPUT_TERMS:
        return SymbolicAccelerations(None, "not solved symbolically: M and f are too large"
                                     + _IMPLICIT)
    try:
        numerators, determinant = _bareiss(polys, size, _Budget(seconds))
    except _OverBudget as exc:
        return SymbolicAccelerations(None, f"not solved symbolically: {exc}{_IMPLICIT}")
    except ZeroDivisionError:
        return SymbolicAccelerations(None, "not solved symbolically: the system is singular"
                                     + _IMPLICIT)
    if not determinant:
        return SymbolicAccelerations(None, "not solved symbolically: the system is singular"
                                     + _IMPLICIT)
    pairs = []
    try:
        budget = _Budget(seconds)
        for numerator in numerators[:n]:
            if len(numerator) * len(determinant) > SYMBOLIC_SOLVE_MAX_WORK or \
                    max((*numerator.degrees(), *determinant.degrees(), 0)) > \
                    SYMBOLIC_SOLVE_MAX_DEGREE:  # a tuple: with no generators, max(0) would fail
                pairs.append((numerator, determinant))
                continue
            p, q = numerator.cancel(determinant)
            budget.check(p)
            pairs.append((p, q))
    except _OverBudget as exc:
        return SymbolicAccelerations(None, f"not solved symbolically: {exc}{_IMPLICIT}")
    if sum(len(p) + len(q) for p, q in pairs) > SYMBOLIC_SOLUTION_MAX_TERMS:
        return SymbolicAccelerations(None, "not solved symbolically: the closed form would "
                                     f"exceed {SYMBOLIC_SOLUTION_MAX_TERMS} terms{_IMPLICIT}")
    solution = [sp.factor_terms(p.as_expr()) / sp.factor_terms(q.as_expr())
                for p, q in pairs]
    if not _verified(mass_matrix, forcing, jacobian, gamma, solution):
        return SymbolicAccelerations(None, "not solved symbolically: the elimination treated "
                                     "related functions (such as sin and cos of one angle) as "
                                     f"independent and met a zero pivot{_IMPLICIT}")
    return SymbolicAccelerations(sp.ImmutableMatrix(n, 1, solution))


def _polynomials(rows):
    """The entries as polynomials over ZZ in one ring, each row scaled to clear denominators
    (scaling an equation does not change its solution)."""
    flat = [e for row in rows for e in row]
    if any(e.has(sp.nan, sp.zoo, sp.oo) for e in flat):
        raise ValueError("not finite")
    # Products of sums are multiplied out, but not the insides of functions and powers:
    # sqrt((x1 - x2)^2) stays one generator (deep expansion only makes it unreadable).
    exact = [_multiplied_out(e.xreplace({f: sp.Rational(str(f)) for f in e.atoms(sp.Float)}))
             for e in flat]
    ring, polys = sring(exact, expand=False)
    if not ring.domain.is_Exact or not (ring.domain.is_ZZ or ring.domain.is_QQ):
        raise ValueError("inexact coefficients")
    integer_ring = PolyRing(ring.symbols, ZZ, ring.order)
    width = len(rows[0])
    out = []
    for r in range(len(rows)):
        row = polys[r * width:(r + 1) * width]
        scale = 1
        if ring.domain.is_QQ:
            for p in row:
                for c in p.values():
                    scale = math.lcm(scale, int(ring.domain.denom(c)))
        out.append([integer_ring.from_dict({k: ZZ.convert(v * scale, ring.domain)
                                            for k, v in p.items()}) for p in row])
    return integer_ring, out


def _multiplied_out(expr: sp.Expr) -> sp.Expr:
    """Products and positive integer powers of sums multiplied out, down through sums and
    products only: a function's argument or a negative or fractional power's base is kept as
    written, to stand as one generator."""
    if expr.is_Add or expr.is_Mul or (expr.is_Pow and expr.exp.is_Integer and expr.exp > 0):
        return expr.func(*(_multiplied_out(a) for a in expr.args)).expand(deep=False)
    return expr


def _bareiss(rows, size: int, budget: _Budget):
    """Fraction-free elimination of the augmented rows: (numerators X_i, det) with x = X / det."""
    a = [list(row) for row in rows]
    previous = None
    for k in range(size - 1):
        pivot = next((i for i in range(k, size) if a[i][k]), None)
        if pivot is None:
            raise ZeroDivisionError
        if pivot != k:
            a[k], a[pivot] = a[pivot], a[k]
        for i in range(k + 1, size):
            for j in range(k + 1, size + 1):
                value = budget.mul(a[i][j], a[k][k]) - budget.mul(a[i][k], a[k][j])
                a[i][j] = budget.check(value.exquo(previous) if previous is not None else value)
            a[i][k] = a[i][k].ring.zero
        previous = a[k][k]
    determinant = a[size - 1][size - 1]
    if not determinant:
        raise ZeroDivisionError
    # Back substitution on X = det * x (Cramer numerators, polynomials: every division is exact).
    numerators = [None] * size
    for i in range(size - 1, -1, -1):
        value = budget.mul(a[i][size], determinant)
        for j in range(i + 1, size):
            value -= budget.mul(a[i][j], numerators[j])
        numerators[i] = budget.check(value.exquo(a[i][i]))
    return numerators, determinant


def _verified(mass_matrix, forcing, jacobian, gamma, solution) -> bool:
    """M q_ddot = f (with the multipliers eliminated) at random points, to 1e-8 relative.

    The polynomial ring is blind to sin^2 + cos^2 = 1 and m (1/m) = 1; a determinant that is zero
    as a function but not as a polynomial would give a wrong closed form, which this catches.
    """
    symbols = set().union(*(e.free_symbols for e in (*mass_matrix, *forcing, *jacobian, *gamma,
                                                     *solution)))
    rng = random.Random(20261123)
    m = jacobian.shape[0]
    checked = 0
    for _ in range(3):
        values = {s: sp.Float(rng.uniform(0.3, 1.7)) for s in symbols}
        try:
            M = sp.Matrix(mass_matrix.xreplace(values)).evalf()
            f = sp.Matrix(forcing.xreplace(values)).evalf()
            kkt = sp.Matrix(sp.BlockMatrix([[M, jacobian.T], [jacobian, sp.zeros(m, m)]])) \
                if m else M
            # A pivot that is zero only through sin^2 + cos^2 = 1 leaves a matrix that is
            # singular in value: the residual test alone would accept 1/(1e-17).
            if np.linalg.cond(np.array(kkt.xreplace(values).evalf(), dtype=complex)) > 1e10:
                return False
            a = sp.Matrix([v.xreplace(values) for v in solution]).evalf()
            residual = f - M * a
            scale = max([abs(complex(x)) for x in (*f, *(M * a))] + [1e-300])
            if m:
                A = sp.Matrix(jacobian.xreplace(values)).evalf()
                g = sp.Matrix(gamma.xreplace(values)).evalf()
                if max(abs(complex(x)) for x in A * a - g) > 1e-8 * max(
                        [abs(complex(x)) for x in (*g, *(A * a))] + [1.0]):
                    return False
                # f - M a must lie in the range of A^T (the multipliers' forces).
                lam = (A * A.T).LUsolve(A * residual)
                residual = residual - A.T * lam
            if max(abs(complex(x)) for x in residual) > 1e-8 * scale:
                return False
            checked += 1
        except (TypeError, ValueError, ZeroDivisionError, OverflowError, MemoryError):
            # MemoryError: mpmath on exp(exp(exp(exp(exp(x))))) at a random point (fuzzing find)
            continue
    return checked > 0
