"""Simulation through impacts: each guard crossing located (to about 1e-12 s), the derived impact
map applied (derivation/impact_map.py), and the run goes on; an accumulation of impacts (a ball
coming to rest) is detected and ends the run, or settles it where the user asks.

The flow between impacts is simulate's scipy step loop; a guard g(q, t) of the model's
[[impacts]] fires when it falls through 0 (the event max_i(-g_i) turning >= 0), the crossing is
found by the dense output (brentq) and polished by Newton steps of the guard along the flow.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace

import numpy as np
import sympy as sp

from ..compile.functions import NumericSystem, numeric
from ..compile.lambdified import StateFunction
from ..derivation.equations import EquationsOfMotion
from ..derivation.impact_map import ImpactMap, derive_impact_maps
from ..errors import InputError
from ..kinds import InvariantKind
from ..model.values import resolve_parameters, resolve_state
from .integration_loops import integrate_steps
from .invariants import cumulative_work, energy_is_conserved, invariant_kind
from .options import SaveAt, StepControl
from .relabel_check import RelabelCheck
from .result import STATUS_MESSAGES, SimulationResult

ACCUMULATED = "accumulated"  # impacts accumulate (Zeno): the run stops at their limit time
IMPACT_LIMIT = "impact_limit"  # the cap on the number of impacts was reached
SETTLED = "settled"  # impacts accumulated and the model was put to rest on the surface
HYBRID_STATUS = {ACCUMULATED: "impacts accumulate (the motion comes to rest on a surface)",
                 IMPACT_LIMIT: "stopped at the cap on the number of impacts",
                 SETTLED: "impacts accumulated and the model rests on the surface"}
STATUS_MESSAGES.update(HYBRID_STATUS)
MAX_IMPACTS = 1000
DEFAULT_STEPS, DEFAULT_SAMPLES = StepControl(), SaveAt()  # as simulate's
# Impacts accumulate when the last intervals between them shrink geometrically (two ratios
# agreeing to this) and what is left of the series, dt r / (1 - r), is below ACCUMULATION_TIME.
RATIO_AGREEMENT = 1e-3
ACCUMULATION_TIME = 1e-9  # s
# ... or when an interval is below this (times max(1, t)): no longer resolved in time.
SHORTEST_INTERVAL = 1e-13
APPROACH_TOLERANCE = 1e-9  # a normal velocity before the impact above this (relative) leaves
ON_GUARD = 1e-9  # |g| below which a piece starts on a guard (just after its impact)


@dataclass(frozen=True)
class ImpactRecord:
    """One impact: its time (s), name, state before and after (by name, SI), the impulse on
    the model at the striking point (N s, world axes), the kinetic energy lost (J) and the
    residual of the law on the striking point's velocity after it (m/s)."""

    time: float
    name: str
    before: dict[str, float]
    after: dict[str, float]
    impulse: tuple[float, ...]
    energy_lost: float
    residual: float

    def to_dict(self) -> dict:
        return {"t": self.time, "name": self.name, "before": self.before, "after": self.after,
                "impulse": list(self.impulse), "energy_lost": self.energy_lost,
                "residual": self.residual}


@dataclass(frozen=True, repr=False)
class HybridResult(SimulationResult):
    """A SimulationResult through impacts: ``impacts`` lists each (ImpactRecord) in order;
    ``accumulation_time`` the limit time of accumulating impacts (s) where they did."""

    impacts: tuple[ImpactRecord, ...] = field(default=())
    accumulation_time: float | None = None
    # where the model's pivot is at each sample (N, 2 or 3; m, the model's axes): the released
    # pivots' striking points added up (a walker's way down its slope); None without release
    pivot_offsets: np.ndarray | None = None


