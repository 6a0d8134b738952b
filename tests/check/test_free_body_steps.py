"""crosscheck --steps: each body's free-body equations and their projection onto dr/dq_i.

Asserted as physics: the parallel-axis theorem in a link's projected share, the weight and the
push as the forces on the free bodies, the reactions doing no virtual work (their projection
sums to zero), and the printed shares, read back, summing to derive's own equation.
"""

from __future__ import annotations

import json
import random

import pytest
import sympy as sp

import lagrangian
from lagrangian.model.expressions import parse_expression
from lagrangian.output.crosscheck_steps import crosscheck_steps_document

UNCONSTRAINED = ["virtual_work_link", "cart_pendulum", "double_pendulum", "ladder_vertical_force",
                 "ladder_pendulum"]


def _same(a, b, symbols, trials: int = 4) -> bool:
    rng = random.Random(11)
    free = sorted((sp.sympify(a) - b).free_symbols | set(symbols), key=str)
    for _ in range(trials):
        values = {s: sp.Float(rng.uniform(0.3, 1.4), 30) for s in free}
        x, y = complex(sp.sympify(a).evalf(30, subs=values)), complex(sp.sympify(b).evalf(30, subs=values))
        if abs(x - y) > 1e-12 * max(1.0, abs(x), abs(y)):
            return False
    return True


def _names(model):
    names = {p.name: p.symbol for p in model.parameters}
    for c in model.coordinates:
        names.update({c.name: c.symbol, str(c.velocity): c.velocity,
                      str(c.acceleration): c.acceleration})
    names[str(model.time)] = model.time
    return names


@pytest.mark.parametrize("name", [*UNCONSTRAINED, "damped_oscillator", "slider_crank",
                                  "four_bar"])
def test_printed_shares_sum_to_the_lagrange_equation(name):
    system = lagrangian.load(name)
    model, eom = system.model, system.equations_of_motion()
    document = crosscheck_steps_document(system.crosscheck_steps())
    names = _names(model)
    symbols = list(names.values())
    for i, c in enumerate(model.coordinates):
        p = document["projections"][c.name]
        assert p["agree"] is True
        inertial = sum((parse_expression(v, names) for v in p["inertial"].values()), sp.S.Zero)
        work = sum((parse_expression(v, names) for v in p["work"].values()), sp.S.Zero)
        # Lagrange's (M q_ddot - f)_i, the multiplier terms being on both sides alike
        lagrange = sp.Add(*(eom.mass_matrix[i, j] * a for j, a in enumerate(model.q_ddot))) \
            - eom.forcing[i]
        assert _same(inertial - work, lagrange, symbols), c.name


@pytest.mark.parametrize("name", UNCONSTRAINED)
def test_reactions_do_no_virtual_work(name):
    # sum_b R_b . dr_G/dq_i + M_R dangle/dq_i = 0: ideal joints, so they drop out of E_i
    system = lagrangian.load(name)
    model = system.model
    steps = system.crosscheck_steps()
    positions = {p.name: (p.position, None) for p in model.particles}
    positions.update({b.name: (b.position, b.angle) for b in model.bodies})
    for q in model.q:
        total = sp.S.Zero
        for b in steps.bodies:
            position, angle = positions[b.body]
            total += sum((R * r.diff(q) for R, r in zip(b.reaction, position, strict=True)),
                         sp.S.Zero)
            if b.reaction_moment is not None:
                total += b.reaction_moment * angle.diff(q)
        # on the solution of the equations of motion only: substitute q_ddot from derive
        eom = system.equations_of_motion()
        solved = dict(zip(model.q_ddot, eom.accelerations, strict=True))
        assert _same(total.xreplace(solved), 0, list(_names(model).values())), (name, q)


def test_link_share_is_the_parallel_axis_inertia():
    # worked example 2's link: I_G = m L^2/12 about G, m (L/2)^2 more about the pin -> m L^2/3
    system = lagrangian.load("virtual_work_link")
    steps = system.crosscheck_steps()
    (link,) = steps.bodies
    m, L, F, theta = (system.symbol(n) for n in ("m", "L", "F", "theta"))
    assert link.kind == "body" and sp.simplify(link.inertia - m * L**2 / 12) == 0
    (projection,) = steps.projections
    (_, share), = projection.inertial
    assert sp.simplify(share - m * L**2 * system.symbol("theta_ddot") / 3) == 0
    (_, work), = projection.work
    assert sp.simplify(work - F * L * sp.cos(theta)) == 0
    (force,) = link.forces
    assert force.source == "F" and force.force[:2] == (F, 0)


def test_cart_free_bodies_carry_weight_and_push():
    system = lagrangian.load("cart_pendulum")
    steps = system.crosscheck_steps()
    cart = next(b for b in steps.bodies if b.body == "cart")
    M, g, F = (system.symbol(n) for n in ("M", "g", "F"))
    assert {f.source: f.force[:2] for f in cart.forces} == {"weight": (0, -M * g),
                                                             "push": (F, 0)}
    assert cart.reaction[1] == M * g  # the rail holds the cart's weight (its a_y is 0)
    assert "CrosscheckSteps" in repr(steps) and steps.agree
    assert isinstance(steps, lagrangian.CrosscheckSteps)
    latex = steps._repr_latex_()
    assert latex.startswith("$") and r"\ddot{x}" in latex and r"\text{(cart, x)}" in latex


def test_crosscheck_steps_cli(cli):
    text = cli("crosscheck", "virtual_work_link", "--steps")
    assert text.code == 0
    assert "Free-body equations" in text.out and "about G: L**2*m*theta_ddot/12" in text.out
    assert "F: F . dr/dtheta = F*L*cos(theta)" in text.out
    plain = json.loads(cli("crosscheck", "cart_pendulum", "--json").out)
    document = json.loads(cli("crosscheck", "cart_pendulum", "--json", "--steps").out)
    assert {k: v for k, v in document.items() if k != "steps"} == plain
    assert document["steps"]["projections"]["x"]["work"] == {"push": "F"}
    bad = cli("crosscheck", "pendulum", "--steps")  # T given as an expression: no free body
    assert bad.code == 2 and bad.err.startswith("error:") and "Traceback" not in bad.err
