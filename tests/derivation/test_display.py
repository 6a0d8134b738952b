"""Jupyter shows a model's rates with dots (issue 22): every matrix and every single expression
of the public results (the equations, one equation, T, V, L, the Jacobi integral, each step of
derive --steps) renders theta_dot as a dot over theta, never as theta_{dot}; the displayed
expressions are equal to, hash and sort as the plain sympy ones."""

from __future__ import annotations

import pickle
import re

import pytest
import sympy as sp

import lagrangian

UNDOTTED = re.compile(r"_\{d+ot\}|\\text\{[^}]*dot|Derivative|operatorname\{d+ot")


def shows_dots(obj) -> str:
    latex = obj._repr_latex_()
    assert not UNDOTTED.search(latex), latex
    return latex


@pytest.fixture(scope="module")
def cart():
    return lagrangian.load("cart_pendulum")


def test_every_scalar_and_matrix_of_the_equations_shows_dots(cart):
    eom = cart.equations_of_motion()
    for name in ("kinetic_energy", "lagrangian", "jacobi_integral", "invariant", "power"):
        latex = shows_dots(getattr(eom, name))
        assert r"\dot{\theta}" in latex or name == "power", name
    for name in ("mass_matrix", "forcing", "equations", "velocities", "acceleration_symbols",
                 "accelerations"):
        shows_dots(getattr(eom, name))
    # one equation, one entry: M q_ddot = f row by row, with the accelerations dotted twice
    assert r"\ddot{\theta}" in shows_dots(eom.equations[1])
    assert r"\dot{\theta}" in shows_dots(eom.forcing[0])
    assert r"\dot{\theta}" in shows_dots(eom.velocities)


def test_every_step_shows_dots(cart):
    steps = cart.steps()
    shows_dots(steps)
    theta = steps.coordinate("theta")
    for name in ("momentum", "momentum_rate", "equation"):
        shows_dots(getattr(theta, name))
    assert r"\dot{\theta}" in shows_dots(theta.momentum)
    assert r"\ddot{\theta}" in shows_dots(theta.momentum_rate)
    for load in steps.loads:
        shows_dots(load.virtual_work)


def test_the_reports_show_dots():
    damped = lagrangian.load("damped_oscillator")
    shows_dots(damped)
    shows_dots(damped.equations_of_motion())
    shows_dots(damped.crosscheck_steps())
    for reaction in lagrangian.load("cartesian_pendulum").crosscheck().reactions:
        shows_dots(reaction)
    shows_dots(damped.modes())
    shows_dots(damped.generalized_forces_at({"x": 0.1, "x_dot": 0.2}))
    link = lagrangian.load("virtual_work_link")
    shows_dots(link.statics({"theta": 0.5}, "F", {"m": 0.0}))


def test_a_displayed_expression_is_the_plain_one(cart):
    eom = cart.equations_of_motion()
    T = eom.kinetic_energy
    plain = sp.Add(*T.args)
    assert type(plain) is sp.Add and type(T) is not sp.Add
    assert T == plain and plain == T and hash(T) == hash(plain) and not T != plain
    assert sp.srepr(T) == sp.srepr(plain) and str(T) == str(plain)
    assert sp.expand(eom.lagrangian - (T - eom.potential_energy)) == 0
    assert {plain: 1}[T] == 1 and pickle.loads(pickle.dumps(T)) == plain
    # sympy's canonical order reads class names: a sum holding either orders them alike
    x = cart.symbol("x")
    assert sp.Add(eom.equations[1], x).args == sp.Add(sp.Add(*eom.equations[1].args), x).args
    assert sp.latex(T + 1) == sp.latex(plain + 1)  # arithmetic gives the plain expression