class CompiledImpact:
    """An ImpactMap in numbers (parameter values put in): apply(q, v, t) -> (q+, v+, record
    parts); functions of (q, q_dot, t)."""

    def __init__(self, model, impact_map: ImpactMap, substitution: Mapping):
        self.map = impact_map
        self.name = impact_map.name
        self.k = impact_map.extension
        self.size = impact_map.mass_matrix.shape[0]
        self.rows = impact_map.jacobian.shape[0]
        m = impact_map
        parts = [*m.mass_matrix, *m.jacobian, *m.restitution_matrix, *m.point_velocity,
                 *m.normal, *m.relabelled, *m.relabel_jacobian]
        self._shapes = [m.mass_matrix.shape, m.jacobian.shape, m.restitution_matrix.shape,
                        m.point_velocity.shape, m.normal.shape, m.relabelled.shape,
                        m.relabel_jacobian.shape]
        self._parts = StateFunction(model, parts, substitution)
        d = m.normal.shape[0]
        self._point = StateFunction(model, list(m.impact.point[:d]), substitution)
        e = float(sp.sympify(m.impact.restitution).xreplace(substitution))  # safe: parsed
        if not 0 <= e <= 1:
            raise InputError(f"impact '{self.name}': the restitution is {e:g}, outside [0, 1]",
                             field="parameters")
        if m.extension and e != 0:
            raise InputError(f"impact '{self.name}': a released pivot needs restitution 0, "
                             f"got {e:g}", field="parameters")
        self.restitution = e
        relabels = bool(m.impact.relabel) or bool(m.extension)
        self._geometry = RelabelCheck(model, m, substitution) if relabels else None

    def striking_point(self, q, t) -> np.ndarray:
        """r(q) of the striking point (m, the model's axes)."""
        return self._point.at(q, np.zeros(len(q)), t)

    def matrices(self, q, v, t):
        """M, J, E, the point's velocity rows P, n, R(q), dR/dq at one state."""
        flat = self._parts.at(q, v, t)
        out, start = [], 0
        for rows, cols in self._shapes:
            out.append(flat[start:start + rows * cols].reshape(rows, cols))
            start += rows * cols
        return out

    def apply(self, q, v, t):
        """(q+, v+, impulse, energy lost, residual, extended velocities before and after)."""
        if self._geometry is not None:
            self._geometry(q, t)
        M, J, E, P, n, R, DR = self.matrices(q, v, t)
        ve = np.concatenate([np.zeros(self.k), v])
        approach = float(n[:, 0] @ P @ ve)  # the point's normal velocity before (m/s)
        if approach > APPROACH_TOLERANCE * max(1.0, float(np.max(np.abs(P @ ve)))):
            raise InputError(f"impact '{self.name}' at t = {t:.12g} s: its guard falls through 0 "
                             f"while the striking point leaves the surface (normal velocity "
                             f"{approach:.6g} m/s): the guard, the point or the normal disagree",
                             field="impacts")
        solution = solve_impact(M, J, E, ve, f"impact '{self.name}' at t = {t:.12g} s")
        after = solution[:self.size]
        impulse_rows = solution[self.size:]
        impulse = impulse_rows if J.shape[0] == P.shape[0] else impulse_rows[0] * n[:, 0]
        lost = 0.5 * float(ve @ M @ ve - after @ M @ after)
        residual = float(np.max(np.abs(J @ after + E @ (J @ ve)))) if len(J) else 0.0
        return R[:, 0], DR @ after[self.k:], impulse, lost, residual, ve, after


def solve_impact(M, J, E, v_before, where: str) -> np.ndarray:
    """[q_dot+; Lambda] from the impact equations; rows of J that repeat others (a stick
    law's tangential row along a velocity the point cannot have) are allowed, a velocity the
    equations leave free (M singular where J does not hold it) is refused."""
    kkt, rhs = kkt_system(M, J, E, v_before)
    try:
        with np.errstate(all="ignore"):
            values = np.linalg.svd(kkt, compute_uv=False)
            rows = np.linalg.svd(J, compute_uv=False) if J.size else np.zeros(0)
            solution = np.linalg.lstsq(kkt, rhs, rcond=None)[0]
    except np.linalg.LinAlgError:
        values, rows, solution = np.zeros(1), np.zeros(0), None
    top = float(values.max(initial=0.0))
    rank = int(np.sum(values > 1e-11 * top)) if top > 0 else 0
    independent = int(np.sum(rows > 1e-11 * max(float(rows.max(initial=0.0)), 1e-300)))
    if solution is None or not np.all(np.isfinite(solution)) or rank < len(M) + independent:
        raise InputError(f"{where}: the impact equations are singular (the mass matrix is "
                         "singular where the law leaves the point free)", field="impacts")
    if np.max(np.abs(kkt @ solution - rhs), initial=0.0) > \
            1e-8 * max(1.0, float(np.max(np.abs(rhs)))):
        raise InputError(f"{where}: the impact equations have no solution", field="impacts")
    return solution


