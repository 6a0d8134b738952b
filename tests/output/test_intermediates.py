"""Large equations (a deep chain of bodies) printed through named intermediate quantities: each
printed intermediate and expression, read back by the model-file parser (never eval) with the
intermediates substituted in order, equals the derived expression at random points; the size by
a cheap proxy (characters); --expand writes the equations out as before."""

from __future__ import annotations

import json
import random
import sys
from pathlib import Path

import pytest
import sympy as sp

import lagrangian
from lagrangian.model.builder import ModelBuilder
from lagrangian.model.expressions import parse_expression
from lagrangian.output.derivation import derivation_document, derivation_latex, derivation_text

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import model_files  # noqa: E402


def chain(n: int, masses=None) -> lagrangian.System:
    """benchmarks/bench_spatial_chain.py's chain: n bodies on revolute joints about x, y, x, ..."""
    masses = masses or [f"m{i}" for i in range(n)]
    b = ModelBuilder(f"{n}-body spatial chain")
    b.parameter("g", 9.81)
    b.set_gravity("g", (0, 0, -1))
    parent = None
    for i in range(n):
        b.coordinate(f"q{i}", "rad")
        b.parameter(masses[i], 1.0 + 0.1 * i)
        joint = {"type": "revolute", "axis": "xy"[i % 2], "angle": f"q{i}"}
        if parent:
            joint["at"] = [0, 0, -1]
        b.add_rigid_body(f"link{i}", masses[i], [0.1, 0.1, 0.02], parent=parent, joint=joint,
                         center=[0, 0, -0.5])
        parent = f"link{i}"
    return lagrangian.System(b.build_model())


def model_names(eom) -> dict[str, sp.Symbol]:
    model = eom.model
    names = {p.name: p.symbol for p in model.parameters}
    for c in model.coordinates:
        names.update({c.name: c.symbol, c.velocity.name: c.velocity,
                      c.acceleration.name: c.acceleration})
    names["t"] = sp.Symbol("t")
    return names


def printed_pairs(eom, document):
    """(printed text, derived expression) for every expression of the document."""
    yield document["kinetic_energy"], eom.kinetic_energy
    yield document["potential_energy"], eom.potential_energy
    yield document["dissipation"], eom.dissipation
    yield document["lagrangian"], eom.lagrangian
    for i, name in enumerate(document["coordinates"]):
        yield document["generalized_forces"][name], eom.generalized_forces[i]
        yield document["forcing"][i], eom.forcing[i]
        yield document["equations"][name], eom.equations[i]
        for j in range(len(document["coordinates"])):
            yield document["mass_matrix"][i][j], eom.mass_matrix[i, j]


def evaluated(expr, values: dict, memo: dict):
    """expr at the 30-digit Floats ``values``, each shared node evaluated once (sympy's own
    arithmetic on Floats; the derived equations share their sub-expressions, so this is linear
    in the shared tree, where lambdify walked the tree written out: 30 s for ten bodies)."""
    found = memo.get(id(expr))
    if found is not None:
        return found[0]
    if expr in values:
        value = values[expr]
    elif not expr.args:
        value = expr.evalf(30)
    else:
        value = expr.func(*(evaluated(a, values, memo) for a in expr.args)).evalf(30)
    memo[id(expr)] = (value, expr)  # expr held, so that its id is not reused meanwhile
    return value


def assert_reads_back(eom, document, points: int = 2, seed: int = 1) -> int:
    """Every intermediate parsed in order and evaluated, then every printed expression: equal
    to the derived one (evaluated on its shared sub-expressions)."""
    names = model_names(eom)
    symbols = sorted(set(names.values()), key=str)
    pairs = list(printed_pairs(eom, document))
    read = []
    for item in document.get("intermediates", []):
        read.append((sp.Symbol(item["name"]), parse_expression(item["expression"], names)))
        names[item["name"]] = read[-1][0]
    printed = [parse_expression(text, names) for text, _ in pairs]
    rng = random.Random(seed)
    for _ in range(points):
        point = {s: sp.Float(rng.uniform(-1.5, 1.5), 30) for s in symbols}
        values = dict(point)
        for symbol, expr in read:
            values[symbol] = expr.xreplace(values).evalf(30)
        memo: dict = {}
        expected = [evaluated(sp.sympify(d), point, memo) for _, d in pairs]  # safe: derived
        for (text, _), mine, theirs in zip(pairs, printed, expected, strict=True):
            got = complex(mine.xreplace(values).evalf(30))
            theirs = complex(theirs)
            assert abs(got - theirs) <= 1e-9 * max(1.0, abs(theirs)), (text[:200], got, theirs)
    return len(read)


