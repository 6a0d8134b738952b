"""The report page (`lagrangian report MODEL`, ``System.report()``): one self-contained HTML file
with the model, its energies, generalized forces, equations, equilibria, modes, a simulation,
the units check and, given an answer, the check of a hand derivation.

Offline by construction: no script, no style sheet or font from elsewhere, every picture a data:
URI (a Content-Security-Policy in the page forbids anything else). Math is MathML, which browsers
render without JavaScript (report/mathml.py). Each section that does not apply to the model (no
loads, no equilibrium found, a URDF robot's equations) says so in one line. The numeric
sections are in report/sections.py, the pictures in report/media.py.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import sympy as sp

from ..derivation.readable import readable
from ..errors import LagrangianError, ModelError
from ..model.examples import example_path
from ..model.urdf import example_urdf
from ..output.files import atomic_write, check_generated_target, check_output_path
from .html import Markup, element, h, image, join, math, note, page, paragraph, table
from .mathml import MathWriter, math_block, mi, mo, mrow, mtext
from .outline import SHOWN, Section

DEFAULT_T_END = 10.0  # s: the simulation's length when none is given
_LONG_SOURCE = 20_000  # characters of model file shown before it is folded away
TYPESET_LIMIT = 2500  # nodes of the expressions in one formula (the largest example but one: 133)


@dataclass(frozen=True)
class Report:
    """A report page of one model: ``html`` (a whole document), ``sections`` (what each shows);
    ``save(path)`` writes it, in Jupyter it shows itself."""

    model_name: str
    html: str
    sections: tuple[Section, ...]

    def save(self, path: str | Path, *, protect: tuple[Path, ...] = ()) -> Path:
        """Write the page to ``path`` (*.html) atomically; a file there that an earlier report did
        not write (or one of ``protect``, the inputs) is refused."""
        path = check_report_path(path, protect)
        return atomic_write(path, self.html, protect=protect)

    def _repr_html_(self) -> str:
        # In its own frame, so the page's style and policy do not touch the notebook's.
        return (f'<iframe srcdoc="{h(self.html)}" title="{h(self.model_name)}" '
                'style="width: 100%; height: 48rem; border: 1px solid #ccc"></iframe>')

    def __repr__(self) -> str:
        shown = sum(s.shown for s in self.sections)
        return f"Report({self.model_name!r}, {shown} of {len(self.sections)} sections shown)"


def check_report_path(path: str | Path, protect: tuple[Path, ...] = ()) -> Path:
    """The page's path, checked before any work: *.html, writable, not an input, and free or
    holding an earlier report (never a file lagrangian did not write)."""
    path = Path(path)
    if path.suffix.lower() not in (".html", ".htm"):
        raise ModelError(f"the report is a web page; name the file *.html (got '{path}')",
                         field="out")
    check_output_path(path, "out", inputs=tuple(protect))
    return check_generated_target(path)


class _Page:
    """What the sections share: the system (duck-typed: api.System), its math writer and the
    equations, derived once."""

    def __init__(self, system, size: tuple[int, int] | None = None, fps: float | None = None):
        self.system = system
        self.size, self.fps = size, fps  # of the animations (None: the page's defaults)
        self.model = system.model
        self.write = MathWriter(self.model)
        self.urdf = self.model.kinematic_tree is not None
        self._eom = None

    @property
    def eom(self):
        if self._eom is None:
            self._eom = self.system.equations_of_motion()
        return self._eom

    def readable(self, expr) -> sp.Expr:
        """The derivation's readable form (grouped by rates; equal to ``expr``)."""
        model = self.model
        rates = frozenset([*model.q_dot, *model.q_ddot, *self.eom.multipliers])
        ranges = {c.symbol: tuple(c.range) for c in model.coordinates if c.range}
        return readable(expr, rates, ranges)

    def formula(self, label, *parts: str) -> Markup:
        """A labelled displayed formula, scrolling sideways when long."""
        block = element("div", math(math_block(*parts)), class_="formula")
        return join([paragraph(label, class_="formula-label"), block]) if label else block

    def typeset(self, what: str, exprs, make: Callable[[], Markup]) -> Markup:
        """``make()``, or one line saying ``what`` is too long to typeset: past TYPESET_LIMIT
        nodes (the benchmark bicycle's M: 32000) a formula is pages wide and costs minutes."""
        size = 0
        for expr in exprs:
            for _ in sp.preorder_traversal(sp.sympify(expr)):  # safe: derived sympy objects, no text
                size += 1
                if size > TYPESET_LIMIT:
                    return note(f"{what}: more than {TYPESET_LIMIT} terms and factors, too long "
                                "to typeset here (`lagrangian derive MODEL` prints it).")
        return make()

    def letter(self, letter: str) -> str:
        """``letter =`` as MathML, or nothing when the model has a symbol of that name (a
        length L is not the Lagrangian)."""
        names = {p.name for p in self.model.parameters} | {c.name for c in self.model.coordinates}
        return "" if letter in names else mi(letter) + mo("=")


