"""Readable forms of derived expressions, for display only: every form returned is equal to the
expression it came from (the same function of q, q_dot, parameters and t), only written shorter.

What a person checking a hand derivation expects to see:

- terms grouped by products of the rates (q_dot_i q_dot_j, q_ddot_i, multipliers), each with a
  compact coefficient, and the factors common to the rate terms pulled out;
- in coefficients (small by construction), the angle-sum identities (sin a cos b + cos a sin b
  = sin(a + b), ...) and sin^2 + cos^2 = 1 applied, and like trig monomials collected;
- cos(-u) -> cos(u), sin(-u) -> -sin(u); an even power of -u written as one of u, so that
  (x + 1)**2/(-x - 1)**2 cancels;
- sqrt(u**2) -> abs(u), and abs(u) -> u (or -u) where the coordinates' declared ranges fix
  its sign.

Cost is bounded: the heavy steps (expansion, trig identities) run only on coefficients below
``COEFFICIENT_BUDGET`` nodes (400 in an expression of at most ``SMALL_EXPRESSION`` nodes and
``SMALL_ANGLES`` angles), and
the grouping gives up past ``MAX_MONOMIALS`` rate products, returning the tidied expression.
Nothing here calls ``simplify``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import sympy as sp
from sympy.core.mul import _keep_coeff
from sympy.simplify.fu import TR10i

from .trig_normal import trig_normal_form

COEFFICIENT_BUDGET = 160  # nodes of a coefficient above which only cheap steps run
SMALL_EXPRESSION = 1500  # nodes of a whole expression whose coefficients get a budget of 400
SMALL_ANGLES = 3  # ... and at most this many distinct trig arguments
_SMALL_BUDGET = 400
MAX_MONOMIALS = 400  # rate products per expression above which no grouping is attempted
MAX_PULLED_TERMS = 40  # terms of a sum above which no common factor is pulled out of it
NORMAL_FORM_FROM = 40  # nodes of a compacted coefficient from which sin^2 + cos^2 is normalized
_CACHE_LIMIT = 50_000

_TRIG = (sp.sin, sp.cos)
_cache: dict = {}


def _remember(key, value):
    if len(_cache) > _CACHE_LIMIT:
        _cache.clear()
    _cache[key] = value
    return value


def _size(expr: sp.Basic, cap: int) -> int:
    """Nodes of the expression tree, counting stops at ``cap``."""
    count, stack = 0, [expr]
    while stack and count < cap:
        node = stack.pop()
        count += 1
        stack.extend(node.args)
    return count


def _ops(expr: sp.Expr) -> int:
    return sp.count_ops(expr)


def _shortest(options: list[sp.Expr]) -> sp.Expr:
    """The first of the shortest options: by sympy's count_ops when they are small, by their
    node count (a cheap stand-in, walked once) when large."""
    if len(options) == 1:
        return options[0]
    if max(_size(o, 400) for o in options) < 400:
        return min(options, key=_ops)
    return min(options, key=lambda o: _size(o, 10**9))


def _trig_candidates(expr: sp.Expr) -> bool:
    """Whether an identity could apply: sin and cos of one angle, or trig of several angles."""
    functions = expr.atoms(*_TRIG)
    angles = {f.args[0] for f in functions}
    return len(angles) > 1 or len(functions) > len(angles)


# -- tidy: cheap local rewrites ------------------------------------------------------------------


def _sign_over_ranges(u: sp.Expr, ranges: Mapping[sp.Symbol, tuple[float, float]]) -> int:
    """+1 or -1 when u keeps that sign over the coordinates' declared ranges, else 0."""
    if not ranges or not u.free_symbols or not u.free_symbols <= set(ranges):
        return 0
    try:
        bounds = u.xreplace({s: sp.AccumBounds(*map(sp.nsimplify, ranges[s]))
                             for s in u.free_symbols})
        if isinstance(bounds, sp.AccumBounds):
            low, high = bounds.min, bounds.max
        else:
            low = high = bounds
        if low.is_extended_positive:
            return 1
        if high.is_extended_negative:
            return -1
    except Exception:  # noqa: BLE001 - an unknown sign only keeps abs()
        return 0
    return 0


def _even(exponent: sp.Expr) -> bool:
    return exponent.is_Integer and exponent % 2 == 0


