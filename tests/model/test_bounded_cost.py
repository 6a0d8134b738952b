"""Bounded cost with a clear message (issue 21): chained definitions that would write out to an
exponential tree are refused where they are defined, and a ground normal with a tiny component
is read as floats, not factored exactly."""

from __future__ import annotations

import time

import pytest

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.model.expressions import MAX_TREE_NODES, tree_size
from lagrangian.model.reader import parse_model


def chained(count: int) -> str:
    lines = ["[coordinates]", "x = {}", "[definitions]", 'd0 = "sin(x) + 1"']
    lines += [f'd{i} = "d{i - 1}*cos(d{i - 1})"' for i in range(1, count + 1)]
    lines += ["[energy]", 'T = "x_dot^2/2"', f'V = "d{count}"']
    return "\n".join(lines) + "\n"


def test_tree_size_counts_each_use_of_a_shared_subexpression():
    """Equal to a plain recursive count (each use of a shared node counted again), found on
    the graph instead."""
    import sympy as sp

    def naive(expr):
        return 1 + sum(naive(a) for a in expr.args)

    x = sp.Symbol("x")
    d = sp.sin(x) + 1
    for _ in range(8):
        d = d + d * sp.cos(d)
    assert tree_size(d) == naive(d) > 2**8
    assert tree_size(d, limit=100) > 100


def test_25_chained_definitions_are_refused_at_once():
    started = time.perf_counter()
    with pytest.raises(ModelError, match=f"more than {MAX_TREE_NODES:,} terms") as error:
        parse_model(chained(25), source="defs.toml")
    assert time.perf_counter() - started < 5
    assert "definitions.d" in str(error.value) and "defs.toml" in str(error.value)


def test_a_few_chained_definitions_still_derive():
    """V = d3 with d_i = d_(i-1) cos(d_(i-1)): the equation is x_ddot = -dV/dx."""
    system = lagrangian.System(parse_model(chained(3)))
    eom = system.equations_of_motion()
    x = system.symbol("x")
    import sympy as sp

    d = sp.sin(x) + 1
    for _ in range(3):
        d = d * sp.cos(d)
    assert sp.simplify(eom.forcing[0] + sp.diff(d, x)) == 0


def test_a_tiny_normal_component_is_read_as_a_float_quickly(tmp_path):
    from lagrangian.model.examples import example_path

    source = example_path("rolling_coin").read_text().replace(
        'axle = "y"', 'axle = "y"\nnormal = [1e-290, 0, 1]')
    started = time.perf_counter()
    model = parse_model(source)
    system = lagrangian.System(model)
    system.equations_of_motion()
    assert time.perf_counter() - started < 10
    reference = lagrangian.load("rolling_coin").equations_of_motion()
    # the normal is (0, 0, 1) to double precision: the same equations
    assert system.equations_of_motion().mass_matrix == reference.mass_matrix
