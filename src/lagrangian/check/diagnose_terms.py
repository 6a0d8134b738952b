"""Diagnoses that trace one wrong term to where it comes from (used by diagnose.py).

- which component a term of V belongs to (each particle's and body's gravity, each spring), so a
  sign error in any single term of V is named with its body or spring;
- which load a differing equation term comes from: the difference D (yours minus ours, both as
  expression = 0) is compared with each load's share Q_i of the virtual work, so a forgotten load
  (D = Q_i) or one projected wrongly (yours gives Q_i - D in its place) is named;
- whether an equation is the linearization of ours about q = 0 (the small-angle form);
- the difference message, with one sign convention in each sentence and a scale that is never a
  division by a fraction.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import singledispatch

import sympy as sp

from ..derivation.kinematics import time_rate
from ..derivation.virtual_work import DISSIPATION_LOAD, GIVEN_LOAD
from ..model.expressions import format_expression as fmt
from ..model.model import Damper, Model, PointForce, Torque
from ..model.rotations import Moment
from . import equivalence as eq

# -- energy parts, to name a missing term ------------------------------------------------


def kinetic_parts(model: Model) -> list[tuple[str, sp.Expr]]:
    """Each component's share of T: 1/2 m v^2 of a particle, 1/2 m v_G^2 and 1/2 I w^2 of a body."""
    q, q_dot, t = model.q, model.q_dot, model.time
    half = sp.Rational(1, 2)
    parts = []

    def speed2(position):
        return sp.Add(*(time_rate(r, q, q_dot, t) ** 2 for r in position))

    for particle in model.particles:
        parts.append((f"translational energy 1/2 m v^2 of particle '{particle.name}'",
                      half * particle.mass * speed2(particle.position)))
    for body in model.bodies:
        parts.append((f"translational energy 1/2 m v_G^2 of body '{body.name}'",
                      half * body.mass * speed2(body.position)))
        omega = time_rate(body.angle, q, q_dot, t)
        if omega != 0:
            parts.append((f"rotational energy 1/2 I w^2 of body '{body.name}'",
                          half * body.inertia * omega**2))
    if model.kinetic_energy != 0:
        parts.append(("kinetic energy given in the model ([energy] T)", model.kinetic_energy))
    return [(label, value) for label, value in parts if value != 0]


def potential_parts(model: Model) -> list[tuple[str, sp.Expr]]:
    """Each source of V: gravity of each particle and body, each spring, the model's V."""
    parts = []
    if model.gravity is not None:
        g, direction = model.gravity.magnitude, model.gravity.direction
        for item in (*model.particles, *model.bodies):
            height = sp.Add(*(d * r for d, r in zip(direction, item.position, strict=True)))
            if height.free_symbols & set(model.q):
                parts.append((f"gravity potential of '{item.name}'", -item.mass * g * height))
    for spring in model.springs:
        parts.append((f"potential of spring '{spring.name}'",
                      sp.Rational(1, 2) * spring.stiffness * (spring.length - spring.rest_length) ** 2))
    if model.potential_energy != 0:
        parts.append(("potential given in the model ([energy] V)", model.potential_energy))
    return parts


def flipped_potential_term(V_user: sp.Expr, V: sp.Expr, model: Model, points: eq.Points,
                           factor: int = 2) -> tuple[list[str], sp.Expr] | None:
    """(labels, term) when V_user is V with one term of V of the wrong sign (up to a constant):
    a term of one component's potential (m2 g l2 cos(theta2) of the second bob), or all the
    terms of one shape together (-(m1 + m2) g l1 cos(theta1), of both bobs). ``factor`` 1:
    the term left out instead."""
    state = set(model.q) | {model.time}
    terms: list[tuple[str, sp.Expr]] = []
    for label, part in potential_parts(model):
        if not eq.is_small(part):
            continue
        written = sp.Add.make_args(part)  # as written: 1/2 k_c (x2 - x1)^2 is one term
        if len(written) > 1:
            terms += [(term_label(term, label, model), term) for term in written
                      if term.free_symbols & state]
        else:
            written = ()
        terms += [(label, term) for term in sp.Add.make_args(sp.expand(part))
                  if term.free_symbols & state and term not in written]
    for label, term in terms:
        if eq.constant_in_state(V_user - (V - factor * term), points):
            return [label], term
    shapes: dict[sp.Expr, list[tuple[str, sp.Expr]]] = {}
    for label, term in terms:
        shapes.setdefault(term.as_independent(*state, as_Add=False)[1], []).append((label, term))
    for members in shapes.values():
        if len(members) < 2:
            continue
        together = sp.Add(*(term for _, term in members))
        if eq.constant_in_state(V_user - (V - factor * together), points):
            return list(dict.fromkeys(label for label, _ in members)), together
    return None