def _negative_first(expr: sp.Expr) -> bool:
    """Whether -expr is the tidier sign: a negative product, or a sum with more negative
    terms than positive ones (cheap, unlike sympy's could_extract_minus_sign on sums)."""
    if expr.is_Add:
        negative = sum(1 for term in expr.args if term.as_coeff_Mul()[0].is_negative)
        return 2 * negative > len(expr.args)
    return expr.as_coeff_Mul()[0].is_negative is True


def _rewrite(node: sp.Expr, ranges) -> sp.Expr:
    """One node's rewrite (its arguments already tidied)."""
    if isinstance(node, sp.cos | sp.sin | sp.tan) and _negative_first(node.args[0]):
        # Even and odd functions of a negated argument (sympy folds most; not every sum).
        folded = node.func(-node.args[0])
        return folded if isinstance(node, sp.cos) else -folded
    if node.is_Pow:
        base, exponent = node.args
        if _even(exponent) and _negative_first(base):
            return sp.Pow(-base, exponent)
        if exponent.is_Rational and exponent.q == 2 and base.is_Pow and _even(base.args[1]):
            # sqrt(u**(2k))**p = |u|**(k p) for real u: every quantity of a model is real.
            inner, power = base.args
            if _negative_first(inner):
                inner = -inner
            new_exponent = power / 2 * exponent.p
            if _even(new_exponent):
                return inner**new_exponent  # |u|^(2j) = u^(2j)
            return _absolute(inner, ranges) ** new_exponent
        return node
    if isinstance(node, sp.Abs):
        sign = _sign_over_ranges(node.args[0], ranges)
        return sign * node.args[0] if sign else node
    return node


def _absolute(u: sp.Expr, ranges) -> sp.Expr:
    sign = _sign_over_ranges(u, ranges)
    return sign * u if sign else sp.Abs(u)


def tidy(expr: sp.Expr, ranges: Mapping[sp.Symbol, tuple[float, float]] | None = None
         ) -> sp.Expr:
    """The cheap rewrites (negated arguments, even powers, sqrt(u**2)), bottom up."""
    ranges = ranges or {}
    memo: dict = {}

    def visit(node):
        if node.is_Atom or not isinstance(node, sp.Expr):
            return node
        found = memo.get(node)
        if found is not None:
            return found
        args = tuple(visit(a) for a in node.args)
        rebuilt = node.func(*args) if args != node.args else node
        result = _rewrite(rebuilt, ranges) if isinstance(rebuilt, sp.Expr) else rebuilt
        memo[node] = result
        return result

    return visit(sp.sympify(expr))  # safe: a sympy object or a number


# -- grouping by products of generators -----------------------------------------------------------


class _TooMany(Exception):
    pass


class _Contains:
    """Whether an expression holds one of the generators, remembered per sub-expression
    (sympy recomputes free_symbols on every call)."""

    def __init__(self, generators: frozenset):
        self.generators = generators
        self.symbols = all(g.is_Symbol for g in generators)
        self.memo: dict = {}

    def __call__(self, expr: sp.Expr) -> bool:
        found = self.memo.get(expr)
        if found is None:
            if expr.is_Atom:
                found = expr in self.generators
            elif self.symbols:
                found = any(self(a) for a in expr.args)
            else:
                found = expr in self.generators or any(self(a) for a in expr.args)
            self.memo[expr] = found
        return found


def _monomials(expr: sp.Expr, generators: frozenset, contains: _Contains | None = None
               ) -> dict[tuple, list]:
    """expr as {monomial: [coefficient terms]}, a monomial a sorted tuple of (generator, power);
    factors free of the generators stay as they are (not expanded)."""
    contains = contains or _Contains(generators)
    if not contains(expr):
        return {(): [expr]}
    if expr in generators:
        return {((expr, 1),): [sp.S.One]}
    if expr.is_Add:
        merged: dict[tuple, list] = {}
        for term in expr.args:
            for m, c in _monomials(term, generators, contains).items():
                merged.setdefault(m, []).extend(c)
        return merged
    if expr.is_Mul:
        free, powers, rest = [], {}, []
        for factor in expr.args:
            base, exponent = factor.as_base_exp()
            if base in generators and exponent.is_Integer and exponent > 0:
                powers[base] = powers.get(base, 0) + exponent
            elif contains(factor):
                rest.append(factor)
            else:
                free.append(factor)
        product: dict[tuple, list] = {_key(powers): [sp.Mul(*free)]}
        for factor in rest:
            product = _multiply(product, _monomials(factor, generators, contains))
        return product
    if expr.is_Pow and expr.args[1].is_Integer and 1 < expr.args[1] <= 4:
        base = _monomials(expr.args[0], generators, contains)
        product = base
        for _ in range(int(expr.args[1]) - 1):
            product = _multiply(product, base)
        return product
    return {(): [expr]}  # a generator inside a function or a denominator: left whole


