"""The working of `derive --steps`: text, LaTeX and the `steps` key of the JSON document.

Expressions are written in the model-file grammar (text, JSON; read back by
``parse_expression`` with the delta q symbols declared) or with the model's LaTeX names.
"""

from __future__ import annotations

from typing import Any

import sympy as sp

from ..derivation.readable import readable
from ..derivation.steps import DerivationSteps
from ..kinds import ConstraintKind, LoadStepKind
from ..model.expressions import format_expression, tree_size
from ..model.notation import latex_symbol_names

SMALL = 400  # nodes: a step this small has its common factors taken out before it is grouped
# nodes: a larger step (the Whipple bicycle's run to 48000; every other example's below 300) is
# no working to follow by hand: text and LaTeX give its size instead, unless full (--steps-full)
STEP_NODES = 1000


class _Form:
    """The readable form of a step (derivation/readable.py: equal, grouped by products of the
    rates and of the delta q)."""

    def __init__(self, steps: DerivationSteps, full: bool = True):
        model = steps.model
        self.full, self.summarized = full, 0
        self.rates = frozenset([*model.q_dot, *model.q_ddot, *steps.variations,
                                *(c.multiplier for c in steps.constraints)])
        self.ranges = {c.symbol: tuple(c.range) for c in model.coordinates if c.range}

    def __call__(self, expr) -> sp.Expr:
        expr = sp.sympify(expr)  # safe: a sympy object or a number
        if not expr.is_Atom and tree_size(expr, SMALL) <= SMALL:
            # -k*(2*x - 2*x0)/2, as d/dx of k*(x - x0)**2/2 comes out, reads -k*(x - x0)
            expr = sp.factor_terms(expr)
        return readable(expr, self.rates, self.ranges)

    def size(self, expr) -> str | None:
        """'412 terms, 38760 nodes' for a step too large to print (counted), else None."""
        expr = sp.sympify(expr)  # safe: a sympy object or a number
        if self.full or tree_size(expr, STEP_NODES) <= STEP_NODES:
            return None
        self.summarized += 1
        return f"{len(sp.Add.make_args(expr))} terms, {tree_size(expr)} nodes"

    def text(self, expr) -> str:
        size = self.size(expr)
        if size is not None:
            return f"<{size}: derive --steps-full prints it>"
        return format_expression(self(expr))


def _lagrangian_name(model) -> str:
    """"L", or words where the model has a symbol L (a pendulum's length), as derive does."""
    names = {p.name for p in model.parameters} | {c.name for c in model.coordinates}
    return "L" if "L" not in names else "(T - V)" if not names & {"T", "V"} else "(Lagrangian)"


def _force_name(model) -> str:
    names = {p.name for p in model.parameters} | {c.name for c in model.coordinates}
    return "Q" if "Q" not in names else "(generalized force)"


# -- text ---------------------------------------------------------------------------------------


def steps_text(steps: DerivationSteps, *, full: bool = False) -> str:
    """The working as text: L, each coordinate's derivatives, each load's virtual work; a step
    over STEP_NODES nodes as its size, unless ``full``."""
    model, form = steps.model, _Form(steps, full)
    lag, force = _lagrangian_name(model), _force_name(model)
    label = {"L": "L = T - V", "(T - V)": "T - V"}.get(lag, "Lagrangian T - V")
    lines = ["Steps (Lagrange's method, each derived from L = T - V):",
             f"  {label} = {form.text(steps.lagrangian)}", ""]
    for c, s in zip(model.coordinates, steps.coordinates, strict=True):
        lines.append(f"  [{c.name}]")
        lines.append(f"    d{lag}/d{c.velocity} = {form.text(s.momentum)}")
        lines.append(f"    d/dt(d{lag}/d{c.velocity}) = {form.text(s.momentum_rate)}")
        lines.append(f"    d{lag}/d{c.name} = {form.text(s.force_gradient)}")
        lines.append(f"    {force}[{c.name}] = {form.text(s.generalized_force)}")
        multipliers = ""
        if steps.constraints:
            lines.append(f"    (Phi_q^T lambda)[{c.name}] = {form.text(s.multiplier_terms)}")
            multipliers = " + (Phi_q^T lambda)"
        lines.append(f"    d/dt(d{lag}/d{c.velocity}) - d{lag}/d{c.name} - {force}[{c.name}]"
                     f"{multipliers} = 0:")
        lines.append(f"      {form.text(s.equation)} = 0")
    if steps.loads:
        variations = ", ".join(str(v) for v in steps.variations)
        lines += ["", f"  Virtual work of the loads (virtual displacements {variations}):"]
        for load in steps.loads:
            lines += _load_lines(load, form, model, force)
    if steps.constraints:
        lines += ["", "  Constraints (one multiplier each, Phi_q^T lambda in each equation):"]
        for k in steps.constraints:
            written = "Phi" if k.kind == ConstraintKind.HOLONOMIC else "A q_dot + b"
            row = ", ".join(form.text(v) for v in k.jacobian)
            lines.append(f"    {k.constraint} ({k.kind}): {written} = "
                         f"{form.text(k.expression)} = 0")
            lines.append(f"      Phi_q row = [{row}]   multiplier {k.multiplier}")
    if form.summarized:
        lines.insert(1, f"  ({form.summarized} steps over {STEP_NODES} nodes are given by their "
                        "size; derive --steps-full prints every step)")
    return "\n".join(lines) + "\n"