def kkt_system(M, J, E, v_before):
    """[[M, -J^T], [J, 0]] and [M v-; -E J v-]: the impact equations (docstring above)."""
    k = J.shape[0]
    kkt = np.block([[M, -J.T], [J, np.zeros((k, k))]])
    rhs = np.concatenate([M @ v_before, -E @ (J @ v_before)])
    return kkt, rhs


class Guards:
    """The guards g_i(q, t) and their rates dg_i/dt = grad g . q_dot + dg/dt, as numbers."""

    def __init__(self, model, maps, substitution):
        t = model.time
        gs = [m.guard for m in maps]
        rates = [sp.Add(*(g.diff(s) * c.velocity for s, c in zip(model.q, model.coordinates,
                                                                   strict=True)), g.diff(t))
                 for g in gs]
        self.values = StateFunction(model, gs, substitution)
        self.rates = StateFunction(model, rates, substitution)

    def event(self, q, v, t) -> float:
        """max_i(-g_i): turns >= 0 when a guard falls through 0."""
        return float(np.max(-self.values.at(q, v, t)))

    def leaving(self, q, v, t, struck: int | None = None):
        """(event, offsets) for a piece of the flow starting at (q, v, t): a guard on its zero
        there (|g| < ON_GUARD; the one just crossed) counts from its value there, so its
        rounding (+-1e-17) neither fires it at once nor hides the next crossing; it must rise
        above that value before it can fall through it."""
        values = self.values.at(q, v, t)
        on = np.abs(values) < ON_GUARD
        if struck is not None:  # only the guard just struck: another near 0 strikes as it falls
            on &= np.arange(len(values)) == struck
        offsets = np.where(on, values, 0.0)
        # The event is 0 at the start (the guards just struck, on their offsets), so the loop
        # arms it only after a step: another guard falling through 0 within that first step
        # went unseen (a tumbling rod's other end through the floor). Where the guards just
        # struck rise at once, the start reads as the other guards' value alone (below 0:
        # armed). One that falls first (a walker's scuffing swing foot) still has to rise
        # above its value before it can strike.
        others = ~on
        start = t if others.any() and np.all(self.rates.at(q, v, t)[on] > 0) else None

        def event(q, v, t) -> float:
            terms = offsets - self.values.at(q, v, t)
            return float(np.max(terms[others] if t == start else terms))

        return event, offsets


def polish(guards: Guards, index: int, functions: NumericSystem, t: float, y: np.ndarray,
           n: int) -> tuple[float, np.ndarray]:
    """Newton steps on g_index along the flow (an RK4 step of the correction each time):
    the crossing to about 1e-12 s."""
    for _ in range(4):
        g = guards.values.at(y[:n], y[n:], t)[index]
        rate = guards.rates.at(y[:n], y[n:], t)[index]
        if rate == 0 or not math.isfinite(g / rate):
            break
        dt = -g / rate
        if abs(dt) > 1e-6 * max(1.0, abs(t)):
            break  # brentq was already close; a large step means a graze: keep its time
        y = _rk4(functions, t, y, dt)
        t += dt
        if abs(dt) < 1e-15 * max(1.0, abs(t)):
            break
    return t, y


def _rk4(functions, t, y, h):
    f = functions.rhs
    k1 = f(t, y)
    k2 = f(t + h / 2, y + h / 2 * k1)
    k3 = f(t + h / 2, y + h / 2 * k2)
    k4 = f(t + h, y + h * k3)
    return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def compiled_impacts(eom: EquationsOfMotion, substitution, maps=None):
    """(CompiledImpact for each impact, Guards) at the parameter values."""
    maps = maps if maps is not None else derive_impact_maps(eom)
    return [CompiledImpact(eom.model, m, substitution) for m in maps], \
        Guards(eom.model, maps, substitution)


