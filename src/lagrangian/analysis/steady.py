"""Linearization about steady motion: cyclic coordinates turning at constant rates.

A relative equilibrium (a sleeping or precessing top, a spinning satellite) has q_ddot = 0 with
some velocities non-zero: the cyclic coordinates q_c (absent from M and f) turn at constant rates
Omega_c while the others stay at q0. About it, M dq_ddot + C dq_dot + K dq = 0 with
M = M(q0), C = -df/dq_dot and K = -df/dq at (q0, q_dot0) (the dM/dq q_ddot terms vanish since
q_ddot0 = 0); C now holds the gyroscopic coupling of the spin. Units SI (rad/s for the rates).

With constraints A(q) q_dot + b(q) = 0 (velocity or holonomic at velocity level) and their
multipliers lambda0 on the steady motion, K gains d(A^T lambda0)/dq and the perturbations keep
G dq_dot + H dq = 0 (G = A(q0), H = d(A q_dot + b)/dq at the steady state): the multipliers'
perturbation is eliminated with that constraint differentiated once, which adds one neutral
(zero) eigenvalue per constraint to the state matrix.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..compile.lambdified import numpy_function
from ..derivation.equations import EquationsOfMotion
from ..derivation.kinematics import Differentiator
from ..errors import DerivationError, InputError, ModelError, did_you_mean
from ..kinds import ConstraintKind
from ..model.expressions import as_expression
from ..model.model import Model, velocity_name
from ..model.rotations import gimbal_lock
from ..model.units import parse_quantity
from ..model.values import ParameterValues, resolve_parameters, resolve_state, state_units
from .linearization import LinearModel, state_matrix

FIELD = "steady"
# q_ddot smaller than this (relative to the rates squared) is a steady motion.
BALANCE_TOLERANCE = 1e-8


def steady_rates(eom: EquationsOfMotion, steady: Mapping[str, float | str],
                 parameters: Mapping[str, float] | ParameterValues | None = None,
                 ) -> dict[int, float]:
    """Coordinate index -> constant rate for names like ``psi_dot`` (rad/s or m/s); a rate may
    be an expression in the parameters (``"-v/rR"``), read with the model grammar."""
    model = eom.model
    velocities = {velocity_name(c.name): i for i, c in enumerate(model.coordinates)}
    rates = {}
    for name, value in steady.items():
        if name not in velocities:
            hint = did_you_mean(name, list(velocities))
            if name in {c.name for c in model.coordinates}:
                hint = f"; give the rate of '{name}' as {velocity_name(name)}=VALUE"
            raise ModelError(f"'{name}' is not a velocity of this model{hint}",
                             field=f"{FIELD}.{name}")
        if isinstance(value, str):
            value = _parameter_value(model, value, f"{FIELD}.{name}", parameters)
        try:
            rate = float(value)
        except (TypeError, ValueError):
            raise ModelError(f"expected a number, got {value!r}", field=f"{FIELD}.{name}") \
                from None
        if not np.isfinite(rate):
            raise ModelError("the rate must be finite", field=f"{FIELD}.{name}")
        rates[velocities[name]] = rate
    if not rates:
        raise ModelError("name at least one steady rate (e.g. psi_dot=10)", field=FIELD)
    return rates


_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def parse_steady_rates(model: Model, written: Mapping[str, str]) -> dict[str, float | str]:
    """Steady rates as written (``{"psi_dot": "600rpm"}``, ``{"thetaR_dot": "-v/rR"}``): each a
    quantity in its velocity's unit (rad/s, m/s), else, when the text names a parameter, the text
    itself, which ``steady_rates`` reads as an expression in the parameters. A name that is not
    a velocity is kept as given, for ``steady_rates`` to refuse by name. A bad quantity that
    names no parameter raises InputError (field ``steady.NAME``)."""
    units = state_units(model)
    parameters = {p.name for p in model.parameters}
    rates: dict[str, float | str] = {}
    for name, text in written.items():
        if name not in units:
            rates[name] = text
            continue
        try:
            rates[name] = parse_quantity(text, units[name], f"{FIELD}.{name}")
        except ModelError as error:
            if not parameters & set(_NAME.findall(text)):
                raise InputError(error.message, field=error.field) from None
            rates[name] = text
    return rates


def _parameter_value(model, text: str, field: str, parameters) -> float:
    """The value of an expression in the model's parameters (at their values)."""
    from ..model.expressions import parse_expression

    names = {p.name: p.symbol for p in model.parameters}
    expr = parse_expression(text, names, field=field)
    values = resolve_parameters(model, parameters).symbol_values(model)
    try:
        return float(expr.xreplace(values))
    except (TypeError, ValueError):
        raise ModelError(f"'{text}' has no value (a parameter without a value?)",
                         field=field) from None


