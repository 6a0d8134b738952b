"""Equality of derived expression trees, each shared node compared once.

sympy's ``==`` compares two trees node by node as if written out: a 25-link chain's body
positions share their parents' sums, and comparing two loads of one URDF took tens of seconds.
Here a pair of nodes is compared once (the derivation cache compares models on every hit)."""

from __future__ import annotations

import dataclasses

import sympy as sp


def same_structure(a, b) -> bool:
    """a == b for sympy trees, tuples, lists and dataclasses of them (other values by ==)."""
    return _Comparison().same(a, b)


class _Comparison:
    def __init__(self):
        self.equal: dict[tuple[int, int], tuple[bool, object, object]] = {}

    def same(self, a, b) -> bool:
        if a is b:
            return True
        if isinstance(a, sp.Basic) and isinstance(b, sp.Basic):
            return self._trees(a, b)
        if isinstance(a, (tuple, list)) and isinstance(b, (tuple, list)):
            return (type(a) is type(b) and len(a) == len(b)
                    and all(self.same(x, y) for x, y in zip(a, b, strict=True)))
        if dataclasses.is_dataclass(a) and not isinstance(a, type):
            return type(a) is type(b) and all(
                self.same(getattr(a, f.name), getattr(b, f.name))
                for f in dataclasses.fields(a) if f.compare)
        return bool(a == b)

    def _trees(self, a: sp.Basic, b: sp.Basic) -> bool:
        key = (id(a), id(b))
        seen = self.equal.get(key)
        if seen is not None:
            return seen[0]
        if type(a) is not type(b) or hash(a) != hash(b):  # hashes are cached per node
            result = False
        elif not a.args or not b.args:
            result = a == b
        else:
            result = len(a.args) == len(b.args) and all(
                self._trees(x, y) for x, y in zip(a.args, b.args, strict=True))
        self.equal[key] = (result, a, b)  # a and b held, so that their ids are not reused
        return result





def complex_values(expressions, values) -> list[complex]:
    """Each expression's value (complex) with ``values`` (symbol -> number) put in, each
    shared node evaluated once: xreplace and evalf walk a large tree as if written out (the
    bicycle's joint reactions at its initial state). A node of a kind not listed here is
    evaluated by sympy itself, on the numbers of its arguments."""
    memo: dict[int, tuple[complex, object]] = {}
    given = {k: complex(v) for k, v in values.items()}

    def value(x) -> complex:
        seen = memo.get(id(x))
        if seen is not None:
            return seen[0]
        if x in given:
            result = given[x]
        elif x.is_Number or x.is_NumberSymbol or x is sp.I:
            result = complex(x)
        elif x.is_Add:
            result = sum((value(a) for a in x.args), 0j)
        elif x.is_Mul:
            result = 1 + 0j
            for a in x.args:
                result *= value(a)
        elif x.is_Pow:
            base, exponent = value(x.base), value(x.exp)
            if exponent.imag == 0 and exponent.real == int(exponent.real):
                result = base ** int(exponent.real)
            else:
                result = base ** exponent
        elif type(x) in _FUNCTIONS and len(x.args) == 1:
            result = _FUNCTIONS[type(x)](value(x.args[0]))
        elif not x.args:
            raise ValueError(f"no value for {x}")
        else:  # a function of several arguments: sympy's own, at the numbers put in
            result = complex(x.func(*(sp.sympify(value(a)) for a in x.args)).evalf())  # safe
        memo[id(x)] = (result, x)  # x held, so that its id is not reused meanwhile
        return result

    return [value(sp.sympify(e)) for e in expressions]  # safe: sympy objects, never text


def _functions():
    import cmath
    return {sp.sin: cmath.sin, sp.cos: cmath.cos, sp.tan: cmath.tan, sp.exp: cmath.exp,
            sp.log: cmath.log, sp.sinh: cmath.sinh, sp.cosh: cmath.cosh, sp.tanh: cmath.tanh,
            sp.asin: cmath.asin, sp.acos: cmath.acos, sp.atan: cmath.atan,
            sp.Abs: lambda z: complex(abs(z))}


_FUNCTIONS = _functions()
__all__ = ["complex_values", "same_structure"]
