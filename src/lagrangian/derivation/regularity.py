"""Checks that the equations can be solved for the accelerations (and multipliers).

A structural test finds coordinates whose velocity T does not contain; a numeric rank test at
random states (probabilistic: generic rank holds almost everywhere) finds the rest, and names
a redundant constraint.
"""

from __future__ import annotations

import math
import random

import numpy as np
import sympy as sp

from ..errors import DerivationError
from ..model.model import Model


def random_state(model: Model, seed: int = 12345) -> dict[sp.Symbol, sp.Float]:
    """A random substitution for parameters without value, coordinates, velocities and time."""
    rng = random.Random(seed)
    values: dict[sp.Symbol, sp.Float] = {}
    for p in model.parameters:
        value = p.value if p.value is not None else rng.uniform(0.6, 1.7)
        values[p.symbol] = sp.Float(value)
    for c in model.coordinates:
        values[c.symbol] = sp.Float(rng.uniform(-1.3, 1.3) + (c.initial or 0.0))
        values[c.velocity] = sp.Float(rng.uniform(-1.0, 1.0))
    values[model.time] = sp.Float(rng.uniform(0.1, 1.0))
    return values


_FUNCTIONS = {
    sp.sin: math.sin, sp.cos: math.cos, sp.tan: math.tan, sp.exp: math.exp, sp.log: math.log,
    sp.asin: math.asin, sp.acos: math.acos, sp.atan: math.atan, sp.sinh: math.sinh,
    sp.cosh: math.cosh, sp.tanh: math.tanh, sp.Abs: abs,
}


class _Evaluator:
    """Float evaluation of sympy trees with shared sub-expressions evaluated once.

    One evaluation at one point does not pay for compiling (lambdify) the whole matrix.
    """

    def __init__(self, values: dict):
        self.memo = {symbol: float(value) for symbol, value in values.items()}

    def __call__(self, expr: sp.Basic) -> float:
        found = self.memo.get(expr)
        if found is not None:
            return found
        if expr.is_Number:
            value = float(expr)
        elif expr.is_Add:
            value = math.fsum(self(a) for a in expr.args)
        elif expr.is_Mul:
            value = math.prod(self(a) for a in expr.args)
        elif expr.is_Pow:
            value = self(expr.args[0]) ** self(expr.args[1])
        elif expr.func in _FUNCTIONS:
            value = _FUNCTIONS[expr.func](*(self(a) for a in expr.args))
        elif expr.func is sp.atan2:
            value = math.atan2(self(expr.args[0]), self(expr.args[1]))
        else:
            symbols = {k: sp.Float(v) for k, v in self.memo.items() if isinstance(k, sp.Symbol)}
            value = complex(expr.xreplace(symbols).evalf())
            if abs(value.imag) > 1e-12 * max(1.0, abs(value.real)):
                raise ValueError("not real")
            value = value.real
        if isinstance(value, complex):
            raise ValueError("not real")
        self.memo[expr] = value
        return value


def numeric_matrix(matrix: sp.MatrixBase, values: dict) -> np.ndarray:
    """Evaluate a symbolic matrix at a point (floats; raises ValueError if not real)."""
    evaluate = _Evaluator(values)
    out = np.empty(matrix.shape)
    for i in range(matrix.rows):
        for j in range(matrix.cols):
            out[i, j] = evaluate(matrix[i, j])
    return out


def check_regularity(model: Model, mass_matrix: sp.MatrixBase, jacobian: sp.MatrixBase) -> None:
    """Raise DerivationError naming the coordinate or constraint that makes the system singular."""
    n, m = mass_matrix.shape[0], jacobian.shape[0]
    names = [c.name for c in model.coordinates]
    missing = [names[i] for i in range(n) if all(mass_matrix[i, j] == 0 for j in range(n))]
    if len(missing) == n:
        # No inertia at all: a mechanism for statics (virtual work needs none); only the
        # commands that integrate or linearize in time refuse it (require_inertia).
        return
    if missing and not m:
        raise DerivationError(_missing_message(missing, model))
    values = random_state(model)
    try:
        M = numeric_matrix(mass_matrix, values)
        A = numeric_matrix(jacobian, values) if m else np.zeros((0, n))
    except (TypeError, ValueError, ZeroDivisionError, OverflowError):
        return  # not numerically evaluable (e.g. complex at this point): leave it to the solver
    if not (np.all(np.isfinite(M)) and np.all(np.isfinite(A))):
        return
    if m:
        _check_constraints(model, A, jacobian)
        system = np.block([[M, A.T], [A, np.zeros((m, m))]])
    else:
        system = M
    if _rank(system) < system.shape[0]:
        if missing:
            raise DerivationError(_missing_message(missing, model))
        null = np.linalg.svd(system)[2][-1][:n]
        involved = [names[i] for i in np.flatnonzero(np.abs(null) > 1e-6 * np.abs(null).max())]
        raise DerivationError(
            "the mass matrix W = d^2L/dq_dot^2 is singular"
            + (" on the constraints" if m else "")
            + f": the accelerations of {', '.join(involved)} cannot be solved for "
            "(T does not determine them independently); check the kinetic energy"
        )


