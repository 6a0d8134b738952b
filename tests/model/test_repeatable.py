"""sympy's random numbers fixed inside repeatable_random() (its factoring's evaluation points,
hence its cost, the same in every run) and the caller's state given back."""

from __future__ import annotations

from sympy.core import random as sympy_random

from lagrangian.model.repeatable import repeatable_random


def test_the_points_repeat_and_the_callers_state_is_given_back():
    sympy_random.rng.seed(5)
    before = sympy_random.rng.getstate()
    with repeatable_random():
        first = [sympy_random.randint(0, 10**9) for _ in range(3)]
    assert sympy_random.rng.getstate() == before
    with repeatable_random():
        assert [sympy_random.randint(0, 10**9) for _ in range(3)] == first
    try:
        with repeatable_random():
            raise ValueError
    except ValueError:
        assert sympy_random.rng.getstate() == before
