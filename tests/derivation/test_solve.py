"""derive has a bounded cost: symbolic accelerations under a budget, verified, or null with a
note; models that used to hang (sympy's pendulum on a cart, the 3-link pendulum) print fast."""

from __future__ import annotations

import random
import time

import numpy as np
import pytest
import sympy as sp

from lagrangian.derivation.lagrange import derive
from lagrangian.derivation.solve import solve_accelerations
from lagrangian.model.reader import parse_model
from lagrangian.output.derivation import derivation_document, derivation_latex, derivation_text


def pendulum_on_a_cart(n: int) -> str:
    """sympy.physics.mechanics.models.n_link_pendulum_on_cart as a model file: cart at (q0, 0),
    links from the upward vertical, gravity -y, a force F on the cart."""
    lines = ['[coordinates]', 'q0 = "m"'] + [f'q{i} = "rad"' for i in range(1, n + 1)]
    lines += ["[parameters]", "g = 9.81", "F = 1.0"] + [f"m{i} = 1.0" for i in range(n + 1)]
    lines += [f"l{i} = 1.0" for i in range(n)]
    lines += ["[gravity]", 'g = "g"']
    lines += ["[[particles]]", 'name = "cart"', 'mass = "m0"', 'position = ["q0", 0]']
    x, y = "q0", "0"
    for i in range(1, n + 1):
        x, y = f"{x} - l{i - 1}*sin(q{i})", f"{y} + l{i - 1}*cos(q{i})"
        lines += ["[[particles]]", f'name = "P{i}"', f'mass = "m{i}"', f'position = ["{x}", "{y}"]']
    lines += ["[[loads]]", 'name = "push"', 'point = "cart"', 'force = ["F", 0]']
    return "\n".join(lines) + "\n"


def chain(n: int) -> str:
    lines = ["[coordinates]"] + [f'theta{i} = "rad"' for i in range(1, n + 1)]
    lines += ["[parameters]", "g = 9.81"] + [f"m{i} = 1.0\nl{i} = 1.0" for i in range(1, n + 1)]
    lines += ["[gravity]", 'g = "g"']
    x = y = "0"
    for i in range(1, n + 1):
        x, y = f"{x} + l{i}*sin(theta{i})", f"{y} - l{i}*cos(theta{i})"
        lines += ["[[particles]]", f'name = "b{i}"', f'mass = "m{i}"', f'position = ["{x}", "{y}"]']
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("text", [pendulum_on_a_cart(2), chain(3)], ids=["cart-2", "chain-3"])
def test_models_that_hung_derive_and_print_in_every_format_quickly(text):
    start = time.perf_counter()
    eom = derive(parse_model(text))
    for render in (derivation_text, derivation_document, derivation_latex):
        assert render(eom)
    # a hang guard, not a speed test (speed lives in benchmarks/): these took over 5 minutes
    assert time.perf_counter() - start < 60
    if eom.accelerations is None:
        assert eom.accelerations_note.startswith("not solved symbolically: ")


def _numeric_check(eom, seed=0):
    """The closed form against numpy's solve of M q_ddot = f at a random state."""
    rng = random.Random(seed)
    values = {s: rng.uniform(0.3, 1.5) for e in (*eom.mass_matrix, *eom.forcing)
              for s in e.free_symbols}
    M = np.array(eom.mass_matrix.xreplace(values).evalf(), dtype=float)
    f = np.array(eom.forcing.xreplace(values).evalf(), dtype=float).ravel()
    ours = [float(a.xreplace(values)) for a in eom.accelerations]
    assert ours == pytest.approx(list(np.linalg.solve(M, f)), rel=1e-10)


def test_the_single_pendulum_on_a_cart_has_a_verified_closed_form():
    eom = derive(parse_model(pendulum_on_a_cart(1)))
    assert eom.accelerations is not None and eom.accelerations_note is None
    _numeric_check(eom)
    q1 = sp.Symbol("q1")
    m0, m1, l0 = sp.symbols("m0 m1 l0")
    # the denominator is the determinant of M / l0^2 m1: m0 + m1 sin^2(q1)
    denominator = sp.denom(sp.factor(eom.accelerations[0]))
    assert sp.simplify(denominator - (m0 + m1 * sp.sin(q1) ** 2)) == 0


def test_a_spent_time_budget_gives_null_with_a_note():
    eom = derive(parse_model(chain(2)))
    result = solve_accelerations(eom.mass_matrix, eom.forcing, eom.constraint_jacobian,
                                 eom.acceleration_rhs, seconds=0.0)
    assert result.accelerations is None
    assert result.note == ("not solved symbolically: the time budget (0.5 s) ran out; the "
                           "equations are given in the implicit form M q_ddot = f")


def test_too_many_unknowns_and_too_large_forms_are_noted():
    eom = derive(parse_model(chain(4)))
    assert eom.accelerations is None
    assert eom.accelerations_note == ("not solved symbolically: 4 unknowns (more than 3); the "
                                      "equations are given in the implicit form M q_ddot = f")
    big = derive(parse_model(pendulum_on_a_cart(2)))
    assert big.accelerations_note == ("not solved symbolically: the closed form would exceed "
                                      "80 terms; the equations are given in the implicit form "
                                      "M q_ddot = f")


def test_double_pendulum_closed_form_agrees_with_numpy():
    eom = derive(parse_model(chain(2)))
    _numeric_check(eom, seed=3)


def test_a_wrong_closed_form_is_never_returned():
    """sin and cos are independent to the elimination; a pivot that is zero only through
    sin^2 + cos^2 = 1 is caught by the numeric verification."""
    theta = sp.Symbol("theta")
    M = sp.ImmutableMatrix([[sp.sin(theta) ** 2 + sp.cos(theta) ** 2 - 1, 0], [0, 1]])
    f = sp.ImmutableMatrix([1, 0])
    empty = sp.ImmutableMatrix(0, 2, [])
    result = solve_accelerations(M, f, empty, sp.ImmutableMatrix(0, 1, []))
    assert result.accelerations is None
