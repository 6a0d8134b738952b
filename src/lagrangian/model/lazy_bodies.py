"""A large URDF tree's symbolic rigid bodies, built on first use: their positions are sums
whose every addition sorts terms as deep as the chain (sympy), minutes for 200 links, while the
tree's recursive dynamics need only its numbers (model/tree.py). A derivation, a drawing or a
units check asks for them and waits; loading and the dynamics do not."""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence

# Trees of more moving bodies than this build their symbolic bodies lazily (a 24-body chain
# takes about 2 s; the time grows as n^3).
LAZY_ABOVE = 24


class LazyBodies(Sequence):
    """A tuple of RigidBody made by ``make()`` when first read; its length known before."""

    def __init__(self, make: Callable[[], Sequence], count: int):
        self._make: Callable[[], Sequence] | None = make
        self._count = count
        self._items: tuple | None = None

    def _built(self) -> tuple:
        if self._items is None:
            assert self._make is not None
            self._items = tuple(self._make())
            self._make = None
        return self._items

    def __len__(self) -> int:
        return self._count

    def __getitem__(self, index):
        return self._built()[index]

    def __iter__(self) -> Iterator:
        return iter(self._built())

    def __eq__(self, other) -> bool:
        if other is self:
            return True
        if isinstance(other, Sequence) and not isinstance(other, str):
            return len(other) == self._count and tuple(self) == tuple(other)
        return NotImplemented

    def __hash__(self) -> int:  # equal sequences have equal lengths: cheap and consistent
        return hash(("LazyBodies", self._count))

    def __repr__(self) -> str:
        return repr(self._built())

    def __reduce__(self):
        return tuple, (self._built(),)


__all__ = ["LAZY_ABOVE", "LazyBodies"]