def term_label(term: sp.Expr, label: str, model: Model) -> str:
    """A term of a written V named by what it is: 1/2 k_c (x2 - x1)^2 is the spring k_c
    between x1 and x2 (a stiffness parameter times a square of the coordinates)."""
    coefficient, square = term.as_independent(*model.q, model.time, as_Add=False)
    base, exponent = square.as_base_exp()
    stiffness = [p for p in model.parameters if p.symbol in coefficient.free_symbols and (
        (p.unit or "").replace(" ", "") in ("N/m", "N*m/rad", "N*m", "kg/s^2", "N/rad")
        or p.name.lower().startswith("k"))]
    if exponent != 2 or not stiffness or not base.free_symbols & set(model.q):
        return label
    names = [c.name for c in model.coordinates if c.symbol in base.free_symbols]
    between = f" coupling {' and '.join(names)}" if len(names) == 2 else f" on {names[0]}" \
        if len(names) == 1 else ""
    return f"potential of spring {stiffness[0].name}{between}"


def sign_question(labels: list[str], rises: str) -> str:
    """The module's question for a sign error in V: 'Does V increase as the body rises?' for
    gravity, the spring's own for springs only."""
    if labels and all(label.startswith("potential of spring") for label in labels):
        return ("Does the spring store 1/2 k s^2 >= 0 (s its stretch), whichever way it is "
                "stretched?")
    return rises


# -- equations ---------------------------------------------------------------------------


def scale_of(user: sp.Expr, ours: sp.Expr, q_ddot: Sequence[sp.Symbol],
             points: eq.Points) -> sp.Expr:
    """c with user ~ c * ours, from the first acceleration both equations have (1 if none)."""
    for a in q_ddot:
        c_ours = ours.diff(a)
        if ours.has(a) and not eq.zero(c_ours, points):
            c_user = user.diff(a)
            if eq.zero(c_user, points):
                return sp.S.One
            scale = c_user / c_ours
            return sp.cancel(scale) if eq.is_small(scale) else scale
    return sp.S.One


def scaled_phrase(scale: sp.Expr) -> str:
    """' (after multiplying yours by m*L**2)': never a division by a fraction."""
    if scale == 1:
        return ""
    numerator, denominator = sp.fraction(sp.together(scale))
    if denominator == 1:
        return f" (after dividing yours by {fmt(scale)})"
    return f" (after multiplying yours by {fmt(eq.display(1 / scale))})"


