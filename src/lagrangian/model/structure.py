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


__all__ = ["same_structure"]