def test_a_deep_chain_prints_named_quantities_that_read_back():
    eom = chain(5).equations_of_motion()
    document = json.loads(json.dumps(derivation_document(eom)))
    named = [item["name"] for item in document["intermediates"]]
    assert {"R5_12", "omega5_x", "v5_x", "M_q0_q0", "f_q4"} <= set(named)
    assert document["equations"]["q0"].startswith("M_q0_q0*q0_ddot + M_q0_q1*q1_ddot")
    assert assert_reads_back(eom, document) == len(named)


def test_small_models_print_as_before():
    for name in ("double_pendulum", "heavy_top", "slider_crank"):
        eom = lagrangian.load(name).equations_of_motion()
        assert "intermediates" not in derivation_document(eom)
        assert derivation_text(eom) == derivation_text(eom, expand=True)


def test_names_the_model_uses_are_left_alone():
    # a mass named like an intermediate (R1_22) and like cse's names (s1): neither is defined
    eom = chain(5, masses=["s1", "R1_22", "m2", "m3", "m4"]).equations_of_motion()
    document = derivation_document(eom)
    named = [item["name"] for item in document["intermediates"]]
    assert "R1_22" not in named and "s1" not in named
    assert not any(n.startswith("s") and n[1:].isdigit() for n in named)  # another prefix
    assert_reads_back(eom, document, points=1)


def test_expand_writes_everything_out():
    eom = chain(5).equations_of_motion()
    document = derivation_document(eom, expand=True)
    assert "intermediates" not in document
    assert "R1_" not in json.dumps(document) and "M_q0" not in json.dumps(document)
    assert "Intermediate" not in derivation_text(eom, expand=True)
    assert "Intermediate quantities" in derivation_latex(eom)
    assert "Intermediate" not in derivation_latex(eom, expand=True)


def test_the_ten_body_chain_prints_in_under_100_kb():
    # the proxy of size and time: characters (46 MB and two minutes written out in full)
    eom = chain(10).equations_of_motion()
    text = derivation_text(eom)
    assert len(text) < 100_000
    assert "\n  R10_11 = " in text and "\n  omega10_x = " in text
    assert "[q9]  M_q0_q9*q0_ddot" in text


@pytest.mark.slow
def test_the_ten_body_chain_reads_back():
    eom = chain(10).equations_of_motion()
    assert_reads_back(eom, derivation_document(eom), points=1)


def test_derive_expand_flag(cli, tmp_path):
    path = tmp_path / "chain.toml"
    path.write_text(model_files.spatial_chain(5), encoding="utf-8")
    code, named, err = cli("derive", str(path))
    assert code == 0, err
    code, expanded, err = cli("derive", str(path), "--expand")
    assert code == 0, err
    assert "Intermediate quantities" in named and "Intermediate" not in expanded
    assert len(named) < 60_000 < 300_000 < len(expanded)
    code, out, err = cli("derive", str(path), "--json", "--expand")
    assert code == 0 and "intermediates" not in json.loads(out)


def test_the_documented_example():
    import re

    from docs_blocks import block

    code = re.findall(r"```python\n(.*?)```", block("deep-chain"), re.S)[0]
    scope: dict = {}
    exec(compile(code, "docs/readability.md", "exec"), scope)
    assert "Intermediate quantities" in scope["named"] and len(scope["named"]) < 60_000
    assert "Intermediate" not in scope["full"] and len(scope["full"]) > 300_000