def difference_message(user: sp.Expr, ours: sp.Expr, q_ddot: Sequence[sp.Symbol],
                       multipliers: Sequence[sp.Symbol], points: eq.Points) -> str:
    """Name the terms that differ, after scaling the user's equation like ours, side by side
    as the expected answer is written (M q_ddot + Phi_q^T lambda on the left, f on the right),
    so every term keeps the one sign it has there (the left-hand side's terms are those with
    an acceleration or a multiplier)."""
    scale = scale_of(user, ours, q_ddot, points)
    scaled = scaled_phrase(scale)
    yours = user / scale
    if not (eq.is_small(user) and eq.is_small(ours)):
        return (f"the equation differs from ours{scaled} by the term {fmt(yours - ours)} "
                "(yours minus ours, both written as expression = 0).")
    left_unknowns = {*q_ddot, *multipliers}
    sentences = []
    for side in ("left", "right"):
        sign = 1 if side == "left" else -1
        mine = {sign * t for t in sp.Add.make_args(sp.expand(yours))
                if bool(t.free_symbols & left_unknowns) == (side == "left")}
        theirs = {sign * t for t in sp.Add.make_args(sp.expand(ours))
                  if bool(t.free_symbols & left_unknowns) == (side == "left")}
        extra, missing = mine - theirs, theirs - mine
        if not extra and not missing:
            continue
        where = f"the {side}-hand side" + (" (the forcing f)" if side == "right" else "")
        if missing and not extra:
            sentences.append(f"{where} lacks the term {fmt(eq.display(sp.Add(*missing)))} that "
                             "ours has")
        elif extra and not missing:
            sentences.append(f"{where} has the extra term {fmt(eq.display(sp.Add(*extra)))}")
        else:
            sentences.append(f"on {where} yours has {fmt(eq.display(sp.Add(*extra)))} where "
                             f"ours has {fmt(eq.display(sp.Add(*missing)))} (yours minus ours: "
                             f"{fmt(eq.display(sp.Add(*extra) - sp.Add(*missing)))})")
    if not sentences:  # equal term sets, yet not identical: written in another form
        return (f"the equation differs from ours{scaled} by the term "
                f"{fmt(eq.display(sp.expand(yours - ours)))} (yours minus ours, both written "
                "as expression = 0).")
    return (f"the equation differs from ours{scaled}, written as M q_ddot"
            + (" + Phi_q^T lambda" if multipliers else "") + " = f: " + "; ".join(sentences) + ".")


def traced_load(user: sp.Expr, ours: sp.Expr, contributions: list[tuple[str, sp.Expr]],
                model: Model, points: eq.Points):
    """('missing', load, Q_i, scale) when yours lacks exactly one load's share Q_i of the
    virtual work; ('projection', load, Q_i, yours, scale) when yours has another expression
    in the same parameters in its place (sin for cos, a lever arm, a sign); ('all', ...) when
    every load is missing; else None."""
    if not contributions:
        return None
    scale = scale_of(user, ours, model.q_ddot, points)
    difference = user / scale - ours  # ours = M q_ddot - (... + Q_i): a missing Q_i gives +Q_i
    for load, part in contributions:
        if eq.identical(difference, part, points):
            return ("missing", load, part, scale)
    if len(contributions) > 1 and eq.identical(
            difference, sp.Add(*(p for _, p in contributions)), points):
        return ("all", contributions, scale)
    parameters = {p.symbol for p in model.parameters}
    for load, part in contributions:
        yours = part - difference
        if eq.zero(yours, points) or not eq.is_small(yours):
            continue
        yours = eq.display(sp.expand(yours))
        if (yours.free_symbols & parameters) != (part.free_symbols & parameters):
            continue
        ratio = yours / part
        if eq.constant_in_state(ratio, points) and not eq.identical(ratio, -1, points):
            continue  # twice the load is not a projection (nor a sign)
        return ("projection", load, part, yours, scale)
    return None


def potential_source(user: sp.Expr, ours: sp.Expr, coordinate: sp.Symbol, model: Model,
                     points: eq.Points) -> str | None:
    """A sentence naming the component of V whose force -dV/dq_i is left out of the equation
    or has the wrong sign (a spring forgotten), else None."""
    scale = scale_of(user, ours, model.q_ddot, points)
    difference = user / scale - ours  # ours has +dV/dq_i: left out, yours - ours = -dV/dq_i
    for label, part in potential_parts(model):
        force = -part.diff(coordinate)
        if force == 0:
            continue
        shown = fmt(eq.display(force)) if eq.is_small(force) else "its -dV/dq"
        if eq.identical(difference, force, points):
            return f"It is the force -dV/d{coordinate} = {shown} of the {label}, left out."
        if eq.identical(difference, 2 * force, points):
            return (f"Yours has the force -dV/d{coordinate} = {shown} of the {label} with "
                    "the wrong sign.")
    return None