class _SteadyTerms:
    """M, f, their slopes, the constraint terms and the holonomic residuals of one set of
    equations as one numpy function of (q, q_dot, t, parameters): compiled once, evaluated at
    any parameter values (a study of the rider's mass fits a form per mass)."""

    def __init__(self, eom: EquationsOfMotion):
        model = eom.model
        q, q_dot, t = model.q, model.q_dot, model.time
        n, k = len(q), len(model.constraints)
        forcing = [as_expression(e) for e in eom.forcing]
        mass = [as_expression(e) for e in eom.mass_matrix]
        jacobian = [as_expression(e) for e in eom.constraint_jacobian]
        bias = [as_expression(e) for e in eom.velocity_bias]
        gamma = [as_expression(e) for e in eom.acceleration_rhs]
        if any(t in e.free_symbols for e in (*forcing, *mass, *jacobian, *bias)):
            raise ModelError("the equations depend on time t explicitly, so there is no "
                             "steady motion to linearize about", field=FIELD)
        d = Differentiator()
        stiffness = [-d(e, x) for e in forcing for x in q]
        damping = [-d(e, v) for e in forcing for v in q_dot]
        level = [sp.Add(*(jacobian[c * n + j] * q_dot[j] for j in range(n)), bias[c])
                 for c in range(k)]  # A q_dot + b
        level_slope = [d(e, x) for e in level for x in q]
        jacobian_slope = [d(e, x) for e in jacobian for x in q]
        # Holonomic constraints hold at position level too: Phi(q0) = 0 on the steady motion.
        self.holonomic = [i for i, c in enumerate(model.constraints)
                          if c.kind == ConstraintKind.HOLONOMIC]
        positions = [as_expression(model.constraints[i].expression) for i in self.holonomic]
        self.sizes = [n * n, n, n * n, n * n, k * n, k, k, k * n, k * n * n]
        self.parameters = tuple(p.symbol for p in model.parameters)
        self.function = numpy_function(
            [*q, *q_dot, t, *self.parameters],
            [*mass, *forcing, *stiffness, *damping, *jacobian, *gamma, *level, *level_slope,
             *jacobian_slope, *positions])


class SteadyFunctions:
    """M, f, their slopes -df/dq and -df/dq_dot, the constraints A, gamma, A q_dot + b, its
    slope H, dA/dq and the holonomic residuals, at given parameter values (SI)."""

    def __init__(self, eom: EquationsOfMotion, values: Mapping[sp.Symbol, float]):
        self.model = eom.model
        self.n, self.k = len(self.model.q), len(self.model.constraints)
        terms = _steady_terms(eom)
        self.holonomic, self.sizes, self._function = terms.holonomic, terms.sizes, terms.function
        # a parameter without a value is NaN: every term it enters is then NaN, and refused
        self._values = tuple(float(values.get(s, np.nan)) for s in terms.parameters)

    def evaluate(self, qv, vv) -> dict[str, np.ndarray]:
        n, k = self.n, self.k
        flat = np.array([float(x) for x in self._function(*qv, *vv, 0.0, *self._values)],
                        dtype=float)
        parts = np.split(flat, np.cumsum(self.sizes))
        return {"M": parts[0].reshape(n, n), "f": parts[1], "K": parts[2].reshape(n, n),
                "C": parts[3].reshape(n, n), "A": parts[4].reshape(k, n), "gamma": parts[5],
                "level": parts[6], "H": parts[7].reshape(k, n),
                "dA": parts[8].reshape(k, n, n), "Phi": parts[9]}

    def solve(self, values) -> tuple[np.ndarray, np.ndarray]:
        """(q_ddot, lambda) of M q_ddot + A^T lambda = f, A q_ddot = gamma."""
        n, k = self.n, self.k
        M, A = values["M"], values["A"]
        system = np.block([[M, A.T], [A, np.zeros((k, k))]])
        right = np.concatenate([values["f"], values["gamma"]])
        solution = np.linalg.lstsq(system, right, rcond=None)[0]
        return solution[:n], solution[n:]


# The compiled terms of the last few equations: a speed sweep, a benchmark-form fit or a study
# of several parameter values linearizes the same equations many times.
_TERMS: dict[int, tuple[EquationsOfMotion, _SteadyTerms]] = {}