def simulate_through_impacts(
    eom: EquationsOfMotion, t_end: float, *, initial=None, parameters=None,
    step_control: StepControl = DEFAULT_STEPS, save_at: SaveAt = DEFAULT_SAMPLES,
    progress: Callable[[float], None] | None = None, functions: NumericSystem | None = None,
    max_impacts: int = MAX_IMPACTS, settle: bool = False, maps=None, **unused,
) -> HybridResult:
    """Integrate ``eom`` from its start to ``t_end`` (s) through its model's impacts: each
    located, mapped and listed; accumulating impacts end the run (status 'accumulated') or,
    with ``settle``, leave the model at rest on the surface to ``t_end`` (status 'settled');
    ``max_impacts`` caps their number (status 'impact_limit'); ``maps`` the derived impact
    maps where they are at hand."""
    for name, value in unused.items():
        if value not in (None, (), False, True):
            raise InputError(f"'{name}' is not available for a model with impacts",
                             field=name)
    # 0 would be a cap the first impact already passes (the run stops just after it)
    if isinstance(max_impacts, bool) or not isinstance(max_impacts, int) or max_impacts < 1:
        raise InputError(f"max_impacts must be a whole number >= 1, got {max_impacts!r}",
                         field="max_impacts")
    model = eom.model
    start = resolve_state(model, initial, field="initial", what="coordinate or velocity (or t)")
    if not (math.isfinite(t_end) and t_end > start.t):
        raise InputError(f"the end time ({t_end} s) must be after the start time ({start.t} s)",
                         field="t_end")
    values = resolve_parameters(model, parameters)
    substitution = values.symbol_values(model)
    functions = functions if functions is not None else numeric(eom, values)
    impacts, guards = compiled_impacts(eom, substitution, maps)
    n = functions.n
    grid = np.linspace(start.t, t_end, save_at.samples)
    t0, y = float(start.t), np.concatenate([start.q_array(), start.q_dot_array()])
    ts, ys, records = [], [], []
    spent, lost_so_far = [], 0.0  # T + V's drops at the impacts before each piece (J)
    pivots, pivot = [], None  # where the pivot is in each piece (m), None while none released
    times: dict[str, list[float]] = {}
    steps = nfev = 0
    status, message, limit_time = "finished", STATUS_MESSAGES["finished"], None
    names = [*model.q, *model.q_dot]
    began = time.perf_counter()
    struck = None  # the guard of the last impact
    while True:
        segment = np.concatenate([[t0], grid[grid > t0]])
        if len(segment) < 2:
            segment = np.array([t0, t_end])
        event, offsets = guards.leaving(y[:n], y[n:], t0, struck)
        run = integrate_steps(functions.rhs, t0, y, float(t_end), segment, step_control,
                              event, None, progress)
        steps += run.steps or 0
        nfev += run.nfev
        ts.append(run.t)
        ys.append(run.y)
        spent.append(lost_so_far)
        pivots.append(pivot)
        if run.status != "stopped":
            status, message = run.status, run.message
            break
        t_hit, y_hit = float(run.t[-1]), np.array(run.y[-1])
        which = int(np.argmin(guards.values.at(y_hit[:n], y_hit[n:], t_hit) - offsets))
        t_hit, y_hit = polish(guards, which, functions, t_hit, y_hit, n)
        kept = int(np.searchsorted(run.t[:-1], t_hit))  # samples before the polished time
        ts[-1] = np.concatenate([run.t[:kept], [t_hit]])
        ys[-1] = np.concatenate([run.y[:kept], [y_hit]])
        impact = impacts[which]
        q_new, v_new, impulse, lost, residual, _, _ = impact.apply(y_hit[:n], y_hit[n:], t_hit)
        if impact.k:  # the striking point is the new pivot
            here = impact.striking_point(y_hit[:n], t_hit)
            pivot = here if pivot is None else pivot + here
        y = np.concatenate([q_new, v_new])
        # T + V's drop across the impact: the kinetic energy lost, and where the pivot moved
        # (a walker's new stance foot) the potential's new reference
        lost_so_far += float(functions.energy(y_hit[:n], y_hit[n:], t_hit)
                             - functions.energy(q_new, v_new, t_hit))
        records.append(ImpactRecord(
            float(t_hit), impact.name, _named(names, y_hit), _named(names, y),
            tuple(float(x) for x in impulse), float(lost), float(residual)))
        t0, struck = t_hit, which
        history = times.setdefault(impact.name, [])
        history.append(t_hit)
        limit_time = accumulation(history)
        resting = limit_time is None and pressing(impact, functions, y, t_hit, n)
        if resting:
            limit_time = t_hit
        if limit_time is not None:
            status = ACCUMULATED
            message = (f"impacts at '{impact.name}' accumulate at t = {limit_time:.12g} s "
                       f"({len(history)} impacts): the motion comes to rest there")
            if resting:
                message = (f"after the impact at '{impact.name}' at t = {t_hit:.12g} s the "
                           "point stays on the surface, pressed into it: the motion comes to "
                           "rest there (a contact, not an impact, from then on)")
            if settle:
                y, settled = _settled(impact, y, limit_time, n)
                if settled:
                    status = SETTLED
                    message += f"; settled at rest to t = {t_end:g} s"
                    later = grid[grid > limit_time]
                    ts.append(np.concatenate([[limit_time], later]))
                    ys.append(np.tile(y, (len(later) + 1, 1)))
                    spent.append(lost_so_far)
                    pivots.append(pivot)
                else:
                    message += "; not settled: it still moves along the surface"
            if status == ACCUMULATED:  # the run ends on the state just after the last impact
                ts.append(np.array([t_hit]))
                ys.append(y[None, :])
                spent.append(lost_so_far)
                pivots.append(pivot)
            break
        if len(records) >= max_impacts:
            status = IMPACT_LIMIT
            message = (f"stopped at the cap of {max_impacts} impacts at t = {t_hit:.12g} s "
                       "(raise max_impacts)")
            ts.append(np.array([t_hit]))
            ys.append(y[None, :])
            spent.append(lost_so_far)
            pivots.append(pivot)
            break
        if t_hit >= t_end:
            ts.append(np.array([t_hit]))
            ys.append(y[None, :])
            spent.append(lost_so_far)
            pivots.append(pivot)
            break
    wall = time.perf_counter() - began
    losses = np.concatenate([np.full(len(piece), lost) for piece, lost in zip(ts, spent,
                                                                             strict=True)])
    offsets = None
    if any(p is not None for p in pivots):
        d = len(next(p for p in pivots if p is not None))
        offsets = np.concatenate([np.tile(np.zeros(d) if p is None else p, (len(piece), 1))
                                  for piece, p in zip(ts, pivots, strict=True)])
    result = _result(eom, functions, substitution, np.concatenate(ts), np.concatenate(ys),
                     step_control, status, message, steps, nfev, wall, t_end, records,
                     limit_time, losses)
    return replace(result, pivot_offsets=offsets)


