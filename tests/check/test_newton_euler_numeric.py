"""Newton-Euler formed with numbers (jets) for deep trees of bodies in space: the jets against
sympy's own derivatives, the numeric check against the symbolic one, wrong equations caught, and
a hanging chain's joint reactions against the weights they carry."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest
import sympy as sp
from test_newton_euler_3d import _loaded_arm

import lagrangian
from lagrangian.check import newton_euler_numeric as numeric
from lagrangian.check.jets import JetEvaluator, UnsupportedExpression
from lagrangian.check.newton_euler import crosscheck
from lagrangian.model.builder import ModelBuilder


def test_jets_are_the_time_derivatives_sympy_takes():
    t = sp.Symbol("t", real=True)
    x, y, z = sp.symbols("x y z")
    path = {x: 0.3 + 1.1 * t - 0.7 * t**2 / 2, y: 1.4 - 0.5 * t + 2.0 * t**2 / 2,
            z: -0.2 + 0.9 * t + 0.4 * t**2 / 2}
    expressions = [
        sp.sin(x) * sp.cos(y) ** 3 - sp.tan(x * y) / (1 + y**2),
        sp.exp(x - y) * sp.log(y) + sp.sqrt(y + x**2) - sp.atan(x / 3) * sp.Abs(z),
        sp.asin(x / 2) + sp.acos(z) - 1 / (x * y) ** 3 + sp.pi * x + sp.Rational(1, 3),
    ]
    jets = {s: np.array([[float(e.subs(t, 0))], [float(e.diff(t).subs(t, 0))],
                         [float(e.diff(t, 2).subs(t, 0)) / 2]]) for s, e in path.items()}
    evaluate = JetEvaluator(jets, 1)
    for expr in expressions:
        moving = expr.subs(path)
        jet = evaluate(expr)[:, 0]
        assert jet[0] == pytest.approx(float(moving.subs(t, 0)), rel=1e-13)
        assert jet[1] == pytest.approx(float(moving.diff(t).subs(t, 0)), rel=1e-12)
        assert 2 * jet[2] == pytest.approx(float(moving.diff(t, 2).subs(t, 0)), rel=1e-12)
    with pytest.raises(UnsupportedExpression):
        evaluate(sp.Function("h")(x))
    with pytest.raises(UnsupportedExpression):
        evaluate(x * sp.Symbol("unknown"))


@pytest.fixture
def always_numeric(monkeypatch):
    monkeypatch.setattr(numeric, "NUMERIC_ABOVE", 0)


@pytest.mark.parametrize("name", ["heavy_top", "torque_free_body"])
def test_numeric_and_symbolic_newton_euler_agree(name, monkeypatch):
    eom = lagrangian.load(name).equations_of_motion()
    symbolic = crosscheck(eom)
    monkeypatch.setattr(numeric, "NUMERIC_ABOVE", 0)
    formed = crosscheck(eom)
    assert symbolic.agree and formed.agree
    assert any("formed numerically" in note for note in formed.notes)
    assert all(c.newton_euler is None for c in formed.coordinates)
    for a, b in zip(symbolic.reactions, formed.reactions, strict=True):
        assert a.joint == b.joint and a.labels == b.labels
        scale = max(1.0, max(abs(x) for x in a.at_initial_state))
        assert np.allclose(a.at_initial_state, b.at_initial_state, rtol=0, atol=1e-10 * scale)


def test_every_kind_of_load_on_bodies_in_space_agrees_numerically(always_numeric):
    # moments in body and world axes, a force at a body point, a spring to the ground
    report = _loaded_arm().crosscheck()
    assert report.agree, report
    assert {r.joint for r in report.reactions} == {"upper", "lower"}


def test_a_wrong_equation_is_caught_numerically(always_numeric):
    top = lagrangian.load("heavy_top").equations_of_motion()
    g, A = sp.Symbol("g"), sp.Symbol("A")
    report = crosscheck(replace(top, forcing=top.forcing + sp.Matrix([0, g / 100, 0])))
    wrong = [c for c in report.coordinates if not c.agree]
    assert [c.coordinate for c in wrong] == ["theta"]
    assert "random state" in wrong[0].difference
    assert not crosscheck(replace(top, mass_matrix=top.mass_matrix + sp.diag(A, 0, 0))).agree
    # a forgotten generalized force: the weight dropped from Lagrange's side
    arm = _loaded_arm()
    eom = arm.equations_of_motion()
    weightless = lagrangian.System(replace(arm.model, gravity=None)).equations_of_motion()
    assert not crosscheck(replace(eom, forcing=weightless.forcing)).agree


def _hanging_chain(n: int, mass: float = 1.5, g: float = 9.81) -> lagrangian.System:
    b = ModelBuilder(f"{n}-body hanging chain")
    b.parameter("g", g)
    b.set_gravity("g", (0, 0, -1))
    parent = None
    for i in range(n):
        b.coordinate(f"q{i}", "rad")
        joint = {"type": "revolute", "axis": "xy"[i % 2], "angle": f"q{i}"}
        if parent:
            joint["at"] = [0, 0, -1]
        b.add_rigid_body(f"link{i}", mass, [0.1, 0.1, 0.02], parent=parent, joint=joint,
                         center=[0, 0, -0.5])
        parent = f"link{i}"
    return lagrangian.System(b.build_model())


def test_a_deep_hanging_chain_is_checked_numerically_and_each_joint_holds_what_hangs_below():
    n, mass, g = 9, 1.5, 9.81
    report = _hanging_chain(n, mass, g).crosscheck()
    assert n > numeric.NUMERIC_ABOVE and report.agree  # link k is k + 1 rotations deep
    assert any("formed numerically" in note for note in report.notes)
    for k, reaction in enumerate(report.reactions):
        values = dict(zip(reaction.labels, reaction.at_initial_state, strict=True))
        assert values["R_z"] == pytest.approx((n - k) * mass * g, rel=1e-12)
        for label in ("R_x", "R_y", "M_x", "M_y", "M_z"):
            assert values[label] == pytest.approx(0.0, abs=1e-9)


def _chain_file(tmp_path, n: int):
    lines = [f'name = "{n}-link chain"', "", "[coordinates]"]
    lines += [f'q{i} = {{ unit = "rad", initial = {0.2 if i == 0 else 0.0} }}' for i in range(n)]
    lines += ["", "[parameters]", 'g = { value = 9.81, unit = "m/s^2" }', "",
              "[gravity]", 'g = "g"', "direction = [0, 0, -1]", ""]
    for i in range(n):
        lines += ["[[bodies]]", f'name = "link{i}"', "mass = 2", "inertia = [0.1, 0.1, 0.02]",
                  "center = [0, 0, -0.5]"]
        if i:
            lines.append(f'parent = "link{i - 1}"')
        at = ", at = [0, 0, -1]" if i else ""
        lines += [f'joint = {{ type = "revolute", axis = "{"xy"[i % 2]}", angle = "q{i}"{at} }}',
                  ""]
    path = tmp_path / "chain.toml"
    path.write_text("\n".join(lines))
    return path


def test_the_command_line_prints_the_numbers_and_the_json_keeps_its_shape(cli, tmp_path):
    path = _chain_file(tmp_path, 8)
    code, out, _ = cli("crosscheck", str(path))
    assert code == 0 and "formed numerically" in out and out.rstrip().endswith("agree")
    assert "N at the initial state" in out
    code, out, _ = cli("crosscheck", str(path), "--json")
    document = json.loads(out)
    assert document["agree"] is True and len(document["coordinates"]) == 8
    root = document["reactions"][0]
    # the first link swings at 0.2 rad: its joint holds less than the whole weight vertically
    assert 0 < root["at_initial_state"]["force"]["z"] < 8 * 2 * 9.81
    assert math.isfinite(float(root["components"][2]))


def test_the_documented_deep_crosscheck_runs():
    import re

    from docs_blocks import block

    code = re.findall(r"```python\n(.*?)```", block("deep-crosscheck"), re.S)[0]
    scope: dict = {}
    exec(compile(code, "docs/readability.md", "exec"), scope)
    assert scope["report"].agree
    assert scope["top"].at_initial_state[2] == pytest.approx(12 * 2.0 * 9.81, rel=1e-12)


def test_the_working_of_a_deep_chain_is_refused_in_one_line(cli, tmp_path):
    path = _chain_file(tmp_path, 8)
    code, _, err = cli("crosscheck", str(path), "--steps")
    assert code == 2 and "with numbers instead" in err and len(err.strip().splitlines()) == 1
