"""The report page's sections on what the motion keeps (report/page.py): the quantities the
model's own L conserves (System.conserved(): cyclic momenta, the Jacobi integral, Noether
quantities), each with its value at the initial state, and, for a model with impacts, the limit
cycle through them (System.limit_cycle(): the fixed point, the period, the Poincare map's
multipliers, stable or not). Each returns (body, status); one line where it does not apply.
"""

from __future__ import annotations

import sympy as sp

from ..analysis.conserved import ConservedKind
from ..errors import LagrangianError
from .html import Markup, element, join, note, number, paragraph, table
from .mathml import mi, mo
from .outline import SHOWN

_KIND_WORDS = {
    ConservedKind.MOMENTUM: "the momentum of a cyclic coordinate, p = ∂L/∂q̇",
    ConservedKind.JACOBI: "the Jacobi integral h = q̇·∂L/∂q̇ − L",
    ConservedKind.NOETHER: "a Noether quantity of a symmetry no coordinate shows",
}


def initial_state(model) -> tuple[list[float], list[float]]:
    """The model's initial q and q_dot (SI, coordinate order; an unset value is 0)."""
    return ([float(c.initial or 0.0) for c in model.coordinates],
            [float(c.rate or 0.0) for c in model.coordinates])


def conserved_section(c) -> tuple[Markup, str]:
    if c.urdf:
        return note("A URDF robot: its Lagrangian is evaluated by recursive algorithms, not "
                    "written out, so its conserved quantities are not derived."), \
            "not applicable: URDF"
    found = c.system.conserved()
    if not len(found) and not found.broken:
        return note("Nothing is conserved along every motion: L depends on every coordinate "
                    "and on t, and no symmetry was found."), "not applicable: none found"
    q, q_dot = initial_state(c.model)
    parts = []
    if len(found):
        between = (" between impacts (an impact changes them: the simulation lists the energy "
                   "each one takes)") if c.model.impacts else ""
        parts.append(paragraph("Along every motion of the model's own L these keep their "
                               f"value{between}; each is shown with its value at the initial "
                               "state (SI)."))
    for quantity in found:
        words = _KIND_WORDS[quantity.kind]
        if quantity.kind == ConservedKind.JACOBI:
            words += (": equal to T + V, the energy" if quantity.equals_energy else
                      ": not T + V, which is not conserved here (the drive does work)")
        if quantity.kind == ConservedKind.NOETHER:
            words += ", generator ξ = (" + ", ".join(map(str, quantity.generator)) + ")"
        name = mi(quantity.name) if quantity.name == "h" else c.write(sp.Symbol(quantity.name))
        try:
            value = f"; at the initial state {number(quantity.value(q, q_dot))}"
        except (LagrangianError, ArithmeticError, ValueError) as exc:  # a value left symbolic
            value = f"; no value at the initial state ({exc})"
        parts.append(c.typeset(f"The {quantity.kind} {quantity.name}", [quantity.expression],
                               lambda quantity=quantity, name=name, label=f"{words}{value}":
                               c.formula(label[:1].upper() + label[1:], name, mo("="),
                                         c.write(c.readable(quantity.expression)))))
    if found.broken:
        parts.append(element("h3", "Not conserved"))
        parts.append(table(["quantity", "kind", "why"],
                           [(b.name, str(b.kind), b.reason) for b in found.broken]))
    if found.note:
        parts.append(paragraph(found.note, class_="note"))
    return join(parts), SHOWN


def limit_cycle_section(c) -> tuple[Markup, str]:
    model = c.model
    if not model.impacts:
        return note("No impacts: the model has no limit cycle through one (a walker's gait "
                    "is one)."), "not applicable: no impacts"
    try:
        cycle = c.system.limit_cycle()
    except LagrangianError as exc:  # the reason without its field: no guess was given here
        reason = getattr(exc, "message", str(exc)).rstrip(".")
        return note(f"No limit cycle found from the initial state: {reason}."), \
            "not applicable: no cycle found"
    units = {co.name: co.unit or "" for co in model.coordinates}
    units |= {co.velocity.name: f"{co.unit or '1'}/s" for co in model.coordinates}
    verdict = element("span", {"neutral": "neutrally stable"}.get(cycle.stability,
                                                                  cycle.stability),
                      class_="good" if cycle.stable else "bad")
    largest = max((abs(m) for m in cycle.multipliers), default=0.0)
    parts = [paragraph(f"A periodic motion through the impact '{cycle.impact}', period "
                       f"{number(cycle.period, 9)} s: ", verdict,
                       f" (the largest multiplier has |μ| = {number(largest, 6)}, "
                       f"{_where(cycle)} the unit circle). "
                       "The fixed point of the Poincaré map on the section just after the "
                       "impact, found by Newton's method on the map's exact Jacobian.")]
    parts.append(element("h3", "The fixed point, just after the impact"))
    parts.append(table(["state", "value", "unit"],
                       [(name, number(value, 9), units.get(name, ""))
                        for name, value in cycle.state.items()]))
    parts.append(element("h3", "Multipliers"))
    parts.append(paragraph("The eigenvalues μ of the linearized Poincaré map (its Jacobian "
                           "from the variational equations and the impact's saltation), "
                           "less the flow direction's 0:"))
    parts.append(table(["#", "μ", "|μ|"],
                       [(str(i), _complex(m), number(abs(m), 9))
                        for i, m in enumerate(cycle.multipliers, 1)]))
    return join(parts), SHOWN


def _complex(m: complex) -> str:
    """A multiplier as text: real where its imaginary part is rounding, else a ± b i."""
    if abs(m.imag) <= 1e-12 * max(1.0, abs(m)):
        return number(m.real, 9)
    sign = "−" if m.imag < 0 else "+"
    return f"{number(m.real, 9)} {sign} {number(abs(m.imag), 9)}i"


def _where(cycle) -> str:
    """Where the largest multiplier lies: inside, on (a neutral cycle) or outside the circle."""
    return {"stable": "inside", "neutral": "on", "unstable": "outside"}[cycle.stability]
