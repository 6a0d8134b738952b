"""Equilibria: configurations where the system can stay at rest, f(q, 0) = Phi_q^T lambda, Phi(q) = 0.

Found by Newton's method (minimum-norm steps, batched over many starting points spread over
the coordinates' ranges); angles that differ by 2 pi are one equilibrium when the model is
periodic in them. Stability is linear: no mode of the linearized motion grows.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..compile.at_rest import AtRestFunctions
from ..errors import ModelError
from ..model.model import Model
from ..model.rotations import gimbal_lock
from ..model.values import State, resolve_state
from .linearization import static_residual, total_stiffness

MAX_ITERATIONS = 80
# Residual relative to the force scale of the model at which Newton has converged.
RESIDUAL_TOLERANCE = 1e-9
# Relative distance below which two equilibria are one.
SAME_TOLERANCE = 1e-6
# A given equilibrium may be off by this much (relative) in the given coordinates: refined.
ACCEPT_MOVE = 1e-6


@dataclass(frozen=True)
class Equilibrium:
    """A configuration of rest (SI), its multipliers (constraint reactions) and its stability."""

    coordinates: dict[str, float]
    multipliers: dict[str, float]
    stable: bool
    neutral: tuple[str, ...] = ()

    def __repr__(self) -> str:
        where = ", ".join(f"{k}={v:.6g}" for k, v in self.coordinates.items())
        state = "stable" if self.stable else "unstable"
        return f"Equilibrium({where}; {state})"


@dataclass(frozen=True)
class Equilibria:
    """The equilibria of a model at given parameter values, each once."""

    model_name: str
    coordinates: tuple[str, ...]
    constraints: tuple[str, ...]
    equilibria: tuple[Equilibrium, ...]
    # Configurations of rest where a body's rotation sequence is singular (gimbal lock): the
    # forces balance only because the angles lose a direction there, so no stability is claimed.
    singular: tuple[dict[str, float], ...] = ()

    def __iter__(self):
        return iter(self.equilibria)

    def __len__(self) -> int:
        return len(self.equilibria)

    def __getitem__(self, index: int) -> Equilibrium:
        return self.equilibria[index]

    def __repr__(self) -> str:
        lines = [f"Equilibria of {self.model_name!r}:"]
        lines += [f"  {e!r}" for e in self.equilibria] or ["  (none found)"]
        return "\n".join(lines)


# -- the search ---------------------------------------------------------------------------------


@dataclass
class _Solver:
    """Batched Newton on [f(q, 0) - Phi_q^T lambda; Phi(q)] = 0 over (q, lambda)."""

    functions: AtRestFunctions
    t: float
    force_scale: float

    def residual(self, q: np.ndarray, lam: np.ndarray) -> np.ndarray:
        return static_residual(self.functions.evaluate(q, self.t), lam)

    def solve(self, q: np.ndarray, lam: np.ndarray, free: np.ndarray,
              step_limit: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Newton from each row of q (batch, n); only coordinates where ``free`` move.
        Returns (q, lambda, converged)."""
        q, lam = q.copy(), lam.copy()
        k = int(free.sum())
        settled = np.zeros(q.shape[:-1], dtype=bool)
        for _ in range(MAX_ITERATIONS):
            values = self.functions.evaluate(q, self.t)
            residual = static_residual(values, lam)
            jacobian = self._jacobian(values, lam)[..., self._columns(free)]
            step = _newton_step(jacobian, residual)
            dq = np.zeros_like(q)
            dq[..., free] = step[..., :k]
            # A full Newton step can jump across the configuration space: limit its size.
            ratio = np.max(np.abs(dq) / step_limit, axis=-1, keepdims=True)
            scale = np.where(ratio > 1.0, 1.0 / np.maximum(ratio, 1e-300), 1.0)
            scale = np.where(settled[..., None], 0.0, scale)
            q = q + scale * dq
            lam = lam + scale * step[..., k:]
            # Iterate until the steps stop changing anything: machine precision, also at
            # singular points where Newton converges only linearly.
            settled |= np.all(np.abs(dq) <= 1e-14 * (1 + np.abs(q)), axis=-1)
            if settled.all():
                break
        size = np.linalg.norm(self.residual(q, lam), axis=-1)
        return q, lam, size <= RESIDUAL_TOLERANCE * self.force_scale

    def _columns(self, free: np.ndarray) -> np.ndarray:
        return np.concatenate([free, np.ones(self.functions.m, dtype=bool)])

    def _jacobian(self, values: dict[str, np.ndarray], lam: np.ndarray) -> np.ndarray:
        """d(residual)/d(q, lambda): [[-K, -Phi_q^T], [S_q, 0]]."""
        stiffness = total_stiffness(values, lam)
        jac_t = np.swapaxes(values["jacobian"], -1, -2)
        static_q = values["static_jacobian"]
        batch = stiffness.shape[:-2]
        s, m = static_q.shape[-2], jac_t.shape[-1]
        top = np.concatenate([-stiffness, -jac_t], axis=-1)
        bottom = np.concatenate([static_q, np.zeros(batch + (s, m))], axis=-1)
        return np.concatenate([top, bottom], axis=-2)


