"""C source for a model's numeric functions: M, f, Phi_q, gamma, energy and residuals.

Generated once from the symbolic equations with common-subexpression elimination; parameters
stay runtime inputs (an array ``p``), so one compiled module serves every parameter value.
The linear solve of M q_ddot = f (or the KKT system) and a DOP853 integrator are C code in
``template.c``, appended after the generated functions (see ``compiled.py``).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import sympy as sp
from sympy.codegen.rewriting import create_expand_pow_optimization, optimize
from sympy.printing.c import C99CodePrinter

from ..derivation.equations import EquationsOfMotion
from .exact import distinct_nodes, machine_numbers

# the numerics appended after the generated functions: the solve and DOP853, the ensembles,
# then the Python bindings (one text: template_text)
TEMPLATES = tuple(Path(__file__).with_name(name) for name in
                  ("template.c", "template_ensemble.c", "template_bindings.c"))


def template_text() -> str:
    """The numerics template's C, its three parts in order."""
    return "\n".join(path.read_text(encoding="utf-8") for path in TEMPLATES)

# x**2 .. x**4 as products: pow() is a library call at -O2 without fast-math.
_EXPAND_POW = create_expand_pow_optimization(4)


# Characters that may carry a user's name into a C comment: none of them can open or close a
# comment, start a preprocessor line, continue a line (\\), form a trigraph (??) or leave ASCII.
_COMMENT_SAFE = re.compile(r"[^A-Za-z0-9 _.,:;+=()\[\]-]")


def c_table(name: str, ctype: str, rows) -> str:
    """A static const C array named ``name`` (ours, never the user's) of numbers, or of rows of
    numbers; doubles by repr, so exact."""
    rows = list(rows)
    number = (lambda x: repr(float(x))) if ctype == "double" else (lambda x: str(int(x)))
    nested = bool(rows) and isinstance(rows[0], (list, tuple))
    body = ", ".join("{" + ", ".join(map(number, row)) + "}" if nested else number(row)
                     for row in rows)
    width = f"[{len(rows[0])}]" if nested else ""
    return f"static const {ctype} {name}[{max(len(rows), 1)}]{width} = {{{body}}};"


def c_comment_text(text: object, limit: int = 60) -> str:
    """``text`` reduced to characters that are inert inside a C comment (others become '_',
    never '?', which could form a trigraph), at most ``limit`` characters: a name from a file
    never reaches C as code."""
    safe = _COMMENT_SAFE.sub("_", str(text))
    return safe if len(safe) <= limit else safe[:limit - 3] + "..."


class CodegenError(Exception):
    """The equations use a function the C printer cannot express (the numpy backend can)."""


@dataclass(frozen=True)
class GeneratedSource:
    """The C source of one model's numeric functions, and the names of its runtime parameters."""

    source: str
    parameters: tuple[str, ...]
    n: int
    m: int


class CPrinter(C99CodePrinter):
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


_nodes = distinct_nodes  # every distinct sub-expression, each once


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


def _statements(exprs: Sequence[sp.Expr], targets: Sequence[str], printer: CPrinter
                ) -> list[tuple[str | None, str, str, bool]]:
    """(name of a shared subexpression or None, target, C expression, constant?) computing
    ``targets[i] = exprs[i]`` with shared subexpressions hoisted."""
    # exact numbers as doubles before cse, which would split p/q into p and 1/q
    exprs = [machine_numbers(sp.sympify(e)) for e in exprs]  # safe: already sympy objects
    exprs = _fewer_trig_calls(exprs)
    optimizations = "basic" if _basic_cse_pays(exprs) else None
    replacements, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("c_"),
                                   optimizations=optimizations)
    statements = [(str(symbol), str(symbol), value) for symbol, value in replacements]
    statements += [(None, target, value) for target, value in zip(targets, reduced, strict=True)]
    out = []
    for shared, target, value in statements:
        try:
            code = printer.doprint(optimize(value, [_EXPAND_POW]))
        except (NotImplementedError, TypeError, ValueError) as exc:
            raise CodegenError(str(exc).splitlines()[0]) from None
        out.append((shared, target, code, not value.free_symbols))
    return out