def _multiply(a: dict, b: dict) -> dict:
    if len(a) * len(b) > MAX_MONOMIALS:
        raise _TooMany
    result: dict[tuple, list] = {}
    for ma, ca in a.items():
        for mb, cb in b.items():
            powers = dict(ma)
            for g, p in mb:
                powers[g] = powers.get(g, 0) + p
            key = _key(powers)
            coefficient = sp.Add(*ca) * sp.Add(*cb)
            result.setdefault(key, []).append(coefficient)
    return result


def _key(powers: dict) -> tuple:
    return tuple(sorted(powers.items(), key=lambda item: str(item[0])))


def _product(monomial: tuple) -> sp.Expr:
    return sp.Mul(*(g**p for g, p in monomial))


# -- coefficients -----------------------------------------------------------------------------------


def _pythagoras(expr: sp.Expr) -> sp.Expr:
    """sin^2 + cos^2 = 1: for each angle with both squared functions, the shorter of the two
    substitutions (cos^2 -> 1 - sin^2, sin^2 -> 1 - cos^2) or none."""
    angles = {f.args[0] for f in expr.atoms(sp.sin)} & {f.args[0] for f in expr.atoms(sp.cos)}
    best, best_ops = expr, _ops(expr)
    for x in sorted(angles, key=sp.default_sort_key):
        for square, other in ((sp.cos(x) ** 2, sp.sin(x) ** 2), (sp.sin(x) ** 2, sp.cos(x) ** 2)):
            if not best.has(square):
                continue
            candidate = sp.expand(best.subs(square, 1 - other), trig=False, log=False,
                                  power_exp=False, power_base=False)
            ops = _ops(candidate)
            if ops < best_ops:
                best, best_ops = candidate, ops
    return best


def _collected(expr: sp.Expr) -> sp.Expr:
    """Like trig monomials collected, each coefficient with its common factors out."""
    trig = frozenset(a for a in expr.atoms(*_TRIG))
    if not trig:
        return sp.factor_terms(expr)
    try:
        groups = _monomials(expr, trig)
    except _TooMany:
        return expr
    return sp.Add(*(sp.factor_terms(sp.Add(*c)) * _product(m) for m, c in groups.items()))


def compact(coefficient: sp.Expr, budget: int = COEFFICIENT_BUDGET) -> sp.Expr:
    """The shortest (sympy count_ops) of a few equal forms of a coefficient free of the rates:
    as given, common factors out, and, when small, expanded with the trig identities applied
    and like terms collected."""
    if coefficient.is_Atom or not isinstance(coefficient, sp.Expr):
        return coefficient
    key = ("compact", coefficient, budget)
    found = _cache.get(key)
    if found is not None:
        return found
    options = [coefficient]
    small = _size(coefficient, budget + 1) <= budget
    if coefficient.is_Add:
        # sympy's factor_terms recurses through the whole tree: on small coefficients only.
        options.append(sp.factor_terms(coefficient) if small
                       else _pull_common(list(coefficient.args)))
    if small and (coefficient.is_Add or _trig_candidates(coefficient)):
        try:
            expanded = sp.expand(coefficient, trig=False, log=False, power_exp=False,
                                 power_base=False)
            if _size(expanded, 4 * budget) < 4 * budget:
                identities = expanded
                if _trig_candidates(expanded):
                    angles = {f.args[0] for f in expanded.atoms(*_TRIG)}
                    identities = TR10i(expanded) if len(angles) > 1 else expanded
                    identities = _pythagoras(identities)
                collected = _collected(identities)
                options += [collected, sp.factor_terms(collected)]
        except Exception:  # noqa: BLE001 - a failed rewrite only costs readability
            pass
    best = options[0] if len(options) == 1 else _shortest(options)
    if _size(best, NORMAL_FORM_FROM) >= NORMAL_FORM_FROM and _trig_candidates(best):
        # sin^2 + cos^2 = 1 applied exactly (a particle-built top's T: products of its rotation
        # matrix's entries); the normal form and its common factors out. Only where the forms
        # above left a long one: the expansion costs a few ms a coefficient
        normal = trig_normal_form(coefficient)
        if normal is not None:
            collected = _collected(normal)
            best = _shortest([best, normal, collected, sp.factor_terms(collected)])
    return _remember(key, best)