def build_report(system, *, answer=None, t_end: float | None = None,
                 progress: Callable[[str], None] | None = None, size: object = None,
                 fps: object = None) -> Report:
    """The report of ``system`` (an api.System): ``answer`` (a path, dict or Answer) adds the
    check of a hand derivation; ``t_end`` (s) sets the simulation's length (default 10 s);
    ``size`` ("WxH" or (width, height) pixels) and ``fps`` set every animation's frames, as
    for ``modes --animate``. An unreadable answer or a bad size is refused before any work."""
    from ..output.media import check_fps, check_size
    from . import invariants
    from . import sections as numeric

    size, fps = check_size(size), None if fps is None else check_fps(fps)
    if t_end is not None and not (np.isfinite(float(t_end)) and float(t_end) > 0):
        raise ModelError(f"the simulation's length must be a positive number of seconds, got "
                         f"{t_end!r}", field="t_end")
    checked = system.check(answer) if answer is not None else None
    context = _Page(system, size, fps)
    builders = [
        ("model", "Model", _model_section),
        ("energy", "Energies and the Lagrangian", _energy_section),
        ("forces", "Generalized forces per load", _forces_section),
        ("equations", "Equations of motion", _equations_section),
        ("equilibria", "Equilibria and their stability", numeric.equilibria_section),
        ("modes", "Modes", numeric.modes_section),
        ("conserved", "Conserved quantities", invariants.conserved_section),
        ("simulation", "Simulation", lambda c: numeric.simulation_section(
            c, DEFAULT_T_END if t_end is None else float(t_end))),
        ("cycle", "Limit cycle through the impacts", invariants.limit_cycle_section),
        ("units", "Units check", numeric.units_section),
        ("check", "Check of a hand derivation", lambda c: numeric.check_section(c, checked)),
    ]
    parts, sections = [], []
    for key, title, build in builders:
        if progress is not None:
            progress(title)
        try:
            body, status = build(context)
        except LagrangianError as exc:  # this section cannot be made for this model: one line
            body, status = note(f"Not available for this model: {exc}"), f"not available: {exc}"
        parts.append((key, title, body))
        sections.append(Section(key, title, status))
    model = context.model
    heading = join([element("h1", f"{model.name}"),
                    paragraph("A report by lagrangian: the equations by Lagrange's method, "
                              "their analysis and a simulation. Units SI.", class_="note")])
    html = page(f"{model.name} · lagrangian report", heading, parts)
    return Report(model.name, html, tuple(sections))


# -- the model ----------------------------------------------------------------------------------


def model_file_text(model) -> tuple[str, str] | None:
    """(where, text) of the file the model was read from, or None (built in Python)."""
    source = model.source
    if not source:
        return None
    if source.startswith("example:"):
        name = source.removeprefix("example:")
        path = example_urdf(name) or example_path(name)
        where = f"built-in example '{name}'"
    else:
        path, where = Path(source), source
    try:
        text = Path(path).read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
    if source.startswith("example:"):  # the examples' listing order is not part of the model
        text = re.sub(r"\A# order: \d+\n", "", text)
    return where, text