def _load_lines(load, form: _Form, model, force: str) -> list[str]:
    lines = LOAD_TEXT[load.kind](load, form)
    lines += [f"      {force}[{name}] from {load.load} = {form.text(value)}"
              for name, value in load.shares]
    return lines


def _force_text(load, form: _Form) -> list[str]:
    point = ", ".join(form.text(r) for r in _planar(load.acts_at))
    moved = ", ".join(form.text(r) for r in _planar(load.displacement))
    return [f"    {load.load} (force at r = ({point})):",
            f"      delta r = sum_i dr/dq_i delta q_i = ({moved})",
            f"      delta W = F . delta r = {form.text(load.work_form)}" + _same(load, form)]


def _torque_text(load, form: _Form) -> list[str]:
    return [f"    {load.load} (torque through the angle {form.text(load.acts_at[0])}):",
            f"      delta(angle) = {form.text(load.displacement[0])}",
            f"      delta W = tau delta(angle) = {form.text(load.work_form)}" + _same(load, form)]


def _moment_text(load, form: _Form) -> list[str]:
    turned = ", ".join(form.text(v) for v in load.displacement)
    return [f"    {load.load} (moment on a body in space):",
            f"      delta phi = sum_i d omega/d q_dot_i delta q_i = ({turned})",
            f"      delta W = M . delta phi = {form.text(load.work_form)}" + _same(load, form)]


def _damper_text(load, form: _Form) -> list[str]:
    return [f"    {load.load} (damper, rate of its length {form.text(load.acts_at[0])}):",
            f"      delta(length) = {form.text(load.displacement[0])}",
            f"      delta W = -c (rate) delta(length) = {form.text(load.work_form)}"
            + _same(load, form)]


def _summed_text(what: str):
    """A load with no displacement of its own: delta W as the sum of its Q_i delta q_i."""
    def lines(load, form: _Form) -> list[str]:
        return [f"    {load.load} ({what}):", f"      delta W = {form.text(load.virtual_work)}"]
    return lines


# one entry per kind of load step (tests/model/test_component_tables.py walks every kind)
LOAD_TEXT = {
    LoadStepKind.FORCE: _force_text,
    LoadStepKind.TORQUE: _torque_text,
    LoadStepKind.MOMENT: _moment_text,
    LoadStepKind.DAMPER: _damper_text,
    LoadStepKind.DISSIPATION: _summed_text("the dissipation function: Q_i = -dD/dq_dot_i"),
    LoadStepKind.GIVEN: _summed_text("given as generalized forces"),
}


def _same(load, form: _Form) -> str:
    """' = sum_i Q_i delta q_i' where that reads differently from the load's own form."""
    written, summed = form.text(load.work_form), form.text(load.virtual_work)
    return "" if written == summed else f" = {summed}"


def _planar(vector) -> tuple:
    """(x, y) when every z is 0, else (x, y, z)."""
    return tuple(vector[:2]) if len(vector) == 3 and vector[2] == 0 else tuple(vector)


# -- JSON ---------------------------------------------------------------------------------------


def steps_document(steps: DerivationSteps) -> dict[str, Any]:
    """The `steps` key of `derive --steps --json`: every expression in the model grammar."""
    form = _Form(steps)
    text = form.text
    return {
        "lagrangian": text(steps.lagrangian),
        "variations": {c.name: str(v) for c, v in zip(steps.model.coordinates, steps.variations,
                                                       strict=True)},
        "coordinates": {
            s.coordinate: {"dL_dq_dot": text(s.momentum), "d_dt_dL_dq_dot": text(s.momentum_rate),
                           "dL_dq": text(s.force_gradient), "Q": text(s.generalized_force),
                           "multiplier_terms": text(s.multiplier_terms),
                           "equation": text(s.equation)}
            for s in steps.coordinates},
        "loads": [
            {"load": load.load, "kind": load.kind,
             "acts_at": [text(v) for v in load.acts_at],
             "virtual_displacement": [text(v) for v in load.displacement],
             "work_form": None if load.work_form is None else text(load.work_form),
             "virtual_work": text(load.virtual_work),
             "Q": {name: text(value) for name, value in load.shares}}
            for load in steps.loads],
        "constraints": [
            {"constraint": k.constraint, "kind": k.kind, "expression": text(k.expression),
             "jacobian": [text(v) for v in k.jacobian], "multiplier": str(k.multiplier)}
            for k in steps.constraints],
    }