def _missing_message(missing: list[str], model: Model) -> str:
    if model.source_names:  # a URDF robot: the joints carry massless links; lock is the fix
        from ..errors import lock_hint

        return lock_hint([dict(model.source_names).get(c, c) for c in missing])
    listed = ", ".join(f"'{name}'" for name in missing)
    return (
        f"singular mass matrix: the kinetic energy does not contain the velocity of {listed}, "
        "so its equation has no acceleration; give it inertia (a mass, a body or a T term) or "
        "remove the coordinate"
    )


def _check_constraints(model: Model, A: np.ndarray, jacobian: sp.MatrixBase) -> None:
    kept: list[np.ndarray] = []
    for index, (constraint, row) in enumerate(zip(model.constraints, A, strict=True)):
        candidate = np.array(kept + [row])
        if _rank(candidate) < len(candidate):
            others = ", ".join(c.name for c in model.constraints[: len(kept)]) or "none"
            contradiction = _contradiction(model, jacobian, index) if np.any(row) else None
            if contradiction is not None:
                value, involved = contradiction
                where = " and ".join(f"'{name}'" for name in involved)
                raise DerivationError(
                    f"inconsistent constraints: where {where} hold{'s' if len(involved) == 1 else ''}"
                    f", '{constraint.name}' equals {value:.6g}, never 0; correct or remove one of "
                    "them"
                )
            if not np.any(row):
                reason = "its Jacobian is zero"
            else:
                reason = f"it depends on the constraints before it ({others})"
            raise DerivationError(
                f"redundant constraint '{constraint.name}': {reason}; "
                "remove it so that there is exactly one multiplier per independent constraint"
            )
        kept.append(row)


def _contradiction(model: Model, jacobian: sp.MatrixBase, index: int
                   ) -> tuple[float, list[str]] | None:
    """The constant value of constraint ``index`` where those before it hold (and their
    names), when the
    constraints can never hold together (x - 1 = 0 and x - 2 = 0); None when it is merely
    redundant.

    Its Jacobian row is a combination a of theirs, so Phi_k - a . Phi has no gradient; when a
    and that difference are the same at two random states, and the difference is not 0, Phi_k
    equals that constant wherever the others are 0. Only constraints of one kind are compared
    (a holonomic Phi and a velocity A q_dot + b are not the same kind of quantity).
    """
    constraints = model.constraints[: index + 1]
    found = []
    for seed in (12345, 54321):
        values = random_state(model, seed)
        try:
            rows = numeric_matrix(jacobian[: index + 1, :], values)
            evaluate = _Evaluator(values)
            phi = np.array([evaluate(c.expression) for c in constraints])
        except (TypeError, ValueError, ZeroDivisionError, OverflowError):
            return None
        if not (np.all(np.isfinite(rows)) and np.all(np.isfinite(phi))):
            return None
        combination = np.linalg.lstsq(rows[:index].T, rows[index], rcond=None)[0]
        found.append((combination, float(phi[index] - combination @ phi[:index])))
    (a1, c1), (a2, c2) = found
    involved = [c for c, a in zip(constraints, a1, strict=False) if abs(a) > 1e-9]
    if {c.kind for c in involved} != {constraints[index].kind}:
        return None
    scale = max(1.0, abs(c1), *(abs(v) for v in a1))
    if np.allclose(a1, a2, rtol=1e-9, atol=1e-12) and abs(c1 - c2) <= 1e-9 * scale \
            and abs(c1) > 1e-9 * scale:
        return c1, [c.name for c in involved]
    return None


def _rank(matrix: np.ndarray) -> int:
    if matrix.size == 0:
        return 0
    singular = np.linalg.svd(matrix, compute_uv=False)
    scale = max(singular.max(), 1.0)
    return int(np.sum(singular > 1e-9 * scale))


def require_inertia(eom, what: str) -> None:
    """Raise DerivationError when ``what`` (e.g. 'simulate') needs accelerations the model
    cannot give: coordinates without mass, inertia or T."""
    missing = eom.coordinates_without_inertia
    if missing:
        listed = ", ".join(f"'{name}'" for name in missing)
        raise DerivationError(
            f"{what} needs inertia: the model has no mass, inertia or kinetic energy for "
            f"{listed} (a statics model: derive, forces, equilibria, check and statics work "
            "without it)"
        )


