"""C source for a model's numeric functions: M, f, Phi_q, gamma, energy and residuals.

Generated once from the symbolic equations with common-subexpression elimination; parameters
stay runtime inputs (an array ``p``), so one compiled module serves every parameter value.
The linear solve of M q_ddot = f (or the KKT system) and a DOP853 integrator are C code in
``template.c``, appended after the generated functions (see ``compiled.py``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import sympy as sp
from sympy.codegen.rewriting import create_expand_pow_optimization, optimize
from sympy.printing.c import C99CodePrinter

from ..derivation.equations import EquationsOfMotion

TEMPLATE = Path(__file__).with_name("template.c")

# x**2 .. x**4 as products: pow() is a library call at -O2 without fast-math.
_EXPAND_POW = create_expand_pow_optimization(4)


class CodegenError(Exception):
    """The equations use a function the C printer cannot express (the numpy backend can)."""


@dataclass(frozen=True)
class GeneratedSource:
    """The C source of one model's numeric functions, and the names of its runtime parameters."""

    source: str
    parameters: tuple[str, ...]
    n: int
    m: int


class _Printer(C99CodePrinter):
    """C99 with exact doubles (repr round-trips) and a record of unsupported functions."""

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Rational(self, expr):
        return f"({float(expr.p)!r}/{float(expr.q)!r})"

    def _print_Integer(self, expr):
        return f"{float(expr)!r}"

    def _print_sign(self, expr):  # sympy's sign(0) = 0, as numpy's
        x = self._print(expr.args[0])
        return f"((double)(({x}) > 0) - (double)(({x}) < 0))"

    def _print_Heaviside(self, expr):  # H(0) = 1/2, sympy's default
        x = self._print(expr.args[0])
        return f"(({x}) > 0 ? 1.0 : (({x}) < 0 ? 0.0 : 0.5))"


def _is_angle_pair(e) -> bool:
    return isinstance(e, (sp.sin, sp.cos)) and isinstance(e.args[0], sp.Add) and len(e.args[0].args) == 2


def _split_angle_pair(e):
    a, b = e.args[0].args
    if isinstance(e, sp.sin):
        return sp.sin(a) * sp.cos(b) + sp.cos(a) * sp.sin(b)
    return sp.cos(a) * sp.cos(b) - sp.sin(a) * sp.sin(b)


def _nodes(exprs) -> set:
    """Every distinct sub-expression, each visited once (sympy's own walks visit a shared
    sub-expression once per occurrence: exponential in the depth of nested rotations)."""
    seen: set = set()
    stack = list(exprs)
    while stack:
        e = stack.pop()
        if e not in seen:
            seen.add(e)
            stack.extend(e.args)
    return seen


def _trig_calls(exprs) -> int:
    return sum(1 for e in _nodes(exprs) if isinstance(e, (sp.sin, sp.cos)))


def _fewer_trig_calls(exprs: list[sp.Expr]) -> list[sp.Expr]:
    """sin/cos(a ± b) by the addition theorems where that leaves fewer distinct trig calls.

    A chain with absolute angles has cos(q_i - q_j) for every pair: n^2 calls become 2n.
    """
    if not any(_is_angle_pair(e) for e in _nodes(exprs)):
        return exprs
    split = [e.replace(_is_angle_pair, _split_angle_pair) for e in exprs]
    return split if _trig_calls(split) < _trig_calls(exprs) else exprs


def _renamed(exprs, rename: dict) -> list:
    """xreplace with each distinct sub-expression rebuilt once."""
    memo: dict = dict(rename)

    def walk(e):
        found = memo.get(e)
        if found is None:
            if e.args:
                args = [walk(a) for a in e.args]
                found = e.func(*args) if any(a is not b for a, b in zip(args, e.args, strict=True)) else e
            else:
                found = e
            memo[e] = found
        return found

    return [walk(e) for e in exprs]


# cse's "basic" preprocessing (factor_terms) walks every expression as a tree, without sharing:
# on the nested rotation products of a chain of 3D bodies (a few thousand distinct
# sub-expressions, ~1e5 tree nodes) it takes a minute and saves ~4% of the operations. It runs
# on small expressions that are not deeply nested (tree no bigger than a few times the DAG).
BASIC_CSE_MAX_NODES = 5000
BASIC_CSE_MAX_NESTING = 4


def _tree_nodes(exprs: Sequence[sp.Expr]) -> int:
    """The number of nodes of the expressions written out as trees (counted on the DAG)."""
    memo: dict = {}

    def size(e) -> int:
        found = memo.get(e)
        if found is None:
            found = memo[e] = 1 + sum(size(a) for a in e.args)
        return found

    return sum(size(e) for e in exprs)