def accumulation(history: list[float]) -> float | None:
    """The limit time of impacts whose intervals shrink geometrically (s), once what is left of
    the series is below ACCUMULATION_TIME (or an interval no longer resolves); else None."""
    if len(history) >= 2:
        last = history[-1] - history[-2]
        if last < SHORTEST_INTERVAL * max(1.0, abs(history[-1])):
            return history[-1]
    if len(history) < 4:
        return None
    d1, d2, d3 = (history[-1] - history[-2], history[-2] - history[-3],
                  history[-3] - history[-4])
    if d2 <= 0 or d3 <= 0:
        return None
    r1, r2 = d1 / d2, d2 / d3
    if not (0 < r1 < 1 and abs(r1 - r2) <= RATIO_AGREEMENT * r1):
        return None
    left = d1 * r1 / (1 - r1)
    return history[-1] + left if left < ACCUMULATION_TIME else None


def pressing(impact: CompiledImpact, functions: NumericSystem, y: np.ndarray, t: float,
             n: int) -> bool:
    """After a plastic impact (no release, no relabel) whose point is left with no normal
    velocity: True when the flow then accelerates it into the surface (a ball with e = 0 on
    the floor), where a guard would let it sink through unseen."""
    if impact.k or impact.map.impact.relabel:
        return False
    q, v = y[:n], y[n:]
    _, _, _, P, normal, _, _ = impact.matrices(q, v, t)
    speed = float(normal[:, 0] @ P @ v)
    scale = max(1e-300, float(np.max(np.abs(P @ v), initial=0.0)), 1e-9)
    if abs(speed) > 1e-9 * max(1.0, scale):
        return False
    step = 1e-6 * max(1.0, abs(t))
    later = _rk4(functions, t, y, step)
    _, _, _, P, normal, _, _ = impact.matrices(later[:n], later[n:], t + step)
    return float(normal[:, 0] @ P @ later[n:]) < speed