def _newton_step(jacobian: np.ndarray, residual: np.ndarray) -> np.ndarray:
    """-J^+ r for each point: an LU solve where J is square and regular, else the minimum-norm
    least-squares step (neutral directions do not move, redundant equations are fine). A point
    whose J or r is not finite (outside the model's domain) gets a NaN step: it is dropped as
    not converged instead of stopping LAPACK for every point."""
    finite = np.all(np.isfinite(jacobian), axis=(-2, -1)) & np.all(np.isfinite(residual), axis=-1)
    if not finite.all():
        step = np.full(residual.shape[:-1] + (jacobian.shape[-1],), np.nan)
        if finite.any():
            step[finite] = _newton_step(jacobian[finite], residual[finite])
        return step
    rows, columns = jacobian.shape[-2:]
    if rows == columns:
        try:
            step = -np.linalg.solve(jacobian, residual[..., None])[..., 0]
            if np.all(np.isfinite(step)):
                return step
        except np.linalg.LinAlgError:
            pass
        batch = jacobian.reshape(-1, rows, columns)
        flat = residual.reshape(-1, rows)
        steps = np.empty_like(flat)
        for i, (matrix, r) in enumerate(zip(batch, flat, strict=True)):
            try:
                steps[i] = -np.linalg.solve(matrix, r)
                if np.all(np.isfinite(steps[i])) and \
                        np.linalg.cond(matrix) < 1e12:
                    continue
            except np.linalg.LinAlgError:
                pass
            steps[i] = -np.linalg.pinv(matrix, rcond=1e-12) @ r
        return steps.reshape(residual.shape[:-1] + (columns,))
    return -np.einsum("...ij,...j->...i", np.linalg.pinv(jacobian, rcond=1e-12), residual)


def initial_multipliers(values: dict[str, np.ndarray]) -> np.ndarray:
    """lambda minimizing |f - Phi_q^T lambda| at each configuration."""
    jac_t = np.swapaxes(values["jacobian"], -1, -2)
    return np.einsum("...ij,...j->...i", np.linalg.pinv(jac_t, rcond=1e-12), values["forcing"])


def coordinate_spans(model: Model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(low, high, periodic) per coordinate: its range, else [-pi, pi] for angles and a span
    around the initial value sized by the model's length parameters for the others."""
    lengths = [abs(p.value) for p in model.parameters
               if p.value is not None and p.unit in ("m", "meter", "metre")]
    length = max([*lengths, 0.1])
    low, high, periodic = [], [], []
    initial = resolve_state(model).q  # the model's initial values
    for c, centre in zip(model.coordinates, initial, strict=True):
        if c.range is not None:
            lo, hi = c.range
        elif c.is_angle:
            lo, hi = -np.pi, np.pi
        else:
            half = 2.0 * max(length, abs(centre))
            lo, hi = centre - half, centre + half
        low.append(lo)
        high.append(hi)
        periodic.append(c.is_angle)
    return np.array(low, float), np.array(high, float), np.array(periodic, bool)


def starting_points(model: Model, free: np.ndarray) -> np.ndarray:
    """The initial values, zero, and points spread over the spans (a grid for 1-2 free
    coordinates, a scrambled Sobol sequence beyond)."""
    low, high, _ = coordinate_spans(model)
    n = len(model.coordinates)
    initial = resolve_state(model).q_array()  # the model's initial values
    points = [initial, np.where(free, 0.0, initial)]
    k = int(free.sum())
    if k:
        if k <= 2:
            per_axis = 9 if k == 1 else 7
            axes = [np.linspace(0, 1, per_axis) for _ in range(k)]
            unit = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, k)
        else:
            from scipy.stats import qmc

            unit = qmc.Sobol(d=k, scramble=True, seed=7).random(64)
        for u in unit:
            point = initial.copy()
            point[free] = low[free] + u * (high[free] - low[free])
            points.append(point)
    return np.array(points, float).reshape(-1, n)


