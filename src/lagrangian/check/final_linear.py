"""Verdicts on ``[linearized]``: the student's small-motion equations against ours,
M z_ddot + C z_dot + K z = 0 about the equilibrium the answer names (or the one `modes` takes).

Ours are exact (parameters kept as symbols, compared at random values) where the model is
unconstrained, small and its equilibrium does not move with the parameters; otherwise numbers at
the model's values, from the numeric linear model. A constrained model is linearized on its
constraints, in the independent coordinates the student writes (dq = N z, z those coordinates).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..compile.at_rest import linear_velocity_row
from ..compile.lambdified import operations_exceed
from ..derivation.kinematics import jacobian_row
from ..errors import ModelError
from ..model.expressions import as_expression
from ..model.expressions import format_expression as fmt
from . import equivalence as eq
from .final_reading import SLACK, Entry
from .finding import Finding

EXACT_MAX_COORDINATES = 8  # symbolic Jacobians of f beyond this cost seconds; numbers instead
EXACT_MAX_OPERATIONS = 4000  # the same for f's size (a URDF arm's f): numbers instead
CONDITION_LIMIT = 1e8  # the student's coordinates must fix the others through the constraints


@dataclass(frozen=True)
class Ours:
    """Our linear equations in ``coordinates`` (rows and columns), about ``equilibrium``."""

    coordinates: tuple[str, ...]
    M: sp.Matrix
    C: sp.Matrix
    K: sp.Matrix
    equilibrium: dict[str, sp.Expr]
    exact: bool  # symbolic in the parameters; else numbers at the model's values

    @property
    def about(self) -> str:
        return ", ".join(f"{k} = {fmt(v) if self.exact else format(float(v), '.6g')}"
                         for k, v in self.equilibrium.items())


def check_linearized(checker) -> list[Finding]:
    """Findings on every equation of [linearized] (checker: final_answers._FinalChecker)."""
    model = checker.model
    equilibrium = checker.equilibrium()  # not an equilibrium: refused (ModelError)
    linear = checker.system.linearize(equilibrium)
    if linear.velocity_constraints.size:
        return [Finding(f"linearized.{name}", "note", None, "not checked: linearized equations "
                        "are checked for unconstrained models and holonomic constraints; this "
                        "model has velocity constraints", None)
                for name, _ in checker.final.linearized]
    chosen = _independent(checker, linear)
    ours = exact_linear(checker, equilibrium) if len(chosen) == len(model.coordinates) else None
    ours = ours or _numeric(linear, chosen)
    return [_equation(checker, name, entry, ours) for name, entry in checker.final.linearized]


def _independent(checker, linear) -> tuple[str, ...]:
    """The coordinates the student's equations are in (their keys and every coordinate they
    name), completed with ours up to the degrees of freedom; refused when too many or when the
    constraints do not fix the others through them."""
    model, names = checker.model, checker.names
    used = set()
    for name, entry in checker.final.linearized:
        used.add(name)
        symbols = entry.value.free_symbols
        used.update(c.name for c in model.coordinates
                    if {c.symbol, c.velocity, c.acceleration} & symbols)
    freedom = linear.basis.shape[1]
    if len(used) > freedom:
        raise ModelError(
            f"this model has {freedom} degree(s) of freedom on its constraints: write the "
            f"linearized equations in {freedom} independent coordinate(s) (ours: "
            f"{', '.join(linear.coordinates)}), got {', '.join(n for n in names if n in used)}",
            field="linearized")
    for name in linear.coordinates:
        if len(used) < freedom:
            used.add(name)
    chosen = tuple(n for n in names if n in used)
    rows = linear.basis[[names.index(n) for n in chosen], :]
    if np.linalg.cond(rows) > CONDITION_LIMIT:
        raise ModelError(
            f"{', '.join(chosen)} cannot serve as independent coordinate(s) at this equilibrium "
            f"(the constraints do not fix the others through them there); ours: "
            f"{', '.join(linear.coordinates)}", field="linearized")
    return chosen


def exact_linear(checker, equilibrium: dict[str, float]) -> Ours | None:
    """Exact M, C, K of an unconstrained model at an equilibrium that is one for every value of
    the parameters (0, pi: not m g / k written as a number); None otherwise."""
    model = checker.model
    if model.constraints or len(model.coordinates) > EXACT_MAX_COORDINATES:
        return None
    point = {c.symbol: sp.nsimplify(equilibrium[c.name], [sp.pi], tolerance=1e-12,
                                    rational=False) for c in model.coordinates}
    if any(v.atoms(sp.Float) or sp.count_ops(v) > 4 for v in point.values()):
        return None  # not 0, pi/2, -3*pi/4, 1/2: a number the parameters may have made
    eom = checker.system.equations_of_motion()
    at_rest = {v: sp.S.Zero for v in model.q_dot}
    forcing = [as_expression(e) for e in eom.forcing]
    if operations_exceed(forcing, EXACT_MAX_OPERATIONS):
        return None
    if not all(eq.zero(f.xreplace(at_rest).xreplace(point), checker.random) for f in forcing):
        return None  # an equilibrium at the model's values only
    K = [[-d.xreplace(point) for d in jacobian_row(f.xreplace(at_rest), model.q)]
         for f in forcing]
    C = [[-d.xreplace(at_rest).xreplace(point) for d in linear_velocity_row(f, model.q_dot)]
         for f in forcing]
    return Ours(tuple(checker.names), sp.Matrix(eom.mass_matrix.xreplace(point)), sp.Matrix(C),
                sp.Matrix(K), {c.name: point[c.symbol] for c in model.coordinates}, exact=True)


def _numeric(linear, chosen: tuple[str, ...]) -> Ours:
    """M, C, K at the model's values, projected on the constraints with ``chosen`` as z."""
    names = list(linear.user_coordinates)
    basis = linear.basis  # dq = basis @ z_ours
    rows = basis[[names.index(n) for n in chosen], :]
    basis = basis @ np.linalg.inv(rows)  # dq = basis @ z_chosen

    def reduced(full: np.ndarray) -> sp.Matrix:
        matrix = basis.T @ full @ basis
        scale = max(float(np.abs(matrix).max()), 1e-300)
        return sp.Matrix([[sp.Float(v) if abs(v) > 1e-10 * scale else sp.S.Zero for v in row]
                          for row in matrix])

    return Ours(chosen, reduced(linear.full_mass_matrix), reduced(linear.full_damping_matrix),
                reduced(linear.full_stiffness_matrix),
                {n: sp.Float(v) for n, v in linear.equilibrium.items()}, exact=False)