# -- LaTeX --------------------------------------------------------------------------------------


def steps_latex(steps: DerivationSteps, *, full: bool = False) -> str:
    """The working as an amsmath align block, to follow `derive --format latex`; a step over
    STEP_NODES nodes as its size, unless ``full``."""
    model, form = steps.model, _Form(steps, full)
    symbol_names = latex_symbol_names(model)
    symbol_names.update({v: rf"\delta {sp.latex(c.symbol)}"
                         for c, v in zip(model.coordinates, steps.variations, strict=True)})

    def printer(expr) -> str:
        return sp.latex(expr, symbol_names=symbol_names)

    names = {p.name for p in model.parameters} | {c.name for c in model.coordinates}
    L = r"\mathcal{L}" if "L" in names else "L"
    Q = r"\mathcal{Q}" if "Q" in names else "Q"
    def tex(expr) -> str:
        entries = list(expr) if isinstance(expr, sp.MatrixBase) else [expr]
        sizes = [size for size in map(form.size, entries) if size is not None]
        if sizes:
            return rf"\text{{({'; '.join(sizes)}: derive --steps-full prints it)}}"
        if isinstance(expr, sp.MatrixBase):
            return printer(sp.ImmutableMatrix(expr.rows, expr.cols, [form(e) for e in expr]))
        return printer(form(expr))

    lines = [f"% {model.name}: the steps of Lagrange's method", r"\begin{align}",
             rf"{L} &= T - V = {tex(steps.lagrangian)} \\"]
    for c, s in zip(model.coordinates, steps.coordinates, strict=True):
        q, v = printer(c.symbol), printer(c.velocity)
        lines += [rf"\frac{{\partial {L}}}{{\partial {v}}} &= {tex(s.momentum)} \\",
                  rf"\frac{{d}}{{dt}}\frac{{\partial {L}}}{{\partial {v}}} &= "
                  rf"{tex(s.momentum_rate)} \\",
                  rf"\frac{{\partial {L}}}{{\partial {q}}} &= {tex(s.force_gradient)} \\",
                  rf"{Q}_{{{q}}} &= {tex(s.generalized_force)} \\"]
        if steps.constraints:
            lines.append(rf"(\Phi_q^T \lambda)_{{{q}}} &= {tex(s.multiplier_terms)} \\")
        lines.append(rf"0 &= {tex(s.equation)} && \text{{({_escape(c.name)})}} \\")
    for load in steps.loads:
        label = _escape(load.load)
        line = LOAD_LATEX[load.kind](load, tex)
        if line:
            lines.append(rf"{line} \\")
        lines.append(rf"\delta W_{{\mathrm{{{label}}}}} &= {tex(load.virtual_work)} \\")
    for k in steps.constraints:
        lines.append(rf"\Phi_{{q,\mathrm{{{_escape(k.constraint)}}}}} &= "
                     rf"{tex(sp.Matrix([list(k.jacobian)]))} \\")
    lines[-1] = lines[-1].removesuffix(r" \\")
    lines.append(r"\end{align}")
    return "\n".join(lines) + "\n"


def _force_latex(load, tex) -> str:
    label = _escape(load.load)
    return rf"\delta \mathbf{{r}}_{{\mathrm{{{label}}}}} &= {tex(sp.Matrix(_planar(load.displacement)))}"


def _moment_latex(load, tex) -> str:
    label = _escape(load.load)
    return rf"\delta \boldsymbol{{\phi}}_{{\mathrm{{{label}}}}} &= {tex(sp.Matrix(load.displacement))}"


def _scalar_latex(symbol: str):
    """delta(angle) or delta(length): one displacement, written with ``symbol``."""
    def line(load, tex) -> str:
        return rf"\delta {symbol}_{{\mathrm{{{_escape(load.load)}}}}} &= {tex(load.displacement[0])}"
    return line


def _no_displacement(load, tex) -> str:
    return ""


# the virtual displacement's line per kind of load step, as LOAD_TEXT (walked by the same test)
LOAD_LATEX = {
    LoadStepKind.FORCE: _force_latex,
    LoadStepKind.TORQUE: _scalar_latex(r"\theta"),
    LoadStepKind.MOMENT: _moment_latex,
    LoadStepKind.DAMPER: _scalar_latex(r"\ell"),
    LoadStepKind.DISSIPATION: _no_displacement,
    LoadStepKind.GIVEN: _no_displacement,
}


_LATEX_SPECIAL = {"\\": r"\textbackslash{}", "^": r"\^{}", "~": r"\~{}",
                  **{ch: "\\" + ch for ch in "_&%$#{}"}}


def _escape(name: str) -> str:
    """A name as LaTeX text: its special characters escaped, never read as commands."""
    return "".join(_LATEX_SPECIAL.get(ch, ch) for ch in name)
