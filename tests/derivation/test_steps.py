"""derive --steps: every printed step read back and compared with sympy's own differentiation of
the printed L (not with the project's derivation), and the equation with derive's M and f."""

from __future__ import annotations

import json
import random

import pytest
import sympy as sp

import lagrangian
from lagrangian.derivation.equations import derivation_steps
from lagrangian.model.expressions import parse_expression
from lagrangian.output.steps import steps_document

MODELS = ["pendulum", "virtual_work_link", "double_pendulum", "cart_pendulum",
          "cartesian_pendulum", "damped_oscillator", "support_pendulum", "bead_on_hoop",
          "slider_crank", "two_mass"]


def _names(model, document) -> dict[str, sp.Symbol]:
    """Every name a printed step may use: parameters, q, q_dot, q_ddot, t, lambda, delta q."""
    names = {p.name: p.symbol for p in model.parameters}
    for c in model.coordinates:
        names.update({c.name: c.symbol, str(c.velocity): c.velocity,
                      str(c.acceleration): c.acceleration})
    names[str(model.time)] = model.time
    for k in document.get("constraints", []):
        names[k["multiplier"]] = sp.Symbol(k["multiplier"])
    names.update({v: sp.Symbol(v) for v in document["variations"].values()})
    return names


def _same(a: sp.Expr, b: sp.Expr, symbols, trials: int = 5) -> bool:
    """a == b at random real values of every symbol (sympy's evalf, 30 digits)."""
    rng = random.Random(7)
    free = sorted((a - b).free_symbols | set(symbols), key=str)
    for _ in range(trials):
        values = {s: sp.Float(rng.uniform(0.3, 1.4), 30) for s in free}
        x, y = complex(a.evalf(30, subs=values)), complex(b.evalf(30, subs=values))
        if abs(x - y) > 1e-12 * max(1.0, abs(x), abs(y)):
            return False
    return True


def _time_derivative(expr: sp.Expr, model) -> sp.Expr:
    """sympy's d/dt with q -> q(t): the chain rule done by sympy, not by the project."""
    t = model.time
    functions = {c.symbol: sp.Function(c.name)(t) for c in model.coordinates}
    moving = expr.xreplace(functions)
    moving = moving.xreplace({c.velocity: functions[c.symbol].diff(t) for c in model.coordinates})
    rate = moving.diff(t)
    for c in model.coordinates:
        rate = rate.subs(functions[c.symbol].diff(t, 2), c.acceleration)
        rate = rate.subs(functions[c.symbol].diff(t), c.velocity)
    return rate.xreplace({f: s for s, f in functions.items()})


@pytest.mark.parametrize("name", MODELS)
def test_each_printed_step_is_sympys_derivative_of_the_printed_L(name):
    system = lagrangian.load(name)
    model, eom = system.model, system.equations_of_motion()
    document = steps_document(derivation_steps(eom))
    names = _names(model, document)

    def read(text: str) -> sp.Expr:
        return parse_expression(text, names)

    L = read(document["lagrangian"])
    symbols = list(names.values())
    # the printed L is derive's T - V
    assert _same(L, eom.kinetic_energy - eom.potential_energy, symbols)
    constraints = document.get("constraints", [])
    for i, c in enumerate(model.coordinates):
        step = {key: read(value) for key, value in document["coordinates"][c.name].items()}
        momentum = L.diff(c.velocity)
        assert _same(step["dL_dq_dot"], momentum, symbols), c.name
        assert _same(step["d_dt_dL_dq_dot"], _time_derivative(momentum, model), symbols), c.name
        assert _same(step["dL_dq"], L.diff(c.symbol), symbols), c.name
        multiplier_terms = sp.Add(*(read(k["jacobian"][i]) * sp.Symbol(k["multiplier"])
                                    for k in constraints))
        assert _same(step["multiplier_terms"], multiplier_terms, symbols)
        lagrange = (_time_derivative(momentum, model) - L.diff(c.symbol) - step["Q"]
                    + multiplier_terms)
        assert _same(step["equation"], lagrange, symbols), c.name
        # and that is derive's own equation M q_ddot + Phi_q^T lambda - f
        assert _same(step["equation"], eom.equations[i], symbols), c.name
    for k, constraint in zip(constraints, model.constraints, strict=True):
        if constraint.kind == "holonomic":
            phi = read(k["expression"])
            for c, entry in zip(model.coordinates, k["jacobian"], strict=True):
                assert _same(read(entry), phi.diff(c.symbol), symbols)


@pytest.mark.parametrize("name", ["virtual_work_link", "cart_pendulum", "damped_oscillator",
                                  "ladder_vertical_force"])