def _basic_cse_pays(exprs: Sequence[sp.Expr]) -> bool:
    tree = _tree_nodes(exprs)
    return tree <= BASIC_CSE_MAX_NODES and tree <= BASIC_CSE_MAX_NESTING * len(_nodes(exprs))


def _block(exprs: Sequence[sp.Expr], targets: Sequence[str], printer: _Printer) -> str:
    """C statements computing ``targets[i] = exprs[i]`` with shared subexpressions hoisted."""
    exprs = _fewer_trig_calls([sp.sympify(e) for e in exprs])  # safe: already sympy objects
    optimizations = "basic" if _basic_cse_pays(exprs) else None
    replacements, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("c_"),
                                   optimizations=optimizations)
    statements = [(f"const double {symbol}", value) for symbol, value in replacements]
    statements += list(zip(targets, reduced, strict=True))
    lines = []
    for target, value in statements:
        try:
            code = printer.doprint(optimize(value, [_EXPAND_POW]))
        except (NotImplementedError, TypeError, ValueError) as exc:
            raise CodegenError(str(exc).splitlines()[0]) from None
        lines.append(f"    {target} = {code};")
    return "\n".join(lines)


def generate(eom: EquationsOfMotion) -> GeneratedSource:
    """The C functions lg_parts, lg_energy and lg_residual for these equations."""
    model = eom.model
    n, m = len(model.q), len(model.constraints)
    parameters = tuple(p.name for p in model.parameters)
    # Rename every symbol to a C identifier nobody's model can clash with.
    rename: dict[sp.Symbol, sp.Symbol] = {}
    for i, (q, v) in enumerate(zip(model.q, model.q_dot, strict=True)):
        rename[q] = sp.Symbol(f"q[{i}]")
        rename[v] = sp.Symbol(f"v[{i}]")
    for i, p in enumerate(model.parameters):
        rename[p.symbol] = sp.Symbol(f"p[{i}]")
    rename[model.time] = sp.Symbol("t")

    def c_exprs(exprs):
        out = []
        for e in exprs:
            e = sp.sympify(e)  # safe: sympy objects
            unknown = {x for x in _nodes([e]) if x.is_Symbol} - set(rename)
            if unknown:
                raise CodegenError(f"unknown symbols {sorted(map(str, unknown))} in the equations")
            out.append(e)
        return _renamed(out, rename)

    printer = _Printer()
    parts = c_exprs([*eom.mass_matrix, *eom.forcing, *eom.constraint_jacobian,
                     *eom.acceleration_rhs])
    targets = ([f"M[{i}]" for i in range(n * n)] + [f"f[{i}]" for i in range(n)]
               + [f"J[{i}]" for i in range(m * n)] + [f"g[{i}]" for i in range(m)])
    energy = c_exprs([eom.kinetic_energy + eom.potential_energy])
    residual = c_exprs([c.expression for c in model.constraints])
    signature = "(const double *restrict q, const double *restrict v, double t, " \
                "const double *restrict p"
    body = [
        f"/* lagrangian: generated C for model {model.name!r} ({n} coordinates, {m} constraints) */",
        f"#define LG_N {n}",
        f"#define LG_M {m}",
        f"#define LG_NP {len(parameters)}",
        "#define PY_SSIZE_T_CLEAN",
        "#include <Python.h>",  # before any standard header, as Python's docs require
        "#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION",
        "#include <numpy/arrayobject.h>",
        "#include <math.h>",
        "",
        f"static void lg_parts{signature}, double *restrict M, double *restrict f, "
        "double *restrict J, double *restrict g)",
        "{",
        "    (void)q; (void)v; (void)t; (void)p; (void)J; (void)g;",
        _block(parts, targets, printer),
        "}",
        "",
        f"static double lg_energy{signature})",
        "{",
        "    (void)q; (void)v; (void)t; (void)p;",
        "    double e;",
        _block(energy, ["e"], printer),
        "    return e;",
        "}",
        "",
        f"static void lg_residual{signature}, double *restrict r)",
        "{",
        "    (void)q; (void)v; (void)t; (void)p; (void)r;",
        _block(residual, [f"r[{i}]" for i in range(m)], printer) if m else "",
        "}",
        "",
    ]
    unsupported = printer._not_supported
    if unsupported:
        names = sorted({type(e).__name__ if not isinstance(e, sp.Basic) else str(e.func)
                        for e in unsupported})
        raise CodegenError(f"no C translation for {', '.join(names)}")
    source = "\n".join(body) + "\n" + TEMPLATE.read_text()
    return GeneratedSource(source=source, parameters=parameters, n=n, m=m)
