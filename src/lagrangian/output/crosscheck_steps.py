"""The working of `crosscheck --steps`: text, and the `steps` key of `crosscheck --json`.

Expressions in the model-file grammar; small ones tidied for reading (equal by construction:
trigsimp and readable grouping), long ones named by their length in the text (whole in JSON).
"""

from __future__ import annotations

import functools
from typing import Any

import sympy as sp

from ..check import equivalence as eq
from ..check.free_body_steps import CrosscheckSteps, FreeBodyStep
from ..derivation.readable import readable
from ..kinds import FreeBodyKind
from ..model.expressions import format_expression
from ..model.repeatable import repeatable_random

LONGEST = 240  # characters of one expression in the text; the JSON has every one whole
_AXES = ("x", "y", "z")

# m a_G (and I alpha) projected, as each kind of free body writes it
_INERTIAL_SHARE = {
    FreeBodyKind.PARTICLE: "m a_G . dr_G/d{q}",
    FreeBodyKind.BODY: "m a_G . dr_G/d{q} + I alpha dangle/d{q}",
    FreeBodyKind.BODY_IN_SPACE: "m a_G . dr_G/d{q} + (I alpha + omega x I omega) . domega/d{q}_dot",
}


@functools.lru_cache(maxsize=2048)
def _tidy(expr: sp.Expr) -> sp.Expr:
    """Equal, shorter: trigonometric identities on a small expression (sin^2 + cos^2 = 1)."""
    expr = sp.sympify(expr)  # safe: a sympy object or a number
    if not eq.is_small(expr):
        return readable(expr)
    try:
        with repeatable_random():  # the same factoring points, and cost, in every run
            tidied = sp.trigsimp(sp.expand(expr))
    except Exception:  # noqa: BLE001 - tidying only costs readability
        return readable(expr)
    grouped = readable(tidied)
    return grouped if sp.count_ops(grouped) <= sp.count_ops(expr) else readable(expr)


def _json(expr) -> str:
    return format_expression(_tidy(expr))


def _text(expr) -> str:
    text = _json(expr)
    return text if len(text) <= LONGEST else f"({len(text)} characters; whole in --json)"


def _planar(steps: CrosscheckSteps) -> bool:
    return all(b.kind != FreeBodyKind.BODY_IN_SPACE and b.acceleration[2] == 0
               and all(f.force[2] == 0 for f in b.forces) for b in steps.bodies)


def _vector(values, planar: bool) -> str:
    return "(" + ", ".join(_text(v) for v in (values[:2] if planar else values)) + ")"


def crosscheck_steps_text(steps: CrosscheckSteps) -> str:
    planar = _planar(steps)
    axes = _AXES[:2] if planar else _AXES
    lines = ["Steps (Newton-Euler: free bodies, then projected onto the virtual displacements):",
             "  Free-body equations, m a_G = sum F + R and I alpha = sum M_G + M_R "
             "(R, M_R: reactions):"]
    for b in steps.bodies:
        lines += _body_lines(b, axes, planar)
    placed = {f.source for b in steps.bodies for f in b.forces}
    elsewhere = sorted({s for p in steps.projections for s, _ in p.work} - placed)
    if elsewhere:
        lines.append("  on no free body (the model gives no force vector or point): "
                     + ", ".join(elsewhere) + "; they enter by their virtual work only")
    lines += ["", "  Projection: E_i = sum_bodies (m a_G . dr_G/dq_i + I alpha dangle/dq_i) - "
              "sum_forces F . dr/dq_i;", "  the reactions do no virtual work and drop out"
              + (" (the constraints' Phi_q^T lambda stands on both sides and is left out):"
                 if steps.constrained else ":")]
    kinds = {b.body: b.kind for b in steps.bodies}
    for p in steps.projections:
        q = p.coordinate
        lines.append(f"  [{q}]")
        for body, value in p.inertial:
            share = _INERTIAL_SHARE[kinds[body]].format(q=q)
            lines.append(f"    {body}: {share} = {_text(value)}")
        lines += [f"    {source}: F . dr/d{p.coordinate} = {_text(value)}"
                  for source, value in p.work]
        lines.append(f"    Newton-Euler E = {_text(p.newton_euler)}")
        lines.append(f"    Lagrange (M q_ddot - f) = {_text(p.lagrange)}   "
                     + ("agree" if p.agree else "DIFFER"))
    return "\n".join(lines) + "\n"


def _body_lines(b: FreeBodyStep, axes, planar: bool) -> list[str]:
    lines = [f"    {b.body} ({b.kind}, m = {_text(b.mass)}"
             + (f", I_G = {_text(b.inertia)}" if b.inertia is not None else "") + "):",
             f"      a_G = {_vector(b.acceleration, planar)}"]
    for f in b.forces:
        moment = (f", moment about G {_text(f.moment[0])}" if len(f.moment) == 1
                  else f", moment about G {_vector(f.moment, False)}" if f.moment else "")
        lines.append(f"      {f.source}: F = {_vector(f.force, planar)}{moment}")
    for k, axis in enumerate(axes):
        total = sp.Add(*(f.force[k] for f in b.forces))
        applied = "" if total == 0 else f"{_text(total)} + "
        lines.append(f"      {axis}: {_text(b.mass * b.acceleration[k])} = {applied}R_{axis}")
    if b.inertia is not None:
        total = sp.Add(*(f.moment[0] for f in b.forces if f.moment))
        applied = "" if total == 0 else f"{_text(total)} + "
        lines.append(f"      about G: {_text(b.inertia * b.angular_acceleration)} = "
                     f"{applied}M_R")
    lines.append(f"      reaction R = {_vector(b.reaction, planar)}"
                 + (f", M_R = {_text(b.reaction_moment)}" if b.reaction_moment is not None
                    else ""))
    if b.kind == FreeBodyKind.BODY_IN_SPACE:
        lines.append("      (its rotation: Euler's equations in body axes, I alpha + omega x "
                     "I omega = M_G + M_R, in the projection below)")
    return lines


def crosscheck_steps_document(steps: CrosscheckSteps) -> dict[str, Any]:
    """The `steps` key of `crosscheck --steps --json`."""
    return {
        "bodies": [
            {"body": b.body, "kind": b.kind, "mass": _json(b.mass),
             "acceleration": [_json(v) for v in b.acceleration],
             "forces": [{"source": f.source, "force": [_json(v) for v in f.force],
                         "moment": [_json(v) for v in f.moment]} for f in b.forces],
             "reaction": [_json(v) for v in b.reaction],
             "inertia": None if b.inertia is None else _json(b.inertia),
             "angular_acceleration": (None if b.angular_acceleration is None
                                      else _json(b.angular_acceleration)),
             "reaction_moment": (None if b.reaction_moment is None
                                 else _json(b.reaction_moment))}
            for b in steps.bodies],
        "projections": {
            p.coordinate: {"inertial": {body: _json(v) for body, v in p.inertial},
                           "work": {source: _json(v) for source, v in p.work},
                           "newton_euler": _json(p.newton_euler),
                           "lagrange": _json(p.lagrange), "agree": p.agree}
            for p in steps.projections},
    }
