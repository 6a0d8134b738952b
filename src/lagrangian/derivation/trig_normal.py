"""sin^2 + cos^2 = 1 applied exactly to a trig polynomial, for display (derivation/readable.py).

A coefficient that is a polynomial in the sines and cosines of its angles is expanded and, angle
by angle, every sin(x)^2 written as 1 - cos(x)^2 (or every cos(x)^2 as 1 - sin(x)^2, whichever
leaves fewer terms). Keeping each angle's sine to at most its first power is a normal form of
such polynomials (the reduction modulo sin^2 + cos^2 - 1, whose leading terms share no
variable): two equal coefficients get the same form, so terms that cancel only through the
identity vanish. A top built of particles, whose kinetic energy holds products of its rotation
matrix's entries, prints as its textbook form this way. No simplify: one expansion and passes
over its terms, bounded by MAX_TERMS.
"""

from __future__ import annotations

from math import comb

import sympy as sp

from ..model.expressions import tree_size

MAX_ANGLES = 4  # distinct trig arguments past which no normal form is tried
MAX_TERMS = 4000  # terms of the expanded polynomial past which it is not tried
MAX_NODES = 3000  # nodes of the coefficient (before expansion) past which it is not tried


def _polynomial_in(expr: sp.Expr, gens: set) -> bool:
    """Whether ``expr`` is a polynomial in ``gens`` by its tree alone (no expansion): each power
    of something holding them a nonnegative integer power, no other function of them."""
    seen: set = set()
    stack = [expr]
    while stack:
        node = stack.pop()
        if node in seen or node.is_Atom:
            continue
        seen.add(node)
        if node.is_Pow:
            if not (node.exp.is_Integer and node.exp >= 0) and node.base.free_symbols & gens:
                return False
            stack.append(node.base)
        elif node.is_Add or node.is_Mul:
            stack.extend(node.args)
        elif node.free_symbols & gens:  # sqrt is a Pow; this is any other function of them
            return False
    return True


def _terms_bound(expr: sp.Expr, limit: int) -> int:
    """An upper bound on the terms of ``expr`` expanded (sums add, products multiply, an integer
    power k of n terms at most C(n + k - 1, k)), from the tree without expanding it; any value
    past ``limit`` stands for "too many"."""
    memo: dict[sp.Basic, int] = {}

    def bound(node: sp.Basic) -> int:
        found = memo.get(node)
        if found is not None:
            return found
        if node.is_Add:
            value = sum(bound(a) for a in node.args)
        elif node.is_Mul:
            value = 1
            for a in node.args:
                value *= bound(a)
                if value > limit:
                    break
        elif node.is_Pow and node.exp.is_Integer and node.exp > 1:
            n = bound(node.base)
            value = comb(n + int(node.exp) - 1, int(node.exp)) if n <= limit else limit + 1
        else:
            value = 1
        memo[node] = value = min(value, limit + 1)
        return value

    return bound(expr)


def trig_normal_form(expr: sp.Expr) -> sp.Expr | None:
    """An equal form of ``expr`` with sin^2 + cos^2 = 1 applied exactly (see the module), or
    None where it is not a polynomial in the sines and cosines, or too large."""
    angles = sorted({f.args[0] for f in expr.atoms(sp.sin, sp.cos)}, key=sp.default_sort_key)
    if not angles or len(angles) > MAX_ANGLES:
        return None
    if tree_size(expr, MAX_NODES) > MAX_NODES:
        return None
    sines = [sp.Dummy(f"s{i}") for i in range(len(angles))]
    cosines = [sp.Dummy(f"c{i}") for i in range(len(angles))]
    swap = {sp.sin(a): s for a, s in zip(angles, sines, strict=True)}
    swap |= {sp.cos(a): c for a, c in zip(angles, cosines, strict=True)}
    replaced = expr.xreplace(swap)
    if replaced.atoms(sp.sin, sp.cos):  # a trig function of something else inside (sin(sin x))
        return None
    gens = [*sines, *cosines]
    # before expanding (the cost): a sine under a root or in a denominator is no polynomial,
    # and an expansion past MAX_TERMS is not tried
    if not _polynomial_in(replaced, set(gens)) or _terms_bound(replaced, MAX_TERMS) > MAX_TERMS:
        return None
    try:
        poly = sp.Poly(replaced, *gens)
    except sp.PolynomialError:  # a sine in a denominator, under a root: not a polynomial
        return None
    if poly.domain.is_EX or len(poly.terms()) > MAX_TERMS:
        return None
    terms = dict(poly.terms())
    n = len(angles)
    for i in range(n):
        by_sine = _reduce(terms, i, n + i)  # sin^2 -> 1 - cos^2
        by_cosine = _reduce(terms, n + i, i)  # cos^2 -> 1 - sin^2
        terms = by_sine if len(by_sine) <= len(by_cosine) else by_cosine
        if len(terms) > MAX_TERMS:
            return None
    if not terms:
        return sp.S.Zero
    back = dict(zip(gens, [*(sp.sin(a) for a in angles), *(sp.cos(a) for a in angles)],
                    strict=True))
    return sp.Add(*(poly.domain.to_sympy(c) * sp.Mul(*(back[g] ** e for g, e in
                                                        zip(gens, monom, strict=True) if e))
                    for monom, c in terms.items()))


def _reduce(terms: dict, square: int, other: int) -> dict:
    """The polynomial with every power >= 2 of generator ``square`` reduced by
    g_square^2 = 1 - g_other^2 (its exponent left 0 or 1); terms by exponent tuples."""
    out: dict = {}
    for monom, coefficient in terms.items():
        k, rest = divmod(monom[square], 2)
        for j in range(k + 1):  # (1 - g_other^2)^k = sum_j C(k, j) (-1)^j g_other^(2j)
            exponents = list(monom)
            exponents[square] = rest
            exponents[other] += 2 * j
            key = tuple(exponents)
            value = out.get(key, 0) + coefficient * ((-1) ** j * comb(k, j))
            if value:
                out[key] = value
            else:
                out.pop(key, None)
    return out


__all__ = ["trig_normal_form"]