def _lines(statements, kind: str = "double") -> str:
    return "\n".join(f"    {'const ' + kind + ' ' if shared else ''}{target} = {code};"
                      for shared, target, code, _ in statements)


def c_block(exprs: Sequence[sp.Expr], targets: Sequence[str], printer: CPrinter) -> str:
    """C statements computing ``targets[i] = exprs[i]`` with shared subexpressions hoisted."""
    return _lines(_statements(exprs, targets, printer))


# Functions with a vector version (vector_header): sin and cos by an inline polynomial kernel,
# the others lane by lane through libm.
_VECTOR_UNARY = {"sin", "cos", "tan", "asin", "acos", "atan", "exp", "log", "log10", "sinh",
                 "cosh", "tanh", "floor", "ceil", "sqrt", "exp2", "expm1", "log2", "log1p",
                 "cbrt", "fabs", "asinh", "acosh", "atanh", "erf", "erfc", "lgamma", "tgamma"}
_VECTOR_BINARY = {"pow", "atan2", "hypot", "fmax", "fmin"}
_CALL = re.compile(r"\b([A-Za-z_][A-Za-z0-9_]*)\s*\(")


def vector_statements(statements) -> str | None:
    """The same statements on LG_LANES members at once (every input a vector), or None when
    one uses something without a vector version (a conditional, an unlisted function)."""
    lines = []
    for shared, target, code, constant in statements:
        if any(c in code for c in "?<>=&|!"):
            return None  # Piecewise, sign, Heaviside: lane-wise selects not printed here
        if any(name not in _VECTOR_UNARY | _VECTOR_BINARY for name in _CALL.findall(code)):
            return None
        code = _CALL.sub(lambda m: f"lg_v_{m.group(1)}(", code)
        if constant:
            code = f"LG_VD({code})"
        lines.append(f"    {'const lg_vd ' if shared else ''}{target} = {code};")
    return "\n".join(lines)


_SINCOS_KERNEL = r"""    /* n = x 2/pi rounded to an integer by adding 1.5 2^52 (low mantissa bits: n) */
    const TYPE shifted = x * 6.36619772367581382433e-01 + 6755399441055744.0;
    const TYPE n = shifted - 6755399441055744.0;
    const TYPE r = ((x - n * 1.57079632673412561417e+00) - n * 6.07710050630396597660e-11)
                   - n * 2.02226624871116645580e-21;
    const TYPE z = r * r;
    const TYPE s = r + r * z * (-1.66666666666666324348e-01 + z * (8.33333333332248946124e-03
        + z * (-1.98412698298579493134e-04 + z * (2.75573137070700676789e-06
        + z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)))));
    const TYPE c = 1.0 - 0.5 * z + z * z * (4.16666666666666019037e-02
        + z * (-1.38888888888741095749e-03 + z * (2.48015872894767294178e-05
        + z * (-2.75573143513906633035e-07 + z * (2.08757232129817482790e-09
        + z * -1.13596475577881948265e-11)))));
"""


def sincos_kernel(kind: str) -> str:
    """C statements for x of type ``kind`` (double or a vector of doubles): the quarter turns
    n = round(x 2/pi) (``shifted``, whose low mantissa bits are n) and fdlibm's kernels
    s = sin r, c = cos r of the remainder r = x - n pi/2 in [-pi/4, pi/4] (Cody-Waite, three
    parts): within an ulp or two of libm for |x| < 1e5. Shared by every generated module."""
    return _SINCOS_KERNEL.replace("TYPE", kind)