def _model_section(c: _Page) -> tuple[Markup, str]:
    from .media import NOTHING_TO_DRAW, data_uri, drawable, drawing_png

    model = c.model
    parts = []
    if model.description:
        parts.append(paragraph(model.description))
    rows = [(co.name, co.unit or "1", _value(co.initial), _value(co.rate)) for co in model.coordinates]
    tables = [element("h3", "Coordinates"), table(["name", "unit", "initial", "rate (per s)"], rows)]
    if model.parameters:
        tables += [element("h3", "Parameters"), table(
            ["name", "value (SI)", "unit"],
            [(p.name, _value(p.value), p.unit or "") for p in model.parameters])]
    drawing = [element("h3", "Drawing")]
    if not drawable(model):
        drawing.append(note(NOTHING_TO_DRAW))
    else:
        try:
            q = np.array([co.initial or 0.0 for co in model.coordinates], dtype=float)
            drawing.append(element(
                "figure", image(data_uri(drawing_png(model, q), "image/png"),
                                f"the mechanism {model.name} at its initial state"),
                element("figcaption", "At the initial values of the coordinates.")))
        except LagrangianError as exc:
            drawing.append(note(f"No drawing: {exc}"))
    parts.append(element("div", element("div", *tables), element("div", *drawing),
                         class_="columns"))
    found = model_file_text(model)
    parts.append(element("h3", "Model file"))
    if found is None:
        parts.append(note("Built in Python (no model file)."))
    else:
        where, text = found
        folded = len(text) > _LONG_SOURCE or c.urdf  # a robot's XML is long and not the point
        summary = element("summary", f"{where} ({len(text.splitlines())} lines)")
        parts.append(element("details", summary, element("pre", element("code", text)),
                             open=None if folded else "open"))
    return join(parts), SHOWN


def _value(value) -> str:
    return "–" if value is None else f"{float(value):.6g}"


# -- energies, forces and equations --------------------------------------------------------------


def _urdf_note(c: _Page, what: str) -> tuple[Markup, str]:
    line = (f"A URDF robot: its {what} are evaluated by recursive algorithms (Newton-Euler, "
            "CRBA), not written out symbolically.")
    return note(line), "not applicable: URDF"


def _energy_section(c: _Page) -> tuple[Markup, str]:
    if c.urdf:
        return _urdf_note(c, "energies")
    eom = c.eom
    T, V, D = eom.kinetic_energy, eom.potential_energy, eom.dissipation
    parts = [c.typeset("Kinetic energy T", [T], lambda: c.formula(
                 "Kinetic energy (J)", c.letter("T"), c.write(c.readable(T)))),
             c.typeset("Potential energy V", [V], lambda: c.formula(
                 "Potential energy (J)", c.letter("V"), c.write(c.readable(V))))]
    if D != 0:
        parts.append(c.typeset("Dissipation function D", [D], lambda: c.formula(
            "Dissipation function (W)", c.letter("D"), c.write(c.readable(D)))))
    parts.append(c.typeset("Lagrangian L = T - V", [T, V], lambda: c.formula(
        "Lagrangian (J)", c.letter("L"), c.write(c.readable(T) - c.readable(V)))))
    return join(parts), SHOWN


def _forces_section(c: _Page) -> tuple[Markup, str]:
    if c.urdf:
        return _urdf_note(c, "generalized forces")
    eom = c.eom
    contributions = [x for x in eom.load_contributions if x.expression != 0]
    if not contributions:
        return note("No loads: every force comes from the potential energy V (or the "
                    "dissipation function D)."), "not applicable: no loads"
    parts = []
    for load in dict.fromkeys(x.load for x in contributions):
        parts.append(element("h3", f"Load {load}"))
        for x in (x for x in contributions if x.load == load):
            name = _force_name(c, c.model.coordinate(x.coordinate).symbol)
            parts.append(c.typeset(f"Q of {x.coordinate}", [x.expression], lambda x=x, name=name:
                                   c.formula(None, name, c.write(c.readable(x.expression)))))
    totals = [(co, q) for co, q in zip(c.model.coordinates, eom.generalized_forces, strict=True)
              if q != 0]
    parts.append(element("h3", "Total generalized force"))
    for co, q in totals:
        name = _force_name(c, co.symbol)
        parts.append(c.typeset(f"Q of {co.name}", [q], lambda q=q, name=name:
                               c.formula(None, name, c.write(c.readable(q)))))
    return join(parts), SHOWN