def test_each_load_moves_by_dr_dq_delta_q_and_does_F_dot_delta_r(name):
    system = lagrangian.load(name)
    model, eom = system.model, system.equations_of_motion()
    document = steps_document(derivation_steps(eom))
    names = _names(model, document)
    symbols = list(names.values())
    deltas = [sp.Symbol(document["variations"][c.name]) for c in model.coordinates]
    assert document["loads"], name
    for entry, load in ((e, next((x for x in model.loads if x.name == e["load"]), None))
                        for e in document["loads"]):
        work = parse_expression(entry["virtual_work"], names)
        shares = sum((parse_expression(entry["Q"].get(c.name, "0"), names) * d
                      for c, d in zip(model.coordinates, deltas, strict=True)), sp.S.Zero)
        assert _same(work, shares, symbols)
        if entry["kind"] == "force":
            moved = [parse_expression(v, names) for v in entry["virtual_displacement"]]
            expected = [sum((r.diff(c.symbol) * d for c, d in zip(model.coordinates, deltas,
                                                                  strict=True)), sp.S.Zero)
                        for r in load.point]
            for got, want in zip(moved, expected, strict=False):
                assert _same(got, want, symbols)
            force_work = sum((f * w for f, w in zip(load.force, expected, strict=True)),
                             sp.S.Zero)
            assert _same(work, force_work, symbols)


def test_worked_example_2_steps_in_numbers():
    # the seed's worked example 2: a horizontal F at the tip of a link of length L,
    # r = (L sin(theta), -L cos(theta)): delta r = (L cos, L sin) delta theta, Q = F L cos(theta)
    steps = lagrangian.load("virtual_work_link").steps()
    theta, F, L = (lagrangian.load("virtual_work_link").symbol(n) for n in ("theta", "F", "L"))
    (load,) = steps.loads
    delta = steps.variations[0]
    assert sp.simplify(load.displacement[0] - L * sp.cos(theta) * delta) == 0
    assert sp.simplify(load.virtual_work - F * L * sp.cos(theta) * delta) == 0
    Q = load.virtual_work.diff(delta).subs({F: 100, L: sp.Rational(1, 2), theta: sp.pi / 6})
    assert float(Q) == pytest.approx(43.3, abs=0.05)


def test_pendulum_momentum_is_m_L2_theta_dot():
    system = lagrangian.load("pendulum")
    step = system.steps().coordinate("theta")
    m, L, g, theta = (system.symbol(n) for n in ("m", "L", "g", "theta"))
    assert sp.expand(step.momentum - m * L**2 * system.symbol("theta_dot")) == 0
    assert sp.expand(step.force_gradient + m * g * L * sp.sin(theta)) == 0
    assert step.generalized_force == 0
    with pytest.raises(KeyError):
        system.steps().coordinate("phi")


def test_steps_display_themselves():
    steps = lagrangian.load("cartesian_pendulum").steps()
    assert isinstance(steps, lagrangian.DerivationSteps)
    latex = steps._repr_latex_()
    assert latex.startswith("$") and r"\frac{\partial \mathcal{L}}" in latex
    assert "x" in repr(steps) and "DerivationSteps" in repr(steps)
    with pytest.raises(AttributeError):
        steps.lagrangian = 0  # frozen


def test_derive_steps_text_latex_and_json(cli):
    text = cli("derive", "virtual_work_link", "--steps")
    assert text.code == 0
    assert "Equations of motion" in text.out  # derive's own output is kept
    assert "d(T - V)/dtheta_dot = L**2*m*theta_dot/3" in text.out
    assert "delta W = F . delta r = F*L*delta_theta*cos(theta)" in text.out
    latex = cli("derive", "cartesian_pendulum", "--steps", "--format", "latex")
    assert latex.code == 0 and latex.out.count(r"\begin{align}") == 2
    assert r"(\Phi_q^T \lambda)_{x}" in latex.out
    plain = json.loads(cli("derive", "pendulum", "--json").out)
    document = json.loads(cli("derive", "pendulum", "--json", "--steps").out)
    assert "steps" not in plain
    assert {k: v for k, v in document.items() if k != "steps"} == plain  # keys kept
    assert document["steps"]["coordinates"]["theta"]["dL_dq"] == "-L*g*m*sin(theta)"


def test_derive_steps_bad_input(cli):
    result = cli("derive", "no_such_model", "--steps")
    assert result.code == 2 and result.err.startswith("error:")
    both = cli("derive", "pendulum", "--steps", "--json", "--format", "latex")
    assert both.code == 2 and "--format" in both.err


def test_the_printed_text_reads_back_to_sympys_derivatives(cli):
    # the terminal text itself, line by line: L, then dL/dq_dot, d/dt(dL/dq_dot) and dL/dq
    system = lagrangian.load("cart_pendulum")
    model = system.model
    out = cli("derive", "cart_pendulum", "--steps").out
    steps = out[out.index("Steps (Lagrange"):]
    names = _names(model, {"variations": {c.name: f"delta_{c.name}" for c in model.coordinates}})
    symbols = list(names.values())

    def value(prefix: str) -> sp.Expr:
        line = next(line for line in steps.splitlines() if line.strip().startswith(prefix))
        return parse_expression(line.split(" = ", 1)[1], names)

    L = parse_expression(next(line for line in steps.splitlines()
                              if line.strip().startswith("L = T - V = ")).split(" = ")[-1], names)
    for c in model.coordinates:
        momentum = L.diff(c.velocity)
        assert _same(value(f"dL/d{c.velocity} = "), momentum, symbols)
        assert _same(value(f"d/dt(dL/d{c.velocity}) = "), _time_derivative(momentum, model),
                     symbols)
        assert _same(value(f"dL/d{c.name} = "), L.diff(c.symbol), symbols)