def _steady_terms(eom: EquationsOfMotion) -> _SteadyTerms:
    found = _TERMS.get(id(eom))
    if found is not None and found[0] is eom:
        return found[1]
    terms = _SteadyTerms(eom)
    if len(_TERMS) >= 4:
        _TERMS.pop(next(iter(_TERMS)))
    _TERMS[id(eom)] = (eom, terms)
    return terms


def steady_functions(eom: EquationsOfMotion,
                     parameters: Mapping[str, float] | ParameterValues | None = None,
                     ) -> SteadyFunctions:
    """The steady-motion functions of ``eom`` at these parameter values (compiled once)."""
    values = resolve_parameters(eom.model, parameters).symbol_values(eom.model)
    return SteadyFunctions(eom, values)


@dataclass(frozen=True)
class SteadyPoint:
    """The steady motion (q0, q_dot0) with the multipliers on it, and the linearized terms:
    M dq_ddot + C dq_dot + K dq + G^T dlambda = dQ, G dq_dot + H dq = 0 (SI units)."""

    q: np.ndarray
    q_dot: np.ndarray
    multipliers: np.ndarray
    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    G: np.ndarray
    H: np.ndarray
    holonomic: tuple[int, ...]
    rates: dict[int, float]


def steady_point(
    eom: EquationsOfMotion, about: Mapping[str, float] | None, steady: Mapping[str, float | str],
    parameters: Mapping[str, float] | ParameterValues | None = None,
) -> SteadyPoint:
    """The steady motion with the given rates (``steady``: velocity name -> rate, a number or
    an expression in the parameters) at the configuration ``about`` (other non-cyclic
    coordinates solved for), checked, with its linearized terms."""
    model = eom.model
    rates = steady_rates(eom, steady, parameters)
    names = [c.name for c in model.coordinates]
    n = len(names)
    state = resolve_state(model, about, field="about", velocities=False, time=False)
    about = {name: v for name, v in zip(names, state.q, strict=True) if name in state.given}
    functions = steady_functions(eom, parameters)
    k = functions.k
    evaluate, solve = functions.evaluate, functions.solve
    cyclic = sorted(rates)

    q0 = np.array([about.get(c.name, c.initial if c.initial is not None else 0.0)
                   for c in model.coordinates], dtype=float)
    v0 = np.zeros(n)
    for i, rate in rates.items():
        v0[i] = rate
    free = [i for i in range(n) if names[i] not in about and i not in rates]
    scale = 1.0 + max(abs(r) for r in rates.values()) ** 2

    if free:
        import scipy.optimize

        def residual(x):
            trial = q0.copy()
            trial[free] = x
            values_at = evaluate(trial, v0)
            return np.concatenate([solve(values_at)[0] / scale, values_at["Phi"]])

        solution = scipy.optimize.least_squares(residual, q0[free], xtol=1e-14, ftol=1e-14,
                                                gtol=1e-14)
        q0[free] = solution.x
    if model.rigid_bodies:  # solved into (or given near) a rotation sequence's singularity
        point = {**resolve_parameters(model, parameters, require=False).symbol_values(model),
                 **dict(zip(model.q, q0, strict=True))}
        lock = gimbal_lock(model.rigid_bodies, point)
        if lock:
            raise DerivationError(f"no linear model about this steady motion: {lock}")
    at = evaluate(q0, v0)
    M, C, G, H = at["M"], at["C"], at["A"], at["H"]
    if np.max(np.abs(at["Phi"]), initial=0.0) > 1e-9:
        raise ModelError("the configuration does not satisfy the holonomic constraints "
                         f"(largest residual {np.max(np.abs(at['Phi'])):.3g}); give 'about' "
                         "values on them", field="about")
    for c, value in enumerate(at["level"]):
        if abs(value) > BALANCE_TOLERANCE * scale:
            raise ModelError(f"the steady rates break constraint '{model.constraints[c].name}' "
                             f"(A q_dot + b = {value:.6g} there): give rates that satisfy it",
                             field=FIELD)
    try:
        np.linalg.cholesky(M)
        q_ddot, multipliers = solve(at)
    except np.linalg.LinAlgError:
        raise DerivationError("the mass matrix is singular on this steady motion (a gimbal-lock "
                              "configuration of the rotation sequence?); the linear model has "
                              "no state-space form") from None
    K = at["K"] + np.einsum("c,cij->ij", multipliers, at["dA"])
    if np.max(np.abs(q_ddot), initial=0.0) > BALANCE_TOLERANCE * scale:
        moving = ", ".join(f"{names[i]}_ddot = {q_ddot[i]:.6g}" for i in range(n)
                           if abs(q_ddot[i]) > BALANCE_TOLERANCE * scale)
        where = ", ".join(f"{name} = {v:.6g}" for name, v in zip(names, q0, strict=True))
        raise ModelError(f"not a steady motion: at {where} with "
                         f"{', '.join(f'{velocity_name(names[i])} = {r:g}' for i, r in rates.items())}"
                         f" the accelerations are not zero ({moving}); give other rates or "
                         "configuration", field=FIELD)
    # A cyclic coordinate appears in neither M, f nor the constraints: the same values with it
    # shifted, checked here and at nearby states (no derivatives needed).
    rng = np.random.default_rng(0)
    keys = ("M", "f", "A", "level")
    size = max(1.0, float(np.abs(M).max()) * scale)
    for trial in range(3):
        qv, vv = q0, v0
        if trial:
            qv = q0 + rng.uniform(-0.3, 0.3, n)
            vv = v0 + rng.uniform(-1.0, 1.0, n)
        base = evaluate(qv, vv)
        for i in cyclic:
            shifted = qv.copy()
            shifted[i] += 0.7
            other = evaluate(shifted, vv)
            change = max(float(np.max(np.abs(other[key] - base[key]), initial=0.0))
                         for key in keys)
            if change > 1e-9 * size:
                raise ModelError(
                    f"'{names[i]}' is not cyclic: the equations of motion depend on it, so it "
                    "cannot turn at a constant rate in a steady motion (choose coordinates in "
                    "which the spin angle is absent from L)", field=f"{FIELD}.{names[i]}_dot")
    return SteadyPoint(q0, v0, multipliers, M, C, K, G if k else np.zeros((0, n)),
                       H if k else np.zeros((0, n)), tuple(functions.holonomic), rates)