def _force_name(c: _Page, coordinate: sp.Symbol) -> str:
    """Q with the coordinate as its index, then =."""
    return mrow("<msub>" + mi("Q") + c.write(coordinate) + "</msub>", mo("="))


def _signed_sum(c: _Page, terms: list[sp.Expr]) -> str:
    """Terms written in the order given (not sympy's), each with its sign."""
    if not terms:
        return c.write(0)
    out = []
    for i, term in enumerate(terms):
        negative = term.could_extract_minus_sign()
        body = c.write(-term if negative else term)
        out.append((mo("\u2212") if negative else (mo("+") if i else "")) + body)
    return mrow(*out)


def _equations_section(c: _Page) -> tuple[Markup, str]:
    if c.urdf:
        return _urdf_note(c, "equations of motion")
    eom = c.eom
    model = c.model
    M, A, f = eom.mass_matrix, eom.constraint_jacobian, eom.forcing
    parts = [paragraph("In the form ", math(_convention()), " (M the mass matrix, f the forcing, "
                       "λ the multipliers): one equation per coordinate, the "
                       "accelerations on the left in coordinate order"
                       + (", then the constraint reactions" if A.rows else "") + ".")]
    for i, coordinate in enumerate(model.coordinates):
        def row(i=i, coordinate=coordinate) -> Markup:
            left = [c.readable(M[i, j]) * a for j, a in enumerate(model.q_ddot) if M[i, j] != 0]
            left += [c.readable(A[k, i]) * eom.multipliers[k] for k in range(A.rows)
                     if A[k, i] != 0]
            return c.formula(f"{coordinate.name}:", _signed_sum(c, left), mo("="),
                             c.write(c.readable(f[i])))

        parts.append(c.typeset(f"The equation of {coordinate.name}",
                               [*M.row(i), *A.col(i), f[i]], row))
    parts.append(element("h3", "Mass matrix and forcing"))
    parts.append(c.typeset("The mass matrix", [M], lambda: c.formula(
        "Mass matrix (kg, kg m, kg m²)", c.letter("M"),
        c.write(sp.Matrix(M.rows, M.cols, [c.readable(x) for x in M])))))
    parts.append(c.typeset("The forcing", [f], lambda: c.formula(
        "Forcing (N, N m)", c.letter("f"), c.write(sp.Matrix([c.readable(x) for x in f])))))
    if model.constraints:
        parts.append(element("h3", "Constraints"))
        for constraint in model.constraints:
            kind = str(getattr(constraint.kind, "value", constraint.kind))
            parts.append(c.typeset(f"The constraint {constraint.name}", [constraint.expression],
                                   lambda constraint=constraint, kind=kind: c.formula(
                                       f"{constraint.name} ({kind}):",
                                       c.write(constraint.expression), mo("="), c.write(0))))
        parts.append(c.typeset("The constraint Jacobian", [A], lambda: c.formula(
            None, "<msub>" + mi("\u03a6") + mi("q") + "</msub>", mo("="),
            c.write(sp.Matrix(A.rows, A.cols, [c.readable(x) for x in A])))))
    return join(parts), SHOWN


def _convention() -> str:
    """M q_ddot + Phi_q^T lambda = f, as inline MathML."""
    from .mathml import DOUBLE_DOT, math_inline

    q_ddot = f'<mover accent="true">{mi("q")}{mo(DOUBLE_DOT)}</mover>'
    phi = f"<msubsup>{mi('Φ')}{mi('q')}{mtext('T')}</msubsup>"
    return math_inline(mi("M"), q_ddot, mo("+"), phi, mi("λ"), mo("="), mi("f"))