def neutral_coordinates(functions: AtRestFunctions) -> np.ndarray:
    """Coordinates the equations of rest do not contain: any value is an equilibrium."""
    return np.array([c.symbol not in functions.depends_on for c in functions.model.coordinates],
                    dtype=bool)


def force_scale(functions: AtRestFunctions, points: np.ndarray, t: float) -> float:
    """A typical size of the generalized forces over the starting points (for tolerances)."""
    low, high, _ = coordinate_spans(functions.model)
    values = functions.evaluate(points, t)
    lam = initial_multipliers(values)
    span = np.abs(high - low)
    sizes = (np.linalg.norm(values["forcing"], axis=-1)
             + np.linalg.norm(np.einsum("...ij,j->...i", total_stiffness(values, lam), span),
                              axis=-1)
             + np.linalg.norm(values["static_jacobian"] @ span, axis=-1))
    scale = float(np.median(sizes))
    return scale if scale > 0 else 1e-300


def find_equilibria(
    functions: AtRestFunctions, *, t: float = 0.0, stability=None,
) -> Equilibria:
    """All equilibria found from the starting points, each once, sorted by coordinates.

    ``stability(q, lambda) -> bool`` decides stability (the modes module provides it).
    """
    # Starting points and Newton's trials may leave the model's domain (a square root of a
    # negative number): those points are dropped as not converged, without numpy's warnings.
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return _find_equilibria(functions, t, stability)


def _find_equilibria(functions: AtRestFunctions, t: float, stability) -> Equilibria:
    model = functions.model
    neutral = neutral_coordinates(functions)
    free = ~neutral
    points = starting_points(model, free)
    scale = force_scale(functions, points, t)
    solver = _Solver(functions, t, scale)
    low, high, _ = coordinate_spans(model)
    periodic = periodic_coordinates(functions, t)
    limit = np.where(periodic, 1.0, np.maximum(np.abs(high - low) / 4, 1e-12))
    lam = initial_multipliers(functions.evaluate(points, t))
    q, lam, converged = solver.solve(points, lam, free, limit)
    found: list[tuple[np.ndarray, np.ndarray]] = []
    singular: list[np.ndarray] = []
    values = {sp.Symbol(k): v for k, v in functions.parameters.items()}
    for qi, li in zip(q[converged], lam[converged], strict=True):
        qi = _wrap(qi, periodic, low)
        if not _inside(qi, low, high, model, periodic):
            continue
        chart_singular = getattr(functions, "chart_singular", None)  # a tree's Euler angles
        if (chart_singular is not None and chart_singular(qi)) or (model.rigid_bodies and gimbal_lock(
                model.rigid_bodies, {**values, **dict(zip(model.q, qi, strict=True))}, 1e-6)):
            if not any(_same(qi, other, periodic, low, high) for other in singular):
                singular.append(qi)
            continue
        same_configuration = getattr(functions, "same_configuration", None)
        if any(_same(qi, other, periodic, low, high)
               or (same_configuration is not None and same_configuration(qi, other))
               for other, _ in found):
            continue
        found.append((qi, li))
    found.sort(key=lambda item: tuple(np.round(item[0], 9)))
    names = tuple(c.name for c in model.coordinates)
    neutral_names = tuple(n for n, flag in zip(names, neutral, strict=True) if flag)
    equilibria = tuple(
        Equilibrium(
            coordinates={n: _clean(v) for n, v in zip(names, qi, strict=True)},
            multipliers={c.name: _clean(v) for c, v in zip(model.constraints, li, strict=True)},
            stable=bool(stability(qi, li)) if stability else False,
            neutral=neutral_names,
        )
        for qi, li in found
    )
    singular.sort(key=lambda item: tuple(np.round(item, 9)))
    return Equilibria(model.name, names, tuple(c.name for c in model.constraints), equilibria,
                      tuple({n: _clean(v) for n, v in zip(names, qi, strict=True)}
                            for qi in singular))


