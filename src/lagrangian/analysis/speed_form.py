"""Reduced linear equations about steady rolling, and their form in the forward speed.

About a steady motion (analysis/steady.py) the perturbations keep G dq_dot + H dq = 0. Splitting
the speeds into independent ones u (the kept coordinates' rates first) and dependent ones,
dq_dot = N du + P dq with N = [1; -G_d^-1 G_u] and P = [0; -G_d^-1 H]; projecting the linear
equations on N (N^T G^T = 0 removes the multipliers) gives

    N^T M N du_dot + N^T (M P + C) N du + N^T ((M P + C) P + K) dq = N^T dQ,

and the holonomic constraints Phi_q dq = 0 remove the dependent positions. The rows and columns
of the kept coordinates are the reduced equations M q_ddot + C q_dot + K q = f (f: the
generalized forces on the kept coordinates, N m for angles). Couplings to the other speeds and
positions must vanish there (checked: an ignorable position such as the heading, or the forward
speed of a bicycle, decouples from lean and steer to first order), else the kept set is named
as too small.

With the steady rates proportional to a speed v, C(v) = v C1 and K(v) = g K0 + v^2 K2 (the
benchmark bicycle's form, Meijaard et al. 2007): C and K are fitted exactly from three speeds
and the fit is verified at a fourth; terms outside the form (C0, K1) are reported, not dropped.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..derivation.equations import EquationsOfMotion
from ..errors import DerivationError, InputError, ModelError, did_you_mean
from ..kinds import CrossingKind
from ..model.model import velocity_name
from ..model.values import ParameterValues, resolve_parameters
from .linearization import LinearModel, state_matrix
from .steady import FIELD, steady_point

# Couplings below this (relative to the largest entry of the kept rows) are zero.
COUPLING_TOLERANCE = 1e-8
# The fitted C(v), K(v) must reproduce a fourth speed to this (relative).
FIT_TOLERANCE = 1e-7


def kept_linear_model(coordinates: Sequence[str], about: dict[str, float],
                      steady: dict[str, float], M: np.ndarray, C: np.ndarray,
                      K: np.ndarray) -> LinearModel:
    """The LinearModel M z_ddot + C z_dot + K z = 0 of the kept coordinates z about a steady
    motion (SI); z are the model's own coordinates, the others dropped (they decouple)."""
    p = len(coordinates)
    try:
        inverse = np.linalg.inv(M)
    except np.linalg.LinAlgError:
        raise DerivationError("the kept coordinates' mass matrix is singular on this steady "
                              "motion; the linear model has no state-space form") from None
    return LinearModel(
        equilibrium=dict(about), multipliers={}, coordinates=tuple(coordinates),
        user_coordinates=tuple(coordinates), basis=np.eye(p), mass_matrix=M, damping_matrix=C,
        stiffness_matrix=K, A=state_matrix(-inverse @ K, -inverse @ C), B=np.zeros((2 * p, 0)),
        input_matrix=np.zeros((p, 0)), full_mass_matrix=M, full_damping_matrix=C,
        full_stiffness_matrix=K, steady=dict(steady))


def _pivots(matrix: np.ndarray, count: int) -> list[int]:
    import scipy.linalg

    if count == 0 or matrix.shape[1] == 0:
        return []
    _, _, pivots = scipy.linalg.qr(matrix, pivoting=True, mode="economic")
    return sorted(int(i) for i in pivots[:count])