def projection_message(model: Model, load_name: str, part: sp.Expr, name: str,
                       yours: sp.Expr) -> str:
    """Why a load's share is wrong: its dr/dq (or d(angle)/dq, d(rate)/dq_dot), its Q and yours."""
    q = model.coordinate(name).symbol
    element = next((item for item in (*model.loads, *model.dampers) if item.name == load_name),
                   None)
    tail = (f"so its generalized force is {fmt(eq.display(part))}; yours is "
            f"{fmt(eq.display(yours))} (sin for cos, lever arm or sign?).")
    if element is not None:
        return projection_explanation(element, name, q, tail)
    what = {DISSIPATION_LOAD: "the dissipation D", GIVEN_LOAD: "the given generalized force"}
    return f"{what.get(load_name, repr(load_name))} is projected wrongly, {tail}"


# one entry per kind that does virtual work (tests/model/test_component_tables.py walks them)
@singledispatch
def projection_explanation(element, name: str, q: sp.Symbol, tail: str) -> str:
    """How ``element``'s virtual work projects onto coordinate ``name``, then ``tail``."""
    raise TypeError(f"no projection message for a {type(element).__name__}")


@projection_explanation.register
def _(load: PointForce, name: str, q: sp.Symbol, tail: str) -> str:
    dr = ", ".join(fmt(eq.display(r.diff(q))) for r in _planar(load.point))
    force = ", ".join(fmt(f) for f in _planar(load.force))
    return (f"the load '{load.name}' is projected wrongly: its point moves by "
            f"dr = dr/d{name} d{name} = ({dr}) d{name}, and dW = F . dr with "
            f"F = ({force}), {tail}")


@projection_explanation.register
def _(load: Torque, name: str, q: sp.Symbol, tail: str) -> str:
    return (f"the torque '{load.name}' is projected wrongly: it turns through "
            f"d(angle) = ({fmt(eq.display(load.angle.diff(q)))}) d{name}, {tail}")


@projection_explanation.register
def _(load: Moment, name: str, q: sp.Symbol, tail: str) -> str:
    return (f"the moment '{load.name}' is projected wrongly: dW = M . dphi, so Q = M . "
            f"d(omega)/d{name}_dot with omega the body's angular velocity, {tail}")


@projection_explanation.register
def _(damper: Damper, name: str, q: sp.Symbol, tail: str) -> str:
    return (f"the damper '{damper.name}' is projected wrongly: Q = -c (rate) d(rate)/"
            f"d{name}_dot with rate = {fmt(damper.rate)}, {tail}")


def _planar(vector):
    return vector[:2] if vector[2] == 0 else vector


def linearized(ours: sp.Expr, model: Model) -> sp.Expr | None:
    """Ours to first order about q = 0, q_dot = 0, q_ddot = 0 (None when it is ours already,
    or for a model with multipliers)."""
    if model.constraints or not eq.is_small(ours):
        return None
    rest = {s: sp.S.Zero for s in (*model.q, *model.q_dot, *model.q_ddot)}
    terms = [ours.xreplace(rest)]
    for s in (*model.q, *model.q_dot, *model.q_ddot):
        slope = ours.diff(s).xreplace(rest)
        if slope != 0:
            terms.append(slope * s)
    linear = sp.Add(*terms)
    if linear.has(sp.zoo, sp.oo, sp.nan) or sp.expand(linear - ours) == 0:
        return None
    return linear


def about_zero(model: Model, equation: sp.Expr) -> str:
    """'theta = 0' (or 'theta1 = 0, theta2 = 0'): the coordinates the equation has."""
    names = [c.name for c in model.coordinates if equation.has(c.symbol)] or \
        [c.name for c in model.coordinates]
    return ", ".join(f"{name} = 0" for name in names)


__all__ = ["about_zero", "difference_message", "flipped_potential_term", "kinetic_parts",
           "linearized", "potential_parts", "potential_source", "projection_message",
           "scale_of", "scaled_phrase", "sign_question", "traced_load"]
