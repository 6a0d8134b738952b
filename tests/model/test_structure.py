"""Shared-node equality and evaluation (model/structure.py) against sympy's own == and evalf."""

from __future__ import annotations

import random

import pytest
import sympy as sp

from lagrangian.model.structure import complex_values, same_structure

x, y, z = sp.symbols("x y z")


def _random_expression(rng: random.Random, depth: int):
    if depth == 0:
        return rng.choice([x, y, z, sp.Rational(rng.randint(1, 9), rng.randint(1, 9)),
                           sp.Float(rng.uniform(-2, 2)), sp.pi])
    a, b = _random_expression(rng, depth - 1), _random_expression(rng, depth - 1)
    return rng.choice([a + b, a * b, a - b, sp.sin(a) * b, sp.cos(a + b), sp.sqrt(a * a + 1),
                       a ** 3, sp.exp(a / 4), sp.atan2(a, b + 3), sp.Abs(a) + b])


@pytest.mark.parametrize("seed", range(6))
def test_values_equal_sympys_evalf_on_a_shared_tree(seed):
    rng = random.Random(seed)
    shared = _random_expression(rng, 3)
    exprs = [shared * _random_expression(rng, 2) + shared, sp.cos(shared) ** 2, shared]
    point = {x: 0.3 + seed / 10, y: -0.7, z: 1.1}
    for got, expr in zip(complex_values(exprs, point), exprs, strict=True):
        expected = complex(expr.xreplace({k: sp.Float(v, 30) for k, v in point.items()}).evalf(30))
        assert got == pytest.approx(expected, rel=1e-12, abs=1e-12)


def test_a_symbol_without_a_value_is_refused():
    with pytest.raises(ValueError, match="no value for z"):
        complex_values([x + z], {x: 1.0})


def test_equality_is_sympys_on_trees_and_containers():
    rng = random.Random(7)
    a = _random_expression(rng, 4)
    rebuilt = a.func(*a.args)  # an equal tree, other objects at the top
    assert same_structure((a, [a, 1.0]), (rebuilt, [rebuilt, 1.0]))
    assert not same_structure((a,), (a + sp.Rational(1, 10**12),))
    assert not same_structure([a], (a,))  # a list is not a tuple, as ==
    assert same_structure(a, rebuilt) == (a == rebuilt)
