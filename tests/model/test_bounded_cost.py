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


@pytest.mark.parametrize("count", [12, 60])
def test_a_long_rotation_sequence_is_refused_before_any_work(tmp_path, count):
    """Said as a sequence too long (60 rotations also pass the chain's limit of 24)."""
    rotation = ", ".join(f'["{"xyz"[i % 3]}", "{"abc"[i % 3]}"]' for i in range(count))
    text = ("[coordinates]\na = {}\nb = {}\nc = {}\n[[bodies]]\nname = \"b\"\nmass = \"1\"\n"
            "inertia = [\"1\", \"2\", \"3\"]\nposition = [0, 0, 0]\n"
            f"rotation = [{rotation}]\n")
    started = time.perf_counter()
    with pytest.raises(ModelError, match=f"{count} rotations in one sequence.*at most 6"):
        parse_model(text, source="spin.toml")
    assert time.perf_counter() - started < 2


def test_a_chain_too_long_to_derive_is_refused_where_it_passes_the_limit():
    """Built (its dynamics go down the tree), refused by derive before the work, naming the
    first body past the limit."""
    from lagrangian.derivation.lagrange import derive
    from lagrangian.model.builder import ModelBuilder
    from lagrangian.model.rotations import MAX_CHAIN_ROTATIONS

    b = ModelBuilder("chain")
    parent = None
    for i in range(MAX_CHAIN_ROTATIONS + 5):
        b.coordinate(f"q{i}", "rad")
        joint = {"type": "revolute", "axis": "xy"[i % 2], "angle": f"q{i}"}
        if parent:
            joint["at"] = [0, 0, -1]
        b.add_rigid_body(f"link{i}", 1.0, [0.1, 0.1, 0.02], parent=parent, joint=joint,
                         center=[0, 0, -0.5])
        parent = f"link{i}"
    started = time.perf_counter()
    with pytest.raises(ModelError, match=f"at most {MAX_CHAIN_ROTATIONS}") as error:
        derive(b.build_model())
    assert time.perf_counter() - started < 2
    assert f"link{MAX_CHAIN_ROTATIONS}" in str(error.value)
    # prismatic joints turn nothing: a long chain of sliders is fine
    b = ModelBuilder("sliders")
    parent = None
    for i in range(MAX_CHAIN_ROTATIONS + 5):
        b.coordinate(f"s{i}", "m")
        joint = {"type": "prismatic", "axis": "x", "distance": f"s{i}"}
        b.add_rigid_body(f"slider{i}", 1.0, [0.1, 0.1, 0.1], parent=parent, joint=joint)
        parent = f"slider{i}"


@pytest.mark.parametrize("edit", [
    ('direction = [0, 0, -1]', 'direction = [1e-290, 0, -1]'),
    ('axle = "y"', 'axle = [1e-290, 1, 0]'),
])
def test_a_tiny_component_of_gravity_or_an_axle_is_read_as_a_float_quickly(edit):
    """Each made the exact unit vector cost 5-7 s (a square root of a 580-digit rational);
    (1e-290, 0, -1) is (0, 0, -1) to double precision: the same equations."""
    from lagrangian.model.examples import example_path

    source = example_path("rolling_coin").read_text()
    assert edit[0] in source
    started = time.perf_counter()
    system = lagrangian.System(parse_model(source.replace(*edit)))
    eom = system.equations_of_motion()
    assert time.perf_counter() - started < 3
    reference = lagrangian.load("rolling_coin").equations_of_motion()
    assert eom.mass_matrix == reference.mass_matrix
    assert eom.forcing == reference.forcing


def test_a_direction_of_small_exact_numbers_stays_exact():
    """(3, 0, -4) is (3/5, 0, -4/5) exactly: printed equations keep their fractions."""
    import sympy as sp

    model = parse_model("[coordinates]\nx = {}\n[parameters]\ng = 9.81\n[gravity]\ng = \"g\"\n"
                        "direction = [3, 0, -4]\n[[particles]]\nname = \"p\"\nmass = \"1\"\n"
                        "position = [\"x\", 0, 0]\n")
    assert model.gravity.direction == (sp.Rational(3, 5), 0, sp.Rational(-4, 5))