# -- the readable form ------------------------------------------------------------------------------


def rate_symbols(expr: sp.Expr) -> frozenset:
    """Velocities, accelerations and multipliers of an expression, known by their names
    (q_dot, q_ddot, lambda_*), for callers without the model at hand."""
    return frozenset(s for s in expr.free_symbols
                     if s.name.endswith(("_dot", "_ddot")) or s.name.startswith("lambda_"))


def readable(expr: sp.Expr, rates: Iterable[sp.Symbol] | None = None,
             ranges: Mapping[sp.Symbol, tuple[float, float]] | None = None) -> sp.Expr:
    """An equal, shorter form of ``expr`` for display: grouped by products of ``rates``
    (velocities, accelerations, multipliers; found by name when not given), each coefficient
    compacted, common factors out; ``ranges`` the coordinates' declared (low, high)."""
    expr = sp.sympify(expr)  # safe: a sympy object or a number
    if expr.is_Atom:
        return expr
    generators = frozenset(rates) if rates is not None else rate_symbols(expr)
    ranges = dict(ranges or {})
    key = ("readable", expr, generators, tuple(sorted(ranges.items(), key=str)))
    found = _cache.get(key)
    if found is not None:
        return found
    try:
        result = _readable(expr, generators, ranges)
    except Exception:  # noqa: BLE001 - display only (a RecursionError too): the derived form stands
        result = expr
    return _remember(key, result)


def _readable(expr: sp.Expr, generators: frozenset, ranges: dict) -> sp.Expr:
    tidied = tidy(expr, ranges)
    numerator, denominator = tidied, sp.S.One
    if tidied.is_Mul and any(f.is_Pow and f.exp.is_negative and not f.base.is_Number
                             for f in tidied.args):
        numerator, denominator = sp.fraction(tidied)
    # A small expression in few angles (a two-link arm's solved acceleration) affords larger
    # coefficients; the identities' cost grows with the angles (the bicycle's M: 1 s an entry).
    budget = COEFFICIENT_BUDGET
    if _size(tidied, SMALL_EXPRESSION + 1) <= SMALL_EXPRESSION and len(
            {f.args[0] for f in tidied.atoms(*_TRIG)}) <= SMALL_ANGLES:
        budget = _SMALL_BUDGET
    if denominator is not sp.S.One:
        result = (_grouped(numerator, generators, budget)
                  / _grouped(denominator, generators, budget))
        result = _shortest([result, tidied])
    else:
        result = _grouped(tidied, generators, budget)
        if _size(result, 400) < 400:
            square = _completed_square(tidied, generators, budget)
            if square is not None and _ops(square) < _ops(result) - 2:
                result = square
    return result


def _completed_square(expr: sp.Expr, generators: frozenset, budget: int) -> sp.Expr | None:
    """A quadratic form in the rates (plus a rate-free part: T) with one rate's terms gathered
    into a square, a (u + sum_w b_w/(2 a) w)^2 from a u^2 + sum_w b_w u w (a top's
    C (psi_dot + phi_dot cos(theta))^2), the rest compacted; None where it is no such form."""
    try:
        groups = _monomials(expr, generators)
    except _TooMany:
        return None
    free = compact(sp.Add(*groups.pop((), [])), budget)
    if not groups or any(sum(p for _, p in m) != 2 for m in groups):
        return None
    coefficients = {m: compact(sp.Add(*c), budget) for m, c in groups.items()}
    rates = sorted({g for m in coefficients for g, _ in m}, key=str)
    if len(rates) > 6:
        return None
    best, best_ops = None, None
    for u in rates:
        a = coefficients.get(((u, 2),))
        if a is None or a == 0:
            continue
        shifts = {}
        for m, c in coefficients.items():
            if len(m) == 2 and u in (m[0][0], m[1][0]):
                shift = sp.cancel(c / (2 * a))
                if _size(shift, 40) >= 40:
                    break
                shifts[m[1][0] if m[0][0] == u else m[0][0]] = shift
        else:
            if not shifts:
                continue
            rest = {m: c for m, c in coefficients.items() if u not in (g for g, _ in m)}
            ws = sorted(shifts, key=str)
            for i, w in enumerate(ws):
                for w2 in ws[i:]:
                    key = _key({w: 2} if w == w2 else {w: 1, w2: 1})
                    twice = 1 if w == w2 else 2
                    rest[key] = rest.get(key, sp.S.Zero) - twice * a * shifts[w] * shifts[w2]
            square = a * (u + sp.Add(*(shifts[w] * w for w in ws))) ** 2
            terms = [compact(c, budget) * _product(m) for m, c in rest.items()]
            candidate = free + _pull_common([square, *terms], generators)
            ops = _ops(candidate)
            if best is None or ops < best_ops:
                best, best_ops = candidate, ops
    return best


