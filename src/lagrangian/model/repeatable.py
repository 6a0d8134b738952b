"""sympy's own random numbers fixed for the length of a call, and given back after.

sympy factors multivariate polynomials (inside trigsimp, factor, cancel) by Wang's algorithm at
random evaluation points from its module-level generator, seeded anew in every process: the
same expression then takes milliseconds in one run and, at an unlucky point, half an hour in
another (a four-bar's printed share, seen in a test run). Under ``repeatable_random()`` the
points are the same in every run, so a call's cost is the one the tests measured; the caller's
own sympy random state is restored on the way out."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

from sympy.core import random as sympy_random

SEED = 2026


@contextlib.contextmanager
def repeatable_random() -> Iterator[None]:
    """sympy's random generator seeded with SEED inside, its state as it was after."""
    state = sympy_random.rng.getstate()
    sympy_random.rng.seed(SEED)
    try:
        yield
    finally:
        sympy_random.rng.setstate(state)


__all__ = ["SEED", "repeatable_random"]