def _state_constraints(point: SteadyPoint, n: int) -> np.ndarray:
    """The linearized constraints over the state (dq, dq_dot): H dq + G dq_dot = 0 for each
    constraint, and for a holonomic one also Phi_q dq = 0 (its rows of G)."""
    if not point.G.shape[0]:
        return np.zeros((0, 2 * n))
    rows = [np.hstack([point.H, point.G])]
    holonomic = list(point.holonomic)
    if holonomic:
        rows.append(np.hstack([point.G[holonomic], np.zeros((len(holonomic), n))]))
    return np.vstack(rows)


def steady_linear_model(
    eom: EquationsOfMotion, about: Mapping[str, float] | None, steady: Mapping[str, float | str],
    parameters: Mapping[str, float] | ParameterValues | None = None,
) -> LinearModel:
    """The linear model about the steady motion with the given rates (``steady``: velocity
    name -> rate) at the configuration ``about`` (other non-cyclic coordinates solved for)."""
    model = eom.model
    names = [c.name for c in model.coordinates]
    n = len(names)
    point = steady_point(eom, about, steady, parameters)
    M, C, K, G, H = point.M, point.C, point.K, point.G, point.H
    k = G.shape[0]
    try:
        inverse = np.linalg.inv(M)
        S = np.linalg.inv(G @ inverse @ G.T) if k else np.zeros((0, 0))
    except np.linalg.LinAlgError:
        raise DerivationError("the mass matrix is singular on this steady motion (a gimbal-lock "
                              "configuration of the rotation sequence?); the linear model has "
                              "no state-space form") from None
    # dq_ddot = M^-1 P (-C dq_dot - K dq) - M^-1 G^T S H dq_dot, P = 1 - G^T S G M^-1: the
    # multipliers' perturbation keeps d/dt (G dq_dot + H dq) = 0.
    P = np.eye(n) - G.T @ S @ G @ inverse
    A = state_matrix(-inverse @ P @ K, -inverse @ P @ C - inverse @ G.T @ S @ H)
    return LinearModel(
        equilibrium={name: float(v) for name, v in zip(names, point.q, strict=True)},
        multipliers={c.name: float(v) for c, v in zip(model.constraints, point.multipliers,
                                                      strict=True)},
        coordinates=tuple(names),
        user_coordinates=tuple(names),
        basis=np.eye(n),
        mass_matrix=M,
        damping_matrix=C,
        stiffness_matrix=K,
        A=A,
        B=np.zeros((2 * n, 0)),
        input_matrix=np.zeros((n, 0)),
        velocity_constraints=G if k else np.zeros((0, n)),
        full_mass_matrix=M,
        full_damping_matrix=C,
        full_stiffness_matrix=K,
        steady={velocity_name(names[i]): float(r) for i, r in sorted(point.rates.items())},
        state_constraints=_state_constraints(point, n),
    )


__all__ = ["SteadyFunctions", "SteadyPoint", "parse_steady_rates", "steady_functions",
           "steady_linear_model", "steady_point", "steady_rates"]
