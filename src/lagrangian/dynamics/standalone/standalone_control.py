"""A model file's [control] laws in its standalone C (codegen): u = law(t, q, q_dot) on each
input, and the generalized forces B u they add (to forward dynamics' tau), as two functions
beside the equations. Only identifiers we make reach the C: q[i], v[i], p[i], t and the
cse's c_<k>; the inputs' names appear in the header as inert comment text."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import sympy as sp

from ...compile.codegen import CodegenError, CPrinter, c_block, c_comment_text
from ...derivation.equations import EquationsOfMotion
from ...model.model import Model

# B's columns of the inputs named, from the derived equations: simulation.control's
# input_columns(eom, names, field=, source=), given by the caller (dynamics does not import
# simulation)
Columns = Callable[..., list[list[sp.Expr]]]


def renamed_for_c(exprs, rename: dict, fault: str) -> list[sp.Expr]:
    """The expressions (sympy's, never a user's text) in the C's own names (``rename``: q, v,
    t and the parameters as q[i], v[i], p[k] or numbers); a symbol outside it refused,
    ``fault`` naming what is wrong."""
    out = []
    for e in exprs:
        e = sp.sympify(e)  # safe: sympy objects
        unknown = e.free_symbols - set(rename)
        if unknown:
            raise CodegenError(f"{fault} {sorted(map(str, unknown))}")
        out.append(e.xreplace(rename))
    return out


def _columns(model: Model, names: Sequence[str],
             equations: Callable[[], EquationsOfMotion] | None,
             columns: Columns | None) -> list[list[sp.Expr]]:
    """B's columns, one per input: e_i for a coordinate; df/dp (from the derived equations)
    for a parameter or a load, as simulate(controller="model") closes them."""
    coordinates = [c.name for c in model.coordinates]
    if all(name in coordinates for name in names):
        return [[sp.S.One if i == coordinates.index(name) else sp.S.Zero
                 for i in range(len(coordinates))] for name in names]
    if equations is None or columns is None:
        raise CodegenError("the [control] table's laws on a parameter or a load need the "
                           "derived equations, which the recursive C of this model does not "
                           "have; write the laws on its coordinates")
    return columns(equations(), names, field="control", source=model.source)


def control_c(model: Model, P: str, parameters: Sequence[str], values: Mapping[str, float],
              equations: Callable[[], EquationsOfMotion] | None,
              columns: Columns | None = None) -> tuple[str, str]:
    """(header declarations, source definitions) of ``<P>_control`` (u, one per law, in the
    table's order) and ``<P>_control_forces`` (B u, one per velocity coordinate) of the
    model's [control] table. ``parameters``: the names in the C's p array (others are folded
    in as their values, as the recursive C folds a model file's masses in)."""
    names = [name for name, _ in model.control]
    laws = [law for _, law in model.control]
    by_input = _columns(model, names, equations, columns)
    n = len(model.q)
    forces = [sp.Add(*(column[i] * law for column, law in zip(by_input, laws, strict=True)))
              for i in range(n)]
    t = sp.Symbol("t")
    rename: dict[sp.Symbol, sp.Expr] = {model.time: t}
    for i, (q, v) in enumerate(zip(model.q, model.q_dot, strict=True)):
        rename[q], rename[v] = sp.Symbol(f"q[{i}]"), sp.Symbol(f"v[{i}]")
    slots = {name: i for i, name in enumerate(parameters)}
    for p in model.parameters:
        if p.name in slots:
            rename[p.symbol] = sp.Symbol(f"p[{slots[p.name]}]")
        elif values.get(p.name) is not None:
            rename[p.symbol] = sp.Float(float(values[p.name]))

    def c_exprs(exprs):
        return renamed_for_c(exprs, rename, "the [control] laws use unknown symbols")

    printer = CPrinter()
    law_code = c_block(c_exprs(laws), [f"u[{i}]" for i in range(len(laws))], printer)
    force_code = c_block(c_exprs(forces), [f"tau[{i}]" for i in range(n)], printer)
    if printer._not_supported:
        raise CodegenError("no C translation for some functions of the [control] laws")
    inputs = c_comment_text(", ".join(names), limit=2000)
    declarations = f"""
/* The model file's [control] laws (SI; t in s): u = law(t, q, q_dot), one per input, in this
   order: {inputs} (a coordinate's generalized force in N or N m, or a value added to a
   parameter or a load, in its unit). */
#define {P.upper()}_NU {len(laws)}
void {P}_control(double t, const double *q, const double *v, const double *p, double *u);
/* tau = B(q, q_dot) u: the laws' generalized forces, to pass as (or add to) forward dynamics'
   tau to close the loop as simulate --control model does. */
void {P}_control_forces(double t, const double *q, const double *v, const double *p,
                        double *tau);
"""
    definitions = f"""
void {P}_control(double t, const double *q, const double *v, const double *p, double *u)
{{
    (void)t; (void)q; (void)v; (void)p;
{law_code}
}}

void {P}_control_forces(double t, const double *q, const double *v, const double *p,
                        double *tau)
{{
    (void)t; (void)q; (void)v; (void)p;
{force_code}
}}
"""
    return declarations, definitions


def with_control(header: str, source: str, declarations: str, definitions: str
                 ) -> tuple[str, str]:
    """The header with the declarations inside its extern "C" block, the source with the
    definitions at its end."""
    end = header.rindex("\n#ifdef __cplusplus\n}")
    return header[:end] + declarations + header[end:], source.rstrip("\n") + "\n" + definitions


__all__ = ["Columns", "control_c", "renamed_for_c", "with_control"]
