"""Cheap angle-difference identities for readable inertia terms, in linear time (no simplify).

Per-element inertia terms of chains come out as sums like l1 l2 (sin a sin b + cos a cos b);
these rules turn them into the textbook l1 l2 cos(a - b) without trigsimp's search:

    c sin(a) sin(b) + c cos(a) cos(b) -> c cos(a - b)   (and c sin(a)^2 + c cos(a)^2 -> c)
    c sin(a) cos(b) - c cos(a) sin(b) -> c sin(a - b)
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Sequence
from functools import lru_cache

import sympy as sp


@lru_cache(maxsize=1 << 16)
def _split(term: sp.Expr):
    """(rest, sorted sin arguments, sorted cos arguments) when the term has exactly two trig
    factors, else None."""
    sins, coss, rest = [], [], []
    for factor in sp.Mul.make_args(term):
        base, exponent = factor.as_base_exp()
        if isinstance(base, sp.sin | sp.cos) and exponent.is_Integer and 0 < exponent <= 2:
            target = sins if isinstance(base, sp.sin) else coss
            target.extend([base.args[0]] * int(exponent))
        else:
            rest.append(factor)
    if len(sins) + len(coss) != 2:
        return None
    key = sp.default_sort_key  # cached per expression, unlike sp.ordered's full comparison
    return sp.Mul(*rest), tuple(sorted(sins, key=key)), tuple(sorted(coss, key=key))


def combine_angle_differences(expr: sp.Expr) -> sp.Expr:
    """Apply the identities above to the terms of an Add (other expressions are returned)."""
    if not expr.is_Add:
        return expr
    return combine_terms(expr.args)


def combine_terms(terms: Sequence[sp.Expr]) -> sp.Expr:
    """The sum of ``terms`` with the identities above applied between them."""
    return sp.Add(*combined_terms(terms))


def combined_terms(terms: Sequence[sp.Expr]) -> list[sp.Expr]:
    """``terms`` with the identities above applied between them (a list of terms)."""
    terms = list(terms)
    parsed = [_split(term) for term in terms]
    index: dict[tuple, list[int]] = defaultdict(list)
    for k, item in enumerate(parsed):
        if item is not None:
            index[item].append(k)
    used = [False] * len(terms)
    combined = []
    for k, item in enumerate(parsed):
        if item is None or used[k]:
            continue
        rest, sins, coss = item
        partner, replacement = None, None
        if len(sins) == 2:  # c sin a sin b + c cos a cos b
            partner = _take(index, (rest, (), sins), used, k)
            if partner is not None:
                replacement = _difference(rest, sp.cos, *sins)
        elif len(sins) == 1:  # c sin a cos b - c cos a sin b
            a, b = sins[0], coss[0]
            if a != b:
                partner = _take(index, (_negated(rest), (b,), (a,)), used, k)
                if partner is not None:
                    replacement = _difference(rest, sp.sin, a, b)
        if partner is not None:
            used[k] = used[partner] = True
            combined.append(replacement)
    combined.extend(term for term, done in zip(terms, used, strict=True) if not done)
    return combined


# Chains meet the same pairs again for every body further out: build each result once.
@lru_cache(maxsize=1 << 16)
def _difference(rest: sp.Expr, function, a: sp.Expr, b: sp.Expr) -> sp.Expr:
    # sympy's trig eval spends milliseconds looking for multiples of pi; the sign is the only
    # canonicalisation an angle difference needs, so it is done here and eval is skipped.
    if a == b:
        return rest * function(sp.S.Zero)
    sign = 1
    if sp.default_sort_key(b) < sp.default_sort_key(a):  # write the difference in sorted order
        a, b = b, a
        sign = -1 if function is sp.sin else 1
    return sign * rest * function(a - b, evaluate=False)


@lru_cache(maxsize=1 << 16)
def _negated(expr: sp.Expr) -> sp.Expr:
    return -expr


def _take(index, key, used, exclude):
    for k in index.get(key, ()):
        if not used[k] and k != exclude:
            return k
    return None