VECTOR_HEADER = r"""
/* Several ensemble members at once, each operation on all lanes: four with AVX (a native
 * build), else two (one SSE2 instruction). */
#define LG_VECTOR 1
#if defined(__AVX__)
#define LG_LANES 4
typedef double lg_vd __attribute__((vector_size(32)));
typedef long long lg_vi __attribute__((vector_size(32)));
static const lg_vd LG_VNEG0 = {-0.0, -0.0, -0.0, -0.0};
#else
#define LG_LANES 2
typedef double lg_vd __attribute__((vector_size(16)));
typedef long long lg_vi __attribute__((vector_size(16)));
static const lg_vd LG_VNEG0 = {-0.0, -0.0};
#endif
/* A number or a vector as a vector: x + (-0) is x for every x, -0 included. */
#define LG_VD(x) ((x) + LG_VNEG0)

static inline lg_vd lg_vsel(lg_vi mask, lg_vd a, lg_vd b)  /* mask ? a : b, lane by lane */
{
    return (lg_vd)(((lg_vi)a & mask) | ((lg_vi)b & ~mask));
}

static inline lg_vd lg_vabs(lg_vd x)  /* every bit but the sign */
{
    return (lg_vd)((lg_vi)x & ~(lg_vi)LG_VNEG0);
}

#define LG_VUNARY(name) \
    static inline lg_vd lg_v_##name(lg_vd x) \
    { lg_vd r; for (int l = 0; l < LG_LANES; l++) r[l] = name(x[l]); return r; }
#define LG_VBINARY(name) \
    static inline lg_vd lg_v2_##name(lg_vd x, lg_vd y) \
    { lg_vd r; for (int l = 0; l < LG_LANES; l++) r[l] = name(x[l], y[l]); return r; }
LG_VUNARY(tan) LG_VUNARY(asin) LG_VUNARY(acos) LG_VUNARY(atan) LG_VUNARY(exp) LG_VUNARY(log)
LG_VUNARY(log10) LG_VUNARY(sinh) LG_VUNARY(cosh) LG_VUNARY(tanh) LG_VUNARY(floor)
LG_VUNARY(ceil) LG_VUNARY(sqrt) LG_VUNARY(exp2) LG_VUNARY(expm1) LG_VUNARY(log2)
LG_VUNARY(log1p) LG_VUNARY(cbrt) LG_VUNARY(fabs) LG_VUNARY(asinh) LG_VUNARY(acosh)
LG_VUNARY(atanh) LG_VUNARY(erf) LG_VUNARY(erfc) LG_VUNARY(lgamma) LG_VUNARY(tgamma)
LG_VBINARY(pow) LG_VBINARY(atan2) LG_VBINARY(hypot) LG_VBINARY(fmax) LG_VBINARY(fmin)
#define lg_v_pow(x, y) lg_v2_pow(LG_VD(x), LG_VD(y))
#define lg_v_atan2(x, y) lg_v2_atan2(LG_VD(x), LG_VD(y))
#define lg_v_hypot(x, y) lg_v2_hypot(LG_VD(x), LG_VD(y))
#define lg_v_fmax(x, y) lg_v2_fmax(LG_VD(x), LG_VD(y))
#define lg_v_fmin(x, y) lg_v2_fmin(LG_VD(x), LG_VD(y))

#ifdef LG_LIBM_TRIG
LG_VUNARY(sin) LG_VUNARY(cos)
#else
/* sin and cos on all lanes: Cody-Waite reduction by pi/2 and fdlibm's kernels on
 * [-pi/4, pi/4] (within an ulp or so of libm); libm lane by lane beyond |x| = 1e5. */
static inline lg_vd lg_vturn(lg_vd x, int quarter)
{
    const lg_vi far = (lg_vabs(x) >= 1.0e5);  /* NaN: not far */
    long long any = 0;
    for (int l = 0; l < LG_LANES; l++) any |= far[l];
    if (any) {
        lg_vd big;
        for (int l = 0; l < LG_LANES; l++) big[l] = quarter ? cos(x[l]) : sin(x[l]);
        return big;
    }
""" + sincos_kernel("lg_vd") + r"""
    /* quadrant k = n (+1 for cosine): odd k takes the other kernel, k & 2 flips the sign */
    const lg_vi k = (lg_vi)shifted + quarter;
    const lg_vd v = lg_vsel((k & 1) != 0, c, s);
    return (lg_vd)((lg_vi)v ^ ((k & 2) << 62));
}
static inline lg_vd lg_v_sin(lg_vd x) { return lg_vturn(x, 0); }
static inline lg_vd lg_v_cos(lg_vd x) { return lg_vturn(x, 1); }
#endif
"""