def reduced_steady_model(
    eom: EquationsOfMotion, about: Mapping[str, float] | None,
    steady: Mapping[str, float | str], keep: Sequence[str],
    parameters: Mapping[str, float] | ParameterValues | None = None,
) -> LinearModel:
    """The linear equations of the ``keep`` coordinates about the steady motion, with the
    constraints eliminated by a null-space basis of independent speeds (module docstring)."""
    model = eom.model
    names = [c.name for c in model.coordinates]
    n = len(names)
    keep = list(keep)
    if not keep:
        raise ModelError("name the coordinates to keep (e.g. phi, delta)", field="keep")
    for name in keep:
        if name not in names:
            raise ModelError(f"'{name}' is not a coordinate{did_you_mean(name, names)}",
                             field="keep")
    if len(set(keep)) != len(keep):
        raise ModelError("a coordinate is named twice", field="keep")
    point = steady_point(eom, about, steady, parameters)
    M, C, K, G, H = point.M, point.C, point.K, point.G, point.H
    k = G.shape[0]
    kept = [names.index(name) for name in keep]
    others = [i for i in range(n) if i not in kept]
    scale = max(1.0, float(np.abs(G).max(initial=0.0)))
    rank = int(np.sum(np.linalg.svd(G, compute_uv=False) > 1e-9 * scale)) if k else 0
    if rank < k:
        raise DerivationError("the constraints are redundant on this steady motion; the "
                              "independent speeds are not defined")
    dependent = [others[i] for i in _pivots(G[:, others], k)]
    independent = [i for i in range(n) if i not in dependent]
    order = kept + [i for i in independent if i not in kept]
    G_d = G[:, dependent]
    if k and np.linalg.cond(G_d) > 1e10:
        raise ModelError("the kept coordinates' rates are not independent speeds here: the "
                         "constraints fix them", field="keep")
    N = np.zeros((n, len(order)))
    N[order, np.arange(len(order))] = 1.0
    P = np.zeros((n, n))
    if k:
        N[dependent] = -np.linalg.solve(G_d, G[:, order])
        P[dependent] = -np.linalg.solve(G_d, H)
    mass = N.T @ M @ N
    damping = N.T @ (M @ P + C) @ N
    stiffness = N.T @ ((M @ P + C) @ P + K)
    # dependent positions from the holonomic constraints Phi_q dq = 0
    rows = G[list(point.holonomic)] if point.holonomic else np.zeros((0, n))
    basis = np.eye(n)
    if rows.shape[0]:
        fixed = [others[i] for i in _pivots(rows[:, others], rows.shape[0])]
        free = [i for i in range(n) if i not in fixed]
        basis = np.zeros((n, len(free)))
        basis[free, np.arange(len(free))] = 1.0
        basis[fixed] = -np.linalg.solve(rows[:, fixed], rows[:, free])
        stiffness = stiffness @ basis
        positions = free
    else:
        positions = list(range(n))
    p = len(kept)
    rows_scale = max(float(np.abs(mass[:p]).max()), float(np.abs(damping[:p]).max()),
                     float(np.abs(stiffness[:p]).max()), 1e-300)
    extra_speeds = list(range(p, len(order)))
    for column, what in ((mass, "acceleration"), (damping, "rate")):
        for j in extra_speeds:
            if np.abs(column[:p, j]).max(initial=0.0) > COUPLING_TOLERANCE * rows_scale:
                raise ModelError(
                    f"the kept coordinates' equations depend on the {what} of "
                    f"'{names[order[j]]}' (it does not decouple to first order): keep it too",
                    field="keep")
    kept_columns = [positions.index(i) for i in kept]
    for j, i in enumerate(positions):
        if i in kept:
            continue
        if np.abs(stiffness[:p, j]).max(initial=0.0) > COUPLING_TOLERANCE * rows_scale:
            raise ModelError(f"the kept coordinates' equations depend on the position of "
                             f"'{names[i]}': keep it too", field="keep")
    return kept_linear_model(
        tuple(keep), {name: float(v) for name, v in zip(names, point.q, strict=True)},
        {velocity_name(names[i]): float(point.q_dot[i]) for i in range(n) if point.q_dot[i] != 0},
        mass[:p, :p], damping[:p, :p], stiffness[:p][:, kept_columns])