def _settled(impact: CompiledImpact, y: np.ndarray, t: float, n: int):
    """The state after a plastic impact (e = 0) at the last one, and whether it is at rest."""
    q, v = y[:n], y[n:]
    M, J, E, *_ = impact.matrices(q, v, t)
    ve = np.concatenate([np.zeros(impact.k), v])
    after = solve_impact(M, J, np.zeros_like(E), ve, "settling")[impact.k:impact.size]
    scale = max(1.0, float(np.max(np.abs(v))))
    at_rest = float(np.max(np.abs(after), initial=0.0)) < 1e-6 * scale
    return np.concatenate([q, np.zeros(n) if at_rest else after]), at_rest


def _named(names, y) -> dict[str, float]:
    return {str(s): float(x) for s, x in zip(names, y, strict=True)}


def _result(eom, functions, substitution, t, y, step_control, status, message, steps, nfev,
            wall, t_end, records, limit_time, losses) -> HybridResult:
    """The result on the samples; T + V's drops at the impacts (J, up to each sample) enter the
    balance: T + V - E0 + drops = 0 between and across impacts (a work balance)."""
    model = eom.model
    n = functions.n
    q, q_dot = y[:, :n], y[:, n:]
    with np.errstate(over="ignore", invalid="ignore"):  # V of y = -1e308 is -inf: NaN, quietly
        energy = functions.energy(q, q_dot, t)
        kinetic = energy - functions.energy(q, np.zeros_like(q_dot), t)
    power_terms = StateFunction(model, eom.generalized_forces, substitution)
    power = np.einsum("ki,ki->k", power_terms(q, q_dot, t), q_dot)
    empty = np.zeros((len(t), 0))
    kind, invariant, work = invariant_kind(eom), energy, None
    if kind != InvariantKind.ENERGY:  # h, and the work of explicit time (no constraints here)
        invariant = StateFunction(model, [eom.jacobi_integral], substitution)(q, q_dot, t)[:, 0]
        if kind == InvariantKind.WORK_BALANCE:
            supplied = power + StateFunction(model, [eom.explicit_time_power],
                                             substitution)(q, q_dot, t)[:, 0]
            work = cumulative_work(t, supplied)
    lossless = not len(losses) or abs(float(losses[-1])) <= 1e-9 * max(
        1.0, abs(float(energy[0])))
    if not lossless:  # the impacts do (negative) work: a balance, not T + V conserved
        if kind == InvariantKind.ENERGY:
            kind, work = InvariantKind.WORK_BALANCE, -losses
        else:  # h jumps by more than T's loss where T is not quadratic: no balance
            kind, work = InvariantKind.WORK_BALANCE, None
    return HybridResult(
        model=model, coordinates=functions.coordinates, constraint_names=(),
        parameters=dict(functions.parameters), t=t, q=q, q_dot=q_dot, energy=energy,
        power=power, multipliers=empty, residuals=empty, step_control=step_control,
        status=status, message=message, steps=steps, nfev=nfev, wall_time=wall,
        backend="scipy", energy_conserved=energy_is_conserved(eom) and lossless,
        t_end=float(t_end), kinetic_energy=kinetic, invariant=kind, invariant_values=invariant,
        work=work, impacts=tuple(records), accumulation_time=limit_time)


__all__ = ["ACCUMULATED", "HYBRID_STATUS", "IMPACT_LIMIT", "MAX_IMPACTS", "SETTLED",
           "CompiledImpact", "Guards", "HybridResult", "ImpactRecord", "accumulation",
           "compiled_impacts", "kkt_system", "polish", "pressing", "solve_impact",
           "simulate_through_impacts"]