def vanishes(expr: sp.Expr, model: Model, samples: int = 4) -> bool:
    """expr == 0 at random states, parameters, times and multipliers (a probabilistic identity
    test: a nonzero analytic expression is almost never zero at a random point); False where
    it cannot be evaluated."""
    if expr == 0:
        return True
    others = sorted(expr.free_symbols, key=str)
    scale = 0.0
    values = []
    for seed in range(samples):
        point = _random_point(model, others, seed=1000 + seed)
        try:
            values.append(_Evaluator(point)(expr))
            scale = max(scale, *(abs(float(v)) for v in point.values()))
        except (TypeError, ValueError, ZeroDivisionError, OverflowError):
            return False
    return all(abs(v) <= 1e-9 * max(1.0, scale) for v in values)


def independent_of_time(exprs, model: Model, samples: int = 3) -> bool:
    """Each expression takes the same value at several times for random other values: it does
    not change with t, whatever its form (sin^2(Omega t) + cos^2(Omega t) does not)."""
    t = model.time
    if not any(t in e.free_symbols for e in exprs):
        return True
    for seed in range(samples):
        point = _random_point(model, set().union(*(e.free_symbols for e in exprs)),
                              seed=2000 + seed)
        try:
            seen = []
            for time in (0.0, 0.37, 1.9, 7.3):
                point[t] = sp.Float(time)
                evaluate = _Evaluator(point)
                seen.append([evaluate(e) for e in exprs])
        except (TypeError, ValueError, ZeroDivisionError, OverflowError):
            return False
        reference = seen[0]
        for row in seen[1:]:
            for a, b in zip(reference, row, strict=True):
                if abs(a - b) > 1e-9 * max(1.0, abs(a), abs(b)):
                    return False
    return True


def _random_point(model: Model, symbols, seed: int) -> dict[sp.Symbol, sp.Float]:
    """Random values for every symbol (parameters too: an identity must hold for all values)."""
    rng = random.Random(seed)
    point = {s: sp.Float(rng.uniform(0.4, 1.6)) for s in sorted(symbols, key=str)}
    for c in model.coordinates:
        point[c.symbol] = sp.Float(rng.uniform(-1.3, 1.3))
        point[c.velocity] = sp.Float(rng.uniform(-1.0, 1.0))
    return point


def physical_warnings(model: Model, mass_matrix: sp.MatrixBase) -> list[str]:
    """What makes a well-formed model physically meaningless, one line each: a negative mass
    or moment of inertia, or a kinetic energy that is not positive (a mass matrix with a
    negative eigenvalue) at the initial state. Parameters without a value are not judged."""
    warnings = []
    values: dict[sp.Symbol, float] = {p.symbol: p.value for p in model.parameters
                                      if p.value is not None}
    for kind, items in (("particle", model.particles), ("body", model.bodies)):
        for item in items:
            for what, expr in (("mass", item.mass), ("moment of inertia",
                                                     getattr(item, "inertia", None))):
                value = _constant_value(expr, values)
                if value is not None and value < 0:
                    warnings.append(f"{kind} '{item.name}' has a negative {what} ({value:.6g})")
    state = dict(values)
    state[model.time] = 0.0
    for c in model.coordinates:
        state[c.symbol] = c.initial if c.initial is not None else 0.0
        state[c.velocity] = c.rate if c.rate is not None else 0.0
    if mass_matrix.shape[0] and not warnings:
        try:
            M = numeric_matrix(mass_matrix, state)
        except (TypeError, ValueError, ZeroDivisionError, OverflowError, KeyError):
            return warnings
        try:
            with np.errstate(all="ignore"):
                eigenvalues = np.linalg.eigvalsh(0.5 * M + 0.5 * M.T)  # M + M.T may overflow
        except (np.linalg.LinAlgError, ValueError):  # entries near overflow (m = 1e308)
            return warnings
        if np.all(np.isfinite(eigenvalues)):
            if eigenvalues.min() < -1e-9 * max(1.0, float(np.abs(eigenvalues).max())):
                warnings.append(
                    "the kinetic energy is not positive at the initial state (the mass matrix has "
                    f"the eigenvalue {eigenvalues.min():.6g}): T < 0 for some velocities, "
                    "so the motion is not physical")
    return warnings


def _constant_value(expr: object, values: dict[sp.Symbol, float]) -> float | None:
    """A mass or inertia as a number with the parameters' values; None where it is not one."""
    if not isinstance(expr, sp.Expr):
        return None
    try:
        value = expr.xreplace({s: sp.Float(v) for s, v in values.items()})
        return float(value) if not value.free_symbols else None
    except (TypeError, ValueError, OverflowError):
        return None