def resolve_equilibrium(
    functions: AtRestFunctions, about: Mapping[str, float] | State | None, *, t: float = 0.0,
    option: str = "about",
) -> tuple[np.ndarray, np.ndarray]:
    """The equilibrium (q, lambda) given by ``about`` (checked to be one; coordinates not given
    are solved for), or, without ``about``, the equilibrium nearest the model's initial values."""
    model = functions.model
    names = [c.name for c in model.coordinates]
    state = resolve_state(model, about, field=option, velocities=False, time=False)
    about = {n: q for n, q in zip(names, state.q, strict=True) if n in state.given}
    low, high, _ = coordinate_spans(model)
    periodic = periodic_coordinates(functions, t)
    initial = resolve_state(model).q_array()  # the model's initial values
    if not about:
        found = find_equilibria(functions, t=t)
        if not len(found):
            raise ModelError("no equilibrium found (the forces at rest balanced at none of the "
                             "configurations searched); name one to analyse about")
        q_all = np.array([[e.coordinates[n] for n in names] for e in found])
        distance = [_distance(qi, initial, periodic) for qi in q_all]
        best = int(np.argmin(distance))
        q = q_all[best]
        lam = np.array([found[best].multipliers[c.name] for c in model.constraints], float)
        return q, lam

    given = np.array([n in about for n in names])
    q = initial.copy()
    for i, n in enumerate(names):
        if n in about:
            q[i] = float(about[n])
    points = np.concatenate([q[None], starting_points(model, ~given)[1:]])
    points[:, given] = q[given]
    # the forces' size over the search's own starting points too, so that a rest that
    # find_equilibria returned (to its tolerance) is taken back as one
    scale = max(force_scale(functions, points, t),
                force_scale(functions, starting_points(model, np.ones(len(names), bool)), t))
    solver = _Solver(functions, t, scale)
    limit = np.where(periodic, 1.0, np.maximum(np.abs(high - low) / 4, 1e-12))
    everything = np.ones(len(names), bool)
    lam = initial_multipliers(functions.evaluate(q, t))

    def polished(q_start, lam_start):
        """Newton with every coordinate free; accepted if the given values barely move."""
        q2, lam2, ok2 = solver.solve(q_start[None], lam_start[None], everything, limit)
        moved = np.abs(q2[0] - q)[given]
        if ok2[0] and np.all(moved <= ACCEPT_MOVE * (1 + np.abs(q[given]))):
            return np.vectorize(_clean)(q2[0]), lam2[0]
        return None

    q1, lam1, ok = solver.solve(q[None], lam[None], ~given, limit)
    candidates = [(q1[0], lam1[0])]
    if not ok[0] and (~given).any():
        # Other starting values for the coordinates not given, nearest first.
        lams = initial_multipliers(functions.evaluate(points, t))
        qs, ls, oks = solver.solve(points, lams, ~given, limit)
        order = sorted(np.flatnonzero(oks), key=lambda i: _distance(qs[i], q, periodic))
        candidates += [(qs[i], ls[i]) for i in order[:5]]
    for q_start, lam_start in candidates:
        result = polished(q_start, lam_start)
        if result is not None:
            return result
    if ok[0]:  # balanced as given, where polishing slides along a family of rests (a ball
        # turning about the vertical: Newton's step is free along it)
        return np.vectorize(_clean)(q1[0]), lam1[0]
    given_text = ", ".join(f"{n}={about[n]:.6g}" for n in names if n in about)
    hint = ""
    nearby = solver.solve(q[None], lam[None], np.ones(len(names), bool), limit)
    if nearby[2][0]:
        near = ", ".join(f"{n}={_clean(v):.6g}" for n, v in zip(names, nearby[0][0], strict=True))
        hint = f"; the nearest equilibrium is at {near}"
    raise ModelError(f"{given_text} is not an equilibrium: "
                     f"{_why_not(functions, q, ~given, t)}{hint}", field=option)