@dataclass(frozen=True)
class SpeedForm:
    """M q_ddot + v C1 q_dot + (g K0 + v^2 K2) q = f about steady motion at speed v (SI).

    ``C0`` and ``K1`` hold the parts outside that form (zero for the benchmark bicycle);
    ``g`` is gravity's magnitude (1 where the model has none).
    """

    coordinates: tuple[str, ...]
    speed: str
    g: float
    M: np.ndarray
    C1: np.ndarray
    K0: np.ndarray
    K2: np.ndarray
    C0: np.ndarray
    K1: np.ndarray
    fit_error: float
    about: dict[str, float] = field(default_factory=dict)
    rates: dict[str, str] = field(default_factory=dict)

    def matrices(self, v: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(M, C, K) at speed v."""
        return (self.M, self.C0 + v * self.C1, self.g * self.K0 + v * self.K1 + v**2 * self.K2)

    def at(self, v: float) -> LinearModel:
        """The LinearModel of the kept coordinates at speed v (m/s)."""
        return kept_linear_model(self.coordinates, self.about, {}, *self.matrices(v))

    def state_matrix(self, v: float) -> np.ndarray:
        """A of x_dot = A x at speed v, x = [q; q_dot]."""
        return self.at(v).A

    def eigenvalues(self, v: float) -> np.ndarray:
        """Eigenvalues (1/s) at speed v, sorted by real part, largest first."""
        return self.at(v).eigenvalues()

    def __repr__(self) -> str:
        return (f"SpeedForm({list(self.coordinates)} at speed {self.speed}; g = {self.g:g})\n"
                f"M =\n{self.M}\nC1 =\n{self.C1}\nK0 =\n{self.K0}\nK2 =\n{self.K2}")


def speed_form(
    eom: EquationsOfMotion, about: Mapping[str, float] | None, steady: Mapping[str, str],
    speed: str, keep: Sequence[str],
    parameters: Mapping[str, float] | ParameterValues | None = None,
    speeds: Sequence[float] = (0.0, 2.0, 4.0, 5.0),
) -> SpeedForm:
    """Fit the reduced equations about steady motion at speed ``speed`` (a parameter the
    ``steady`` rates are written in, e.g. {"x_dot": "v", "thetaR_dot": "-v/rR"}) to
    M q_ddot + (C0 + v C1) q_dot + (g K0 + v K1 + v^2 K2) q = f; the first three speeds fit,
    the fourth checks."""
    model = eom.model
    if speed not in {p.name for p in model.parameters}:
        raise ModelError(f"'{speed}' is not a parameter of this model"
                         f"{did_you_mean(speed, [p.name for p in model.parameters])}",
                         field="speed")
    base = dict(parameters.as_dict() if isinstance(parameters, ParameterValues)
                else (parameters or {}))
    base.pop(speed, None)
    symbols = resolve_parameters(model, base, require=False).symbol_values(model)
    g = 1.0
    if model.gravity is not None:
        try:
            g = float(model.gravity.magnitude.xreplace(symbols))
        except (TypeError, ValueError):
            g = 1.0
    text = {name: str(value) for name, value in steady.items()}
    fitted = []
    for v in speeds:
        rates = {name: (value if not isinstance(value, str) else _at_speed(model, value, speed, v,
                                                                             base, name))
                 for name, value in steady.items()}
        fitted.append(reduced_steady_model(eom, about, rates, keep, base))
    (v0, v1, v2, v3) = speeds
    Ms = [r.M for r in fitted]
    Cs = [r.C for r in fitted]
    Ks = [r.K for r in fitted]
    # exact polynomial through three speeds: C linear, K quadratic
    C1 = (Cs[1] - Cs[0]) / (v1 - v0)
    C0 = Cs[0] - v0 * C1
    vander = np.array([[1.0, s, s * s] for s in (v0, v1, v2)])
    coefficients = np.linalg.solve(vander, np.stack([K.ravel() for K in Ks[:3]]))
    K0, K1, K2 = (c.reshape(Ks[0].shape) for c in coefficients)
    size = max(float(np.abs(Ks[3]).max()), float(np.abs(Cs[3]).max()), 1e-300)
    error = max(float(np.abs(C0 + v3 * C1 - Cs[3]).max()),
                float(np.abs(K0 + v3 * K1 + v3**2 * K2 - Ks[3]).max()),
                float(np.abs(C0 + v2 * C1 - Cs[2]).max()),
                max(float(np.abs(m - Ms[0]).max()) for m in Ms)) / size
    if error > FIT_TOLERANCE:
        raise ModelError(f"the reduced equations are not of the form C = C0 + v C1, K = K0 + "
                         f"v K1 + v^2 K2 in the speed '{speed}' (misfit {error:.3g}); are all "
                         "steady rates proportional to it?", field="speed")
    # round-off in place of an exact zero (C1[0, 0] of the bicycle is 1e-14 of C1's size)
    C1, K0, K2 = (np.where(np.abs(X) < 1e-13 * max(float(np.abs(X).max()), 1e-300), 0.0, X)
                  for X in (C1, K0, K2))
    size_C = max(float(np.abs(C1).max()), 1e-300)
    size_K = max(float(np.abs(K0).max()), float(np.abs(K2).max()), 1e-300)
    C0 = np.where(np.abs(C0) < 1e-12 * size_C, 0.0, C0)
    K1 = np.where(np.abs(K1) < 1e-12 * size_K, 0.0, K1)
    return SpeedForm(coordinates=tuple(keep), speed=speed, g=g, M=Ms[0], C1=C1, K0=K0 / g,
                     K2=K2, C0=C0, K1=K1, fit_error=error, about=fitted[0].equilibrium, rates=text)


def _at_speed(model, text: str, speed: str, v: float, base: Mapping[str, float],
              name: str) -> float:
    from .steady import _parameter_value  # noqa: PLC0415  (one parser for rate expressions)

    return _parameter_value(model, text, f"{FIELD}.{name}", {**base, speed: v})


@dataclass(frozen=True)
class Crossing:
    """A speed where an eigenvalue's real part crosses zero: ``kind`` "oscillatory" (a
    complex pair, frequency in rad/s) or "real"; ``stabilizing``: unstable below, stable above
    (for that eigenvalue)."""

    speed: float
    kind: CrossingKind
    frequency: float
    stabilizing: bool


@dataclass(frozen=True)
class SpeedSweep:
    """Eigenvalues against speed, the speeds where real parts cross zero and the stable range."""

    speeds: np.ndarray
    eigenvalues: np.ndarray  # (speeds, 2p), each row sorted by real part, largest first
    crossings: tuple[Crossing, ...]
    stable: tuple[tuple[float, float], ...]  # intervals of speed where every Re < 0

    def speed_of(self, kind: str, stabilizing: bool | None = None) -> float | None:
        """The first crossing of ``kind`` ("oscillatory": the weave speed of a bicycle; "real":
        its capsize speed), None where there is none."""
        if kind not in set(CrossingKind):
            raise InputError(f"expected one of {', '.join(CrossingKind)}, got {kind!r}",
                             field="kind")
        for c in self.crossings:
            if c.kind == kind and (stabilizing is None or c.stabilizing == stabilizing):
                return c.speed
        return None


def _unstable(form: SpeedForm, v: float, tolerance: float) -> int:
    return int(np.sum(form.eigenvalues(v).real > tolerance))


def _crossing(form: SpeedForm, a: float, b: float, k: int, xtol: float) -> float | None:
    """The speed in [a, b] where the (k+1)-th largest real part of the eigenvalues changes
    sign (a continuous function of the speed, positive where more than k eigenvalues grow):
    the exact weave or capsize speed, by Brent's method to about 1e-15 relative; None where it
    does not change sign in [a, b]."""
    import scipy.optimize

    def real_part(v: float) -> float:
        return float(form.eigenvalues(v).real[k])

    fa, fb = real_part(a), real_part(b)
    if fa == 0.0:
        return float(a)
    if fb == 0.0:
        return float(b)
    if fa * fb > 0:
        return None
    return float(scipy.optimize.brentq(real_part, a, b, xtol=min(xtol, 1e-15 * abs(b)),
                                       rtol=4 * np.finfo(float).eps, maxiter=200))


def speed_sweep(form: SpeedForm, speeds: Sequence[float], tolerance: float = 1e-9,
                xtol: float = 1e-12) -> SpeedSweep:
    """Eigenvalues at each speed; each change in the number of eigenvalues with Re > 0 between
    neighbouring speeds is located where a real part changes sign (Brent's method, to about
    1e-15 relative; by bisection of the count to ``xtol`` only where no real part does)."""
    speeds = np.asarray(speeds, dtype=float)
    table = np.array([form.eigenvalues(v) for v in speeds])
    counts = [_unstable(form, v, tolerance) for v in speeds]
    crossings = []
    for a, b, ca, cb in zip(speeds[:-1], speeds[1:], counts[:-1], counts[1:], strict=True):
        if ca == cb:
            continue
        at = _crossing(form, a, b, min(ca, cb), xtol)
        if at is None:  # no sign change of one real part: the count's change, by bisection
            lo, hi = a, b
            while hi - lo > xtol:
                mid = 0.5 * (lo + hi)
                if _unstable(form, mid, tolerance) == ca:
                    lo = mid
                else:
                    hi = mid
            at = 0.5 * (lo + hi)
        values = form.eigenvalues(at)
        nearest = values[np.argmin(np.abs(values.real))]
        oscillatory = abs(nearest.imag) > 1e-6
        crossings.append(Crossing(float(at), CrossingKind.OSCILLATORY if oscillatory else CrossingKind.REAL,
                                  float(abs(nearest.imag)), cb < ca))
    stable = []
    start = None
    for v, count in zip(speeds, counts, strict=True):
        if count == 0 and start is None:
            start = v
        if count != 0 and start is not None:
            stable.append((start, v))
            start = None
    if start is not None:
        stable.append((start, float(speeds[-1])))
    # refine the ends of the stable intervals to the crossings found
    refined = []
    points = [c.speed for c in crossings]
    for lo, hi in stable:
        below = [p for p in points if p <= lo]
        above = [p for p in points if p > lo]
        refined.append((max(below) if below else float(lo), min(above) if above else float(hi)))
    return SpeedSweep(speeds, table, tuple(crossings), tuple(refined))


__all__ = ["Crossing", "kept_linear_model", "SpeedForm", "SpeedSweep", "reduced_steady_model",
           "speed_form", "speed_sweep"]


def speed_study_chunk(eom: EquationsOfMotion, values: Mapping[str, np.ndarray], count: int,
                      cache: dict) -> dict[str, np.ndarray]:
    """A parameter study of the model's steady motion ([steady] table): at each point the
    eigenvalues (1/s) of the reduced equations at the point's speed, sorted by real part
    (largest first), and whether none grows. ``values`` maps varied names to per-point values;
    one SpeedForm is fitted per combination of the other parameters (kept in ``cache``)."""
    steady = eom.model.steady_motion
    if steady is None:
        raise ModelError("a study of speeds needs the model's [steady] table (its speed "
                         "parameter, steady rates and kept coordinates)", field="compute")
    defaults = {p.name: p.value for p in eom.model.parameters}
    size = 2 * len(steady.keep)
    real = np.full((count, size), np.nan)
    imag = np.full((count, size), np.nan)
    stable = np.full(count, np.nan)
    status = np.full(count, "ok", dtype=object)
    others = sorted(name for name in values if name != steady.speed)
    for i in range(count):
        point = {name: float(values[name][i]) for name in values}
        speed_value = point.get(steady.speed, defaults.get(steady.speed))
        key = tuple(point[name] for name in others)
        try:
            form = cache.get(key)
            if form is None:
                base = {name: point[name] for name in others}
                form = speed_form(eom, dict(steady.about) or None, dict(steady.rates),
                                  steady.speed, list(steady.keep), base)
                cache[key] = form
            if speed_value is None:
                raise ModelError(f"the speed '{steady.speed}' has no value", field="vary")
            eigenvalues = form.eigenvalues(float(speed_value))
        except (ModelError, np.linalg.LinAlgError, ValueError, ArithmeticError) as exc:
            status[i] = str(exc).splitlines()[0] or type(exc).__name__
            continue
        real[i], imag[i] = eigenvalues.real, eigenvalues.imag
        scale = max(float(np.abs(eigenvalues).max(initial=0.0)), 1e-300)
        stable[i] = float(not np.any(eigenvalues.real > 1e-9 * scale))
    return {"eigenvalue_real": real, "eigenvalue_imag": imag, "stable": stable,
            "status": status}
