"""Cheap angle-difference identities for readable inertia terms, in linear time (no simplify).

Per-element inertia terms of chains come out as sums like l1 l2 (sin a sin b + cos a cos b);
these rules turn them into the textbook l1 l2 cos(a - b) without trigsimp's search:

    c sin(a) sin(b) + c cos(a) cos(b) -> c cos(a - b)   (and c sin(a)^2 + c cos(a)^2 -> c)
    c sin(a) cos(b) - c cos(a) sin(b) -> c sin(a - b)
    c X - c X -> 0

Terms are handled as decomposed products (coefficient, other factors, sin and cos arguments):
a product of two terms is formed by merging tuples, and a sympy Mul is built only for a term
that is left over, since building sympy objects is what costs.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable
from functools import lru_cache

import sympy as sp

Parts = tuple[sp.Expr, tuple, tuple, tuple]  # coefficient, other factors, sin args, cos args
_KEY = sp.default_sort_key  # canonical order, for what is printed
# Factor tuples are only compared with each other within one run, so any consistent order will
# do: sympy caches each object's hash, while sort keys cost a cache lookup each.
_FAST = hash


@lru_cache(maxsize=1 << 16)
def parts(term: sp.Expr) -> Parts:
    """Decompose a product into (numeric coefficient, other factors, sin args, cos args)."""
    coefficient = sp.S.One
    rest, sins, coss = [], [], []
    for factor in sp.Mul.make_args(term):
        if factor.is_Number:
            coefficient = coefficient * factor
            continue
        base, exponent = factor.as_base_exp()
        if isinstance(base, sp.sin | sp.cos) and exponent.is_Integer and 0 < exponent <= 2:
            target = sins if isinstance(base, sp.sin) else coss
            target.extend([base.args[0]] * int(exponent))
        else:
            rest.append(factor)
    return (coefficient, tuple(sorted(rest, key=_FAST)), tuple(sorted(sins, key=_FAST)),
            tuple(sorted(coss, key=_FAST)))


def product(a: Parts, b: Parts) -> Parts:
    """The parts of the product of two decomposed terms."""
    x, y = a[0], b[0]
    # most coefficients are 1: skip sympy's number product (a chain forms O(n^2) of these)
    coefficient = y if x is sp.S.One else x if y is sp.S.One else x * y
    return (coefficient, _merge(a[1], b[1]), _merge(a[2], b[2]), _merge(a[3], b[3]))


def _merge(x: tuple, y: tuple) -> tuple:
    if not x:
        return y
    if not y:
        return x
    return tuple(sorted(x + y, key=_FAST))


@lru_cache(maxsize=1 << 16)
def build(item: Parts) -> sp.Expr:
    coefficient, rest, sins, coss = item
    return sp.Mul(coefficient, *rest, *(sp.sin(a) for a in sins), *(sp.cos(a) for a in coss))


def combined_terms(items: Iterable[Parts]) -> list[sp.Expr]:
    """Decomposed terms with the identities above applied between them (a list of terms)."""
    items = _pythagorean(list(items))
    index: dict[Parts, list[int]] = defaultdict(list)
    for k, item in enumerate(items):
        index[item].append(k)
    used = [False] * len(items)
    combined = []
    for k, item in enumerate(items):
        if used[k]:
            continue
        coefficient, rest, sins, coss = item
        partner = _take(index, (-coefficient, rest, sins, coss), used, k)
        if partner is not None:  # exact cancellation
            used[k] = used[partner] = True
            continue
        if len(sins) + len(coss) != 2:
            continue
        replacement = None
        if len(sins) == 2:  # c sin a sin b + c cos a cos b
            partner = _take(index, (coefficient, rest, (), sins), used, k)
            if partner is not None:
                replacement = _difference(coefficient, rest, sp.cos, *sins)
        elif len(sins) == 1:  # c sin a cos b - c cos a sin b
            a, b = sins[0], coss[0]
            if a != b:
                partner = _take(index, (-coefficient, rest, (b,), (a,)), used, k)
                if partner is not None:
                    replacement = _difference(coefficient, rest, sp.sin, a, b)
        if partner is not None:
            used[k] = used[partner] = True
            combined.append(replacement)
    combined.extend(build(item) for item, done in zip(items, used, strict=True) if not done)
    return combined


def _pythagorean(items: list[Parts]) -> list[Parts]:
    """c X sin(a)^2 + c X cos(a)^2 -> c X where X holds other sines and cosines too (a point
    spinning about an axis: sin^2(Omega t) + cos^2(Omega t)), repeated while pairs are found.
    Terms with two trig factors are left to the pair rules of combined_terms."""
    while True:
        index: dict[Parts, list[int]] = defaultdict(list)
        for k, item in enumerate(items):
            index[item].append(k)
        used = [False] * len(items)
        merged = []
        for k, (coefficient, rest, sins, coss) in enumerate(items):
            if used[k] or len(sins) + len(coss) <= 2:
                continue
            for a in dict.fromkeys(sins):
                if sins.count(a) < 2:
                    continue
                fewer = _without_pair(sins, a)
                partner = _take(index, (coefficient, rest, fewer, _merge(coss, (a, a))), used, k)
                if partner is not None:
                    used[k] = used[partner] = True
                    merged.append((coefficient, rest, fewer, coss))
                    break
        if not merged:
            return items
        items = merged + [item for item, done in zip(items, used, strict=True) if not done]


def _without_pair(factors: tuple, a: sp.Expr) -> tuple:
    out = list(factors)
    out.remove(a)
    out.remove(a)
    return tuple(out)


# Chains meet the same pairs again for every body further out: build each result once.
@lru_cache(maxsize=1 << 16)
def _difference(coefficient, rest: tuple, function, a: sp.Expr, b: sp.Expr) -> sp.Expr:
    # sympy's trig eval spends milliseconds looking for multiples of pi; the sign is the only
    # canonicalisation an angle difference needs, so it is done here and eval is skipped.
    if a == b:
        return sp.Mul(coefficient, *rest, function(sp.S.Zero))
    if _KEY(b) < _KEY(a):  # write the difference in sorted order
        a, b = b, a
        coefficient = -coefficient if function is sp.sin else coefficient
    return sp.Mul(coefficient, *rest, _of_difference(function, a, b))


@lru_cache(maxsize=1 << 16)
def _of_difference(function, a: sp.Expr, b: sp.Expr) -> sp.Expr:
    # a chain's f_k meets sin(theta_j - theta_k) for every j, and M the cos of the same angles
    return function(_minus(a, b), evaluate=False)


@lru_cache(maxsize=1 << 16)
def _minus(a: sp.Expr, b: sp.Expr) -> sp.Expr:
    return a - b


def _take(index, key, used, exclude):
    for k in index.get(key, ()):
        if not used[k] and k != exclude:
            return k
    return None