def _why_not(functions: AtRestFunctions, q: np.ndarray, free: np.ndarray, t: float) -> str:
    """Which balance fails at q: first meet the constraints moving only the free coordinates,
    then report the largest unbalanced generalized force (or the violated constraint)."""
    names = [c.name for c in functions.model.coordinates]
    q = q.copy()
    for _ in range(50):
        values = functions.evaluate(q, t)
        if not values["static"].size:
            break
        step = -np.linalg.pinv(values["static_jacobian"][:, free], rcond=1e-12) @ values["static"]
        q[free] += step
        if np.all(np.abs(step) <= 1e-14 * (1 + np.abs(q[free]))):
            break
    values = functions.evaluate(q, t)
    if values["static"].size:
        worst = int(np.argmax(np.abs(values["static"])))
        if abs(values["static"][worst]) > 1e-9 * (1 + np.abs(q).max()):
            return (f"it violates constraint '{functions.static_names[worst]}' "
                    f"(residual {values['static'][worst]:.4g})")
    force = static_residual(values, initial_multipliers(values))[: len(names)]
    worst = int(np.argmax(np.abs(force)))
    return (f"the forces at rest do not balance (residual {force[worst]:.4g} on "
            f"{names[worst]})")


# -- helpers ------------------------------------------------------------------------------------


def _wrap(q: np.ndarray, periodic: np.ndarray, low: np.ndarray) -> np.ndarray:
    """Bring periodic angles into [low, low + 2 pi)."""
    wrapped = q.copy()
    wrapped[periodic] = low[periodic] + np.mod(q[periodic] - low[periodic], 2 * np.pi)
    # The upside-down angle reads better as +pi than as -pi.
    flip = periodic & (low < 0) & np.isclose(wrapped, low, rtol=0, atol=1e-9)
    wrapped[flip] += 2 * np.pi
    return wrapped


def periodic_coordinates(functions: AtRestFunctions, t: float = 0.0) -> np.ndarray:
    """Angles in which the equations of rest repeat after 2 pi (checked at random points)."""
    low, high, periodic = coordinate_spans(functions.model)
    rng = np.random.default_rng(3)
    points = low + rng.random((3, functions.n)) * (high - low)
    base = functions.evaluate(points, t)
    result = periodic.copy()
    for i in np.flatnonzero(periodic):
        shifted = points.copy()
        shifted[:, i] += 2 * np.pi
        other = functions.evaluate(shifted, t)
        result[i] = all(np.allclose(base[k], other[k], rtol=1e-9, atol=1e-12)
                        for k in ("forcing", "static", "jacobian"))
    return result


def _inside(q, low, high, model, periodic) -> bool:
    margin = 1e-9 * (1 + np.abs(high - low))
    for i, c in enumerate(model.coordinates):
        if c.range is None:
            continue
        if q[i] < low[i] - margin[i] or q[i] > high[i] + margin[i]:
            return False
    return True


def _distance(a: np.ndarray, b: np.ndarray, periodic: np.ndarray) -> float:
    return float(np.linalg.norm(_difference(a, b, periodic)))


def _difference(a, b, periodic) -> np.ndarray:
    """|a - b| per coordinate, angles measured the short way round."""
    d = np.abs(a - b)
    wrapped = np.mod(d, 2 * np.pi)
    return np.where(periodic, np.minimum(wrapped, 2 * np.pi - wrapped), d)


def _same(a, b, periodic, low, high) -> bool:
    size = np.maximum(np.abs(high - low), 1e-12)
    return bool(np.all(_difference(a, b, periodic) <= SAME_TOLERANCE * (1 + size)))


def _clean(value: float) -> float:
    """Round off the last bits of noise (1e-17 instead of 0) for a readable report."""
    value = float(value)
    return 0.0 if abs(value) < 1e-12 else value