def generate(eom: EquationsOfMotion, vector: bool = False) -> GeneratedSource:
    """The C functions lg_parts, lg_energy and lg_residual for these equations; with
    ``vector``, also lg_vparts on several members at once for the ensemble loop (where every
    function has a vector version and there are no constraints)."""
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

    printer = CPrinter()
    parts = c_exprs([*eom.mass_matrix, *eom.forcing, *eom.constraint_jacobian,
                     *eom.acceleration_rhs])
    targets = ([f"M[{i}]" for i in range(n * n)] + [f"f[{i}]" for i in range(n)]
               + [f"J[{i}]" for i in range(m * n)] + [f"g[{i}]" for i in range(m)])
    parts_statements = _statements(parts, targets, printer)
    # M and f on several ensemble members at once, where every function has a vector version
    # (no constraints: the ensembles' compiled loop integrates unconstrained models only)
    vector = vector_statements(parts_statements) if vector and m == 0 else None
    energy = c_exprs([eom.kinetic_energy + eom.potential_energy])
    residual = c_exprs([c.expression for c in model.constraints])
    signature = "(const double *restrict q, const double *restrict v, double t, " \
                "const double *restrict p"
    body = [
        f"/* lagrangian: generated C for model '{c_comment_text(model.name)}' ({n} coordinates, "
        f"{m} constraints) */",
        f"#define LG_N {n}",
        f"#define LG_M {m}",
        f"#define LG_NP {len(parameters)}",
        "#define PY_SSIZE_T_CLEAN",
        "#include <Python.h>",  # before any standard header, as Python's docs require
        "#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION",
        "#include <numpy/arrayobject.h>",
        "#include <math.h>",
        # No fused multiply-add contraction in the single-point module, whatever the compiler
        # allows. The ensembles' module (vector, built native) fuses them: 15 % faster, and
        # its members differ from single-point runs at the rounding level, as its polynomial
        # sin/cos already make them; with LG_LIBM_TRIG (libm trig, no fusing) each lane does
        # exactly the scalar loop's arithmetic, which the tests check bit for bit.
        *(["#ifdef LG_LIBM_TRIG"] if vector else []),
        "#pragma GCC optimize(\"fp-contract=off\")",
        "#pragma STDC FP_CONTRACT OFF",
        *(["#endif"] if vector else []),
        "",
        f"static void lg_parts{signature}, double *restrict M, double *restrict f, "
        "double *restrict J, double *restrict g)",
        "{",
        "    (void)q; (void)v; (void)t; (void)p; (void)J; (void)g;",
        _lines(parts_statements),
        "}",
        "",
        f"static double lg_energy{signature})",
        "{",
        "    (void)q; (void)v; (void)t; (void)p;",
        "    double e;",
        c_block(energy, ["e"], printer),
        "    return e;",
        "}",
        "",
        f"static void lg_residual{signature}, double *restrict r)",
        "{",
        "    (void)q; (void)v; (void)t; (void)p; (void)r;",
        c_block(residual, [f"r[{i}]" for i in range(m)], printer) if m else "",
        "}",
        "",
    ]
    if vector is not None:
        body += [VECTOR_HEADER,
                 "static void lg_vparts(const lg_vd *restrict q, const lg_vd *restrict v, "
                 "lg_vd t, const lg_vd *restrict p, lg_vd *restrict M, lg_vd *restrict f)",
                 "{",
                 "    (void)q; (void)v; (void)t; (void)p;",
                 vector,
                 "}",
                 ""]
    unsupported = printer._not_supported
    if unsupported:
        names = sorted({type(e).__name__ if not isinstance(e, sp.Basic) else str(e.func)
                        for e in unsupported})
        raise CodegenError(f"no C translation for {', '.join(names)}")
    source = "\n".join(body) + "\n" + template_text()
    return GeneratedSource(source=source, parameters=parameters, n=n, m=m)