def _pull_common(terms: list[sp.Expr], keep: frozenset = frozenset()) -> sp.Expr:
    """sum(terms) with the factors common to every term (numeric content, the sign when all
    are negative, shared powers but those of ``keep``) written once in front; the terms
    themselves stay flat."""
    terms = [t for t in terms if t != 0]
    if len(terms) < 2:
        return sp.Add(*terms)
    numbers, powers = [], []
    for term in terms:
        number, rest = term.as_coeff_Mul()
        numbers.append(number)
        powers.append(rest.as_powers_dict())
    common = {}
    for base, exponent in powers[0].items():
        if base.is_Number or base in keep or not (exponent.is_Integer and exponent > 0):
            continue
        shared = [p.get(base, sp.S.Zero) for p in powers]
        if all(e.is_Integer and e > 0 for e in shared):
            common[base] = min(shared)
    scale = sp.S.One
    if all(n.is_Rational for n in numbers):
        scale = sp.Rational(sp.igcd(*[n.p for n in numbers]), sp.ilcm(*[n.q for n in numbers]))
    if all(n.is_negative for n in numbers):
        scale = -scale
    if scale == 1 and not common:
        return sp.Add(*terms)
    front = sp.Mul(*(b**e for b, e in common.items()))
    inner = sp.Add(*[(n / scale) * sp.Mul(*(b ** (e - common.get(b, 0)) for b, e in p.items()))
                     for n, p in zip(numbers, powers, strict=True)])
    return _keep_coeff(sp.Rational(scale), front * inner) if scale != 1 else front * inner


def _grouped(expr: sp.Expr, generators: frozenset, budget: int = COEFFICIENT_BUDGET
             ) -> sp.Expr:
    if expr.is_Atom:
        return expr
    contains = _Contains(generators)
    groups: dict[tuple, list] = {}
    whole: dict[tuple, sp.Expr] = {}  # a term that alone makes its group, kept as it is
    try:
        for term in sp.Add.make_args(expr):
            parts = _monomials(term, generators, contains)
            for m, c in parts.items():
                if m in groups:
                    whole.pop(m, None)
                elif len(parts) == 1 and len(c) == 1:
                    whole[m] = term
                groups.setdefault(m, []).extend(c)
    except _TooMany:
        return _shortest([compact(expr, budget), expr])
    if list(groups) == [()]:
        simpler = compact(expr, budget)
        return expr if simpler is expr else _shortest([simpler, expr])
    free = compact(sp.Add(*groups.pop((), [])), budget)
    rate_terms = []
    for m, c in groups.items():
        coefficient = sp.Add(*c)
        simpler = compact(coefficient, budget)
        rate_terms.append(whole[m] if m in whole and simpler is coefficient
                          else simpler * _product(m))
    if len(rate_terms) > MAX_PULLED_TERMS:  # a long sum stays flat: its terms are the reading
        return free + sp.Add(*rate_terms)
    # The rates stay in their terms (each term shows its product of rates).
    grouped = free + _pull_common(rate_terms, generators)
    if free == 0 or len(rate_terms) > 12:
        return grouped
    together = _pull_common([*sp.Add.make_args(free), *rate_terms], generators)
    # A factor common to the rate-free and the rate terms is pulled out only where it saves
    # more than two operations: the split between them is what a reader checks first.
    if _size(grouped, 400) >= 400:
        return _shortest([grouped, together])
    return together if _ops(together) < _ops(grouped) - 2 else grouped


def readable_matrix(matrix: sp.MatrixBase, rates=None, ranges=None) -> sp.ImmutableMatrix:
    """``readable`` applied to each entry."""
    return sp.ImmutableMatrix(matrix.rows, matrix.cols,
                              [readable(v, rates, ranges) for v in matrix])