def _equation(checker, name: str, entry: Entry, ours: Ours) -> Finding:
    model, item = checker.model, f"linearized.{name}"
    z = [model.coordinate(n) for n in ours.coordinates]
    unknowns = [c.acceleration for c in z] + [c.velocity for c in z] + [c.symbol for c in z]
    i = ours.coordinates.index(name)
    coefficients = [*ours.M.row(i), *ours.C.row(i), *ours.K.row(i)]
    expected = f"{fmt(sp.Add(*(_shown(c) * u for c, u in zip(coefficients, unknowns, strict=True))))} = 0"
    about = ours.about
    where = "" if ours.exact else "; compared at the model's parameter values"
    if len(z) < len(model.coordinates):
        where += f"; in {', '.join(ours.coordinates)}, the others following from the constraints"
    user = entry.value
    if not eq.is_linear([user], unknowns, checker.random):
        return Finding(item, "wrong", "not_linearized",
                       f"your equation is not linear in {', '.join(map(str, unknowns))}: "
                       f"about {about}, keep only first-order terms (sin(theta) ~ theta, "
                       "cos(theta) ~ 1, products of small quantities dropped).", expected)
    mine = [user.diff(u) for u in unknowns]
    exact = ours.exact and entry.relative is None
    points = checker.random if exact else checker.valued
    zero = [eq.zero(c, points) for c in coefficients]
    best, best_scale = [], None
    for k in range(len(coefficients)):
        if zero[k] or eq.zero(mine[k], points):
            continue
        scale = mine[k] / coefficients[k]
        wrong = [j for j in range(len(coefficients))
                 if not checker.same(Entry(entry.text, mine[j], relative=entry.relative),
                                     scale * coefficients[j], numeric=not ours.exact)]
        if best_scale is None or len(wrong) < len(best):
            best, best_scale = wrong, scale
    if best_scale is None:
        return Finding(item, "wrong", "linear_coefficient",
                       "your equation has no term in common with ours.", expected)
    if best:
        named = "; ".join(f"the coefficient of {unknowns[j]} is {fmt(eq.display(mine[j]))}"
                          f"{_valued(checker, mine[j], ours)} in yours, ours is "
                          f"{_ours(checker, best_scale * coefficients[j], ours)}"
                          for j in best[:4])
        return Finding(item, "wrong", "linear_coefficient",
                       f"{named} (ours scaled to match your other terms; about {about}{where}).",
                       expected)
    offset = user.xreplace(dict.fromkeys(unknowns, 0))
    shifts = [m * ours.equilibrium[c.name] for m, c in zip(mine[-len(z):], z, strict=True)]
    if _vanishes(offset, shifts, points, entry.relative):
        return Finding(item, "correct", None, f"the linearization of ours about {about}, up to "
                       f"a factor{where}.", None)
    if _vanishes(offset, [], points, entry.relative):
        return Finding(item, "correct", None, f"the linearization of ours about {about}, up to "
                       f"a factor (read in the deviations from the equilibrium){where}.", None)
    return Finding(item, "wrong", "linear_offset",
                   f"your equation is not zero at the equilibrium {about}: its constant term is "
                   f"{fmt(eq.display(offset))}. Write it in the coordinates or in their "
                   "deviations from the equilibrium.", expected)


def _vanishes(offset: sp.Expr, shifts: list[sp.Expr], points, relative: float | None) -> bool:
    """offset + sum(shifts) = 0 at the points, to the precision of the numbers written."""
    total = offset + sp.Add(*shifts)
    if total == 0:
        return True
    rows = points.evaluate([total, *([offset, *shifts] or [sp.S.Zero])])
    tolerance = (relative or 0.0) + SLACK
    for row in rows:
        size = sum(abs(v) for v in row[1:])
        if not abs(row[0]) <= tolerance * size + points.tolerance * max(1, size):
            return False
    return True


def _valued(checker, coefficient: sp.Expr, ours: Ours) -> str:
    """' = 39.24' where ours are numbers and yours is an expression in the parameters."""
    if ours.exact or not coefficient.free_symbols:
        return ""
    return f" = {float(checker.value(coefficient)):.6g}"


def _ours(checker, coefficient: sp.Expr, ours: Ours) -> str:
    """Ours scaled to yours: an expression where exact, else its value at the model's values."""
    if ours.exact:
        return fmt(eq.display(coefficient))
    return f"{float(checker.value(coefficient)):.6g}"


def _shown(value: sp.Expr) -> sp.Expr:
    """Numbers to 6 significant figures for a message (exact expressions as they are)."""
    return value.xreplace({f: sp.Integer(int(f)) if float(f).is_integer() else
                           sp.Float(f"{float(f):.6g}") for f in value.atoms(sp.Float)})
