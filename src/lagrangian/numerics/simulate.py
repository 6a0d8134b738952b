"""Time integration of the equations of motion: ODE, and constrained (index-1 DAE) models.

Unconstrained models integrate y = [q, q_dot], y' = [q_dot, M^-1 f]. Constrained models solve
the index-1 form [[M, Phi_q^T], [Phi_q, 0]] [q_ddot; lambda] = [f; gamma] at every call and
control drift by *coordinate projection*: after every accepted step the state is moved back onto
Phi = 0 (Gauss-Newton, mass-weighted) and Phi_dot = 0 (one linear velocity projection; velocity
constraints A q_dot + b = 0 likewise). Units are SI throughout.
"""

from __future__ import annotations

import math
import re
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np
import sympy as sp
from scipy import integrate, optimize

from ..derivation.equations import EquationsOfMotion
from ..errors import ModelError
from ..model.expressions import as_expression, parse_expression
from ..model.model import Model
from ..model.values import resolve_parameters, resolve_state
from .functions import NumericSystem, numeric

METHODS = ("DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA")
# Explicit Runge-Kutta solvers keep only (y, f) between steps, so a projected state can be put
# back in place; the others carry a history and are restarted from the projected state instead.
_IN_PLACE = {"DOP853", "RK45", "RK23"}
_DRIFT_IN_PLACE = 1e-12
_DRIFT_RESTART = 1e-10
# A restarted multistep solver begins again at order 1 with small steps; restarting it more
# often than this many steps keeps it at low order for ever (BDF then crawls).
_STEPS_BETWEEN_RESTARTS = 50

STATUS_MESSAGES = {
    "finished": "reached the end time",
    "stopped": "stopped by the stop condition",
    "interrupted": "interrupted",
    "failed": "integration failed",
}


# -- stop condition ----------------------------------------------------------------------------

_COMPARISON = re.compile(r"<=|>=|==|!=|<|>")


@dataclass(frozen=True)
class StopCondition:
    """``lhs OP rhs`` in the model grammar; the run stops when it turns true (crossing)."""

    text: str
    lhs: sp.Expr
    operator: str
    rhs: sp.Expr

    @property
    def function(self) -> sp.Expr:
        """g with g > 0 exactly where the condition holds."""
        return self.lhs - self.rhs if self.operator in (">", ">=") else self.rhs - self.lhs


def parse_stop_condition(text: str, model: Model, *, field: str = "--stop-when") -> StopCondition:
    """Parse 'EXPR < EXPR' (or >, <=, >=) with the model grammar; nothing is evaluated."""
    if not isinstance(text, str) or not text.strip():
        raise ModelError("the stop condition is empty; write e.g. 'theta < 0'", field=field)
    operators = _COMPARISON.findall(text)
    if len(operators) != 1:
        what = "no comparison" if not operators else f"{len(operators)} comparisons"
        raise ModelError(
            f"a stop condition has exactly one comparison (<, >, <=, >=), found {what} "
            f"in {text!r}", field=field)
    operator = operators[0]
    if operator in ("==", "!="):
        raise ModelError(f"'{operator}' is not allowed; use <, >, <= or >= (a crossing) "
                         f"in {text!r}", field=field)
    left, right = _COMPARISON.split(text)
    names = _condition_names(model)
    sides = []
    for side, part in (("left", left), ("right", right)):
        if not part.strip():
            raise ModelError(f"the {side} side of {text!r} is empty", field=field)
        sides.append(parse_expression(part, names, field=field))
    return StopCondition(text.strip(), sides[0], operator, sides[1])


def _condition_names(model: Model) -> dict[str, sp.Expr]:
    names: dict[str, sp.Expr] = {"t": model.time}
    names.update({p.name: p.symbol for p in model.parameters})
    names.update(dict(model.definitions))
    for c in model.coordinates:
        names[c.name] = c.symbol
        names[c.velocity.name] = c.velocity
    return names


# -- result ------------------------------------------------------------------------------------

@dataclass(frozen=True)
class SimulationResult:
    """Sampled trajectory t (s), q, q_dot, energy T + V (J), power of non-conservative loads
    Q . q_dot (W), multipliers lambda and constraint residuals, with run statistics."""

    model_name: str
    coordinates: tuple[str, ...]
    constraint_names: tuple[str, ...]
    parameters: dict[str, float]
    t: np.ndarray
    q: np.ndarray
    q_dot: np.ndarray
    energy: np.ndarray
    power: np.ndarray
    multipliers: np.ndarray
    residuals: np.ndarray
    method: str
    rtol: float
    atol: float
    status: str
    message: str
    steps: int | None
    nfev: int
    wall_time: float
    backend: str
    energy_conserved: bool
    t_end: float
    stop_when: str | None = None
    projected_initial_state: dict[str, tuple[float, float]] = field(default_factory=dict)
    kinetic_energy: np.ndarray | None = None

    @property
    def completed(self) -> bool:
        """True when the run reached its end time or its stop condition."""
        return self.status in ("finished", "stopped")

    def columns(self) -> dict[str, np.ndarray]:
        """Named columns: t, <q>, <q>_dot, energy, lambda_<c>, residual_<c>, power."""
        out: dict[str, np.ndarray] = {"t": self.t}
        for i, name in enumerate(self.coordinates):
            out[name] = self.q[:, i]
        for i, name in enumerate(self.coordinates):
            out[f"{name}_dot"] = self.q_dot[:, i]
        out["energy"] = self.energy
        for i, name in enumerate(self.constraint_names):
            out[f"lambda_{name}"] = self.multipliers[:, i]
        for i, name in enumerate(self.constraint_names):
            out[f"residual_{name}"] = self.residuals[:, i]
        out["power"] = self.power
        return out

    @property
    def final_state(self) -> dict[str, float]:
        state = {"t": float(self.t[-1])}
        for i, name in enumerate(self.coordinates):
            state[name] = float(self.q[-1, i])
        for i, name in enumerate(self.coordinates):
            state[f"{name}_dot"] = float(self.q_dot[-1, i])
        return state

    @property
    def energy_drift(self) -> float | None:
        """max |E - E0| / |E0| where energy should be conserved, else None (max T if E0 = 0)."""
        if not self.energy_conserved or len(self.energy) == 0:
            return None
        change = float(np.max(np.abs(self.energy - self.energy[0])))
        scale = abs(float(self.energy[0]))
        if self.kinetic_energy is not None and len(self.kinetic_energy):
            # E0 = 0 (a body starting at rest at the potential's zero): relative to the largest T
            largest_t = float(np.max(np.abs(self.kinetic_energy)))
            if scale <= 1e-9 * largest_t:
                scale = largest_t
        return change / scale if scale > 0 else 0.0

    @property
    def max_residual(self) -> float | None:
        """Largest |Phi| (holonomic) or |A q_dot + b| (velocity) over the samples, else None."""
        if not self.constraint_names or len(self.t) == 0:
            return None
        return float(np.max(np.abs(self.residuals)))

    def summary(self) -> dict:
        """JSON-ready summary: final state, steps, wall time, drift, largest residual."""
        return {
            "model": self.model_name,
            "status": self.status,
            "message": self.message,
            "method": self.method,
            "backend": self.backend,
            "rtol": self.rtol,
            "atol": self.atol,
            "t_start": float(self.t[0]),
            "t_end": self.t_end,
            "t_final": float(self.t[-1]),
            "stop_when": self.stop_when,
            "final_state": self.final_state,
            "steps": self.steps,
            "nfev": self.nfev,
            "samples": int(len(self.t)),
            "wall_time_s": self.wall_time,
            "energy_conserved": self.energy_conserved,
            "relative_energy_drift": self.energy_drift,
            "max_constraint_residual": self.max_residual,
            "projected_initial_state": {
                name: {"given": given, "used": used}
                for name, (given, used) in self.projected_initial_state.items()
            },
        }


# -- the integration ---------------------------------------------------------------------------

def energy_is_conserved(eom: EquationsOfMotion) -> bool:
    """No dissipation, no non-conservative loads, no explicit time dependence."""
    model = eom.model
    t = model.time
    if eom.dissipation != 0 or any(Q != 0 for Q in eom.generalized_forces):
        return False
    terms = [eom.kinetic_energy, eom.potential_energy, *eom.mass_matrix, *eom.forcing,
             *(c.expression for c in model.constraints)]
    return not any(t in as_expression(e).free_symbols for e in terms)


def simulate(
    eom: EquationsOfMotion,
    t_end: float,
    *,
    initial: Mapping[str, float] | None = None,
    parameters: Mapping[str, float] | None = None,
    method: str = "DOP853",
    rtol: float = 1e-9,
    atol: float = 1e-9,
    samples: int = 1001,
    stop_when: str | StopCondition | None = None,
    progress: Callable[[float], None] | None = None,
    system: NumericSystem | None = None,
    fast: bool = True,
) -> SimulationResult:
    """Integrate from the initial state to ``t_end`` (s), sampling ``samples`` evenly spaced times.

    ``initial`` overrides the model's initial/rate values (names q, q_dot and t for the start
    time). ``stop_when`` ends the run when the condition first turns true. ``progress`` is
    called with the time reached after each step. Failures and Ctrl-C return the partial result
    with ``status`` 'failed' or 'interrupted' and the time reached in ``message``.
    """
    model = eom.model
    if method not in METHODS:
        raise ModelError(f"unknown method '{method}'; choose one of {', '.join(METHODS)}",
                         field="method")
    for name, value in (("rtol", rtol), ("atol", atol)):
        if not (math.isfinite(value) and value > 0):
            raise ModelError(f"{name} must be a positive number, got {value}", field=name)
    if int(samples) < 2:
        raise ModelError(f"samples must be at least 2, got {samples}", field="samples")
    start = resolve_state(model, initial, field="initial", what="coordinate or velocity (or t)")
    t0, q0, v0 = start.t, start.q_array(), start.q_dot_array()
    if not (math.isfinite(t_end) and t_end > t0):
        raise ModelError(f"the end time ({t_end} s) must be after the start time ({t0} s)",
                         field="t_end")
    condition = (parse_stop_condition(stop_when, model) if isinstance(stop_when, str)
                 else stop_when)

    # Everything numeric is compiled here, once, before the loop.
    system = system if system is not None else numeric(eom, parameters)
    values = resolve_parameters(model, parameters).symbol_values(model)
    args = [*model.q, *model.q_dot, model.time]
    n, m = system.n, system.m
    drift = _DriftControl(system, _lambdify_rows(args, eom.velocity_bias, values)) if m else None
    event = (_lambdify_scalar(args, condition.function, values) if condition else None)
    power_terms = _lambdify_rows(args, eom.generalized_forces, values)

    projected: dict[str, tuple[float, float]] = {}
    if drift is not None:
        given = {name: name in start.given for name in start.names}
        q_new, v_new = drift.project_initial(q0, v0, t0, given)
        for name, old, new in zip(start.names, np.concatenate([q0, v0]),
                                  np.concatenate([q_new, v_new]), strict=True):
            if abs(new - old) > 1e-12 * max(1.0, abs(old)):
                projected[name] = (float(old), float(new))
        q0, v0 = q_new, v_new

    grid = np.linspace(t0, t_end, int(samples))
    y0 = np.concatenate([q0, v0])
    started = time.perf_counter()
    run = None
    if fast and not m and method == "DOP853" and event is None:
        run = _integrate_compiled(system, (t0, t_end), y0, rtol, atol, grid, progress)
    backend = "compiled" if run is not None else "scipy"
    if run is None:
        fun = _rhs(system)
        run = _integrate_steps(fun, t0, y0, t_end, grid, method, rtol, atol, event, drift,
                               progress)
    wall = time.perf_counter() - started

    t, y = run.t, run.y
    q, q_dot = y[:, :n], y[:, n:]
    energy = system.energy(q, q_dot, t)
    kinetic = energy - system.energy(q, np.zeros_like(q_dot), t)  # T: E less its q_dot = 0 part
    power = np.einsum("ki,ki->k", _rows_batch(power_terms, q, q_dot, t, n), q_dot)
    if m:
        with np.errstate(all="ignore"):
            _, multipliers = system.accelerations(q, q_dot, t)
        residuals = system.constraint_residual(q, q_dot, t)
    else:
        multipliers = residuals = np.zeros((len(t), 0))
    return SimulationResult(
        model_name=model.name, coordinates=system.coordinates,
        constraint_names=system.constraint_names, parameters=dict(system.parameters),
        t=t, q=q, q_dot=q_dot, energy=energy, power=power, multipliers=multipliers,
        residuals=residuals, method=method, rtol=float(rtol), atol=float(atol),
        status=run.status, message=run.message, steps=run.steps, nfev=run.nfev, wall_time=wall,
        backend=backend, energy_conserved=energy_is_conserved(eom), t_end=float(t_end),
        stop_when=condition.text if condition else None, projected_initial_state=projected,
        kinetic_energy=kinetic,
    )


@dataclass(frozen=True)
class _Run:
    t: np.ndarray
    y: np.ndarray
    status: str
    message: str
    steps: int | None
    nfev: int


def _state_names(model: Model) -> list[str]:
    return [c.name for c in model.coordinates] + [c.velocity.name for c in model.coordinates]


def _rhs(system: NumericSystem) -> Callable[[float, np.ndarray], np.ndarray]:
    n = system.n

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        # Always a fresh array: solve_ivp-style solvers keep references to what we return.
        q_ddot, _ = system.accelerations(y[:n], y[n:], t)
        return np.concatenate([y[n:], q_ddot])

    return rhs


def _integrate_compiled(system, t_span, y0, rtol, atol, grid, progress=None) -> _Run | None:
    """The compiled integration loop of numerics.fast when it is there; None to fall back.

    With a ``progress`` callback the run goes in pieces between output samples (a first short
    piece times the loop; the rest in one call when it will take under a second), so a long run
    can report progress; Ctrl-C inside the C loop keeps the states computed so far.
    """
    try:
        from .fast import integrate_fast
    except ImportError:
        return None
    pieces = [(0, len(grid) - 1)]
    if progress is not None and len(grid) > 2:
        first = max(1, (len(grid) - 1) // 100)
        pieces = [(0, first), (first, len(grid) - 1)]
    ts, ys, nfev, steps = [], [], 0, 0
    y_start = y0
    status, message = "finished", STATUS_MESSAGES["finished"]
    while pieces:
        a, b = pieces.pop(0)
        began = time.perf_counter()
        result = integrate_fast(system, (float(grid[a]), float(grid[b])), y_start, rtol=rtol,
                                atol=atol, t_eval=grid[a:b + 1])
        if result is None:
            return None
        t = np.asarray(result.t, dtype=float)
        y = np.asarray(result.y, dtype=float).reshape(len(t), -1)
        skip = 1 if ts and len(t) and t[0] == ts[-1][-1] else 0
        ts.append(t[skip:])
        ys.append(y[skip:])
        nfev += int(result.nfev)
        piece_steps = getattr(result, "steps", getattr(result, "nsteps", None))
        steps = None if piece_steps is None or steps is None else steps + int(piece_steps)
        if not result.success:
            text = str(result.message).rstrip(".")
            status = "interrupted" if text.lower().startswith("interrupted") else "failed"
            reached = float(t[-1]) if len(t) else float(grid[a])
            message = text if "t =" in text else f"{text} (stopped at t = {reached:.9g} s)"
            break
        if progress is not None:
            try:
                progress(float(t[-1]))
            except KeyboardInterrupt:
                if not pieces:  # the run was complete already
                    break
                status = "interrupted"
                message = f"interrupted by the user (Ctrl-C) at t = {float(t[-1]):.9g} s"
                break
            spent = time.perf_counter() - began
            remaining = float(grid[-1] - grid[b])
            if len(pieces) == 1 and a == 0 and \
                    spent * remaining / max(float(grid[b] - grid[a]), 1e-300) > 1.0:
                # about 50 pieces, so the bar moves and Ctrl-C is answered between them
                _, last = pieces.pop(0)
                bounds = np.unique(np.linspace(b, last, 51).round().astype(int))
                pieces = list(zip(bounds[:-1], bounds[1:], strict=True))
        y_start = y[-1]
    return _Run(np.concatenate(ts), np.concatenate(ys), status, message, steps, nfev)


def _integrate_steps(fun, t0, y0, t_end, grid, method, rtol, atol, event, drift, progress) -> _Run:
    """Step a scipy OdeSolver by hand: dense output onto the grid, events, projection, Ctrl-C."""
    solver_class = getattr(integrate, method)

    def start(t, y, first_step=None):
        return solver_class(fun, t, y, t_end, rtol=rtol, atol=atol, first_step=first_step)

    ts, ys = [t0], [y0.copy()]
    index = 1
    status, message = "finished", STATUS_MESSAGES["finished"]
    steps, nfev_done = 0, 0
    n = len(y0) // 2
    armed = event is not None and event(y0[:n], y0[n:], t0) < 0
    solver = None
    try:
        with np.errstate(all="ignore"):
            solver = start(t0, y0)
            while solver.status == "running":
                failure = solver.step()
                if solver.status == "failed":
                    status = "failed"
                    message = (f"{(failure or 'the step failed').rstrip('.')} "
                               f"(stopped at t = {solver.t:.9g} s)")
                    break
                if not np.all(np.isfinite(solver.y)):
                    status = "failed"
                    message = ("the state became infinite or NaN "
                               f"(stopped at t = {solver.t_old:.9g} s)")
                    break
                steps += 1
                dense = solver.dense_output()
                t_stop, hit = solver.t, False
                if event is not None:
                    g_new = event(solver.y[:n], solver.y[n:], solver.t)
                    if armed and g_new >= 0:
                        t_stop, hit = _crossing(event, dense, solver.t_old, solver.t, n), True
                    elif g_new < 0:
                        armed = True
                while index < len(grid) and grid[index] <= t_stop:
                    ts.append(float(grid[index]))
                    ys.append(dense(grid[index]))
                    index += 1
                if hit:
                    if t_stop > ts[-1]:
                        ts.append(float(t_stop))
                        ys.append(dense(t_stop))
                    status, message = "stopped", f"stop condition met at t = {t_stop:.12g} s"
                    break
                if drift is not None and solver.status == "running":
                    solver = drift.correct(solver, start)
                if progress is not None:
                    progress(solver.t)
    except KeyboardInterrupt:
        status = "interrupted"
        message = f"interrupted by the user (Ctrl-C) at t = {_reached(solver, t0):.9g} s"
    except np.linalg.LinAlgError:
        status = "failed"
        message = ("singular mass matrix (or constraint Jacobian without full rank) "
                   f"near t = {_reached(solver, t0):.9g} s")
    if status in ("failed", "interrupted") and solver is not None and solver.t > ts[-1] \
            and np.all(np.isfinite(solver.y)):
        ts.append(float(solver.t))
        ys.append(np.array(solver.y, dtype=float))
    nfev = nfev_done + (solver.nfev if solver is not None else 0)
    if drift is not None:
        nfev += drift.nfev
    return _Run(np.array(ts), np.array(ys), status, message, steps, int(nfev))


def _reached(solver, t0: float) -> float:
    return float(solver.t) if solver is not None else float(t0)


def _crossing(event, dense, t_old: float, t_new: float, n: int) -> float:
    """The time in [t_old, t_new] where the event function turns from negative to >= 0."""
    def g(t):
        y = dense(t)
        return event(y[:n], y[n:], t)

    if g(t_old) >= 0:
        return t_old
    return float(optimize.brentq(g, t_old, t_new, xtol=1e-15 * max(1.0, abs(t_new)),
                                 rtol=4 * np.finfo(float).eps, maxiter=200))


# -- drift control -----------------------------------------------------------------------------

class _DriftControl:
    """Coordinate projection onto Phi = 0 and Phi_dot = 0 (velocity constraints: A q_dot + b = 0).

    Positions: Gauss-Newton steps dq = -W^-1 J^T (J W^-1 J^T)^-1 Phi over the holonomic rows;
    velocities: one step of the same form with the velocity-level residual J q_dot + b. W is the
    mass matrix (the smallest change in kinetic-energy norm).
    """

    def __init__(self, system: NumericSystem, velocity_bias: Callable):
        self.system = system
        self.velocity_bias = velocity_bias
        self.holonomic = np.array([k == "holonomic" for k in system.constraint_kinds])
        self.nfev = 0
        self.steps_since_restart = 0

    def residuals(self, q, v, t):
        s = self.system
        phi = s.constraint_residual(q, v, t)[self.holonomic]
        jacobian = s.constraint_jacobian(q, v, t)
        velocity = jacobian @ v + _row_values(self.velocity_bias, q, v, t)
        return phi, velocity, jacobian

    def project(self, q, v, t, inverse_metric=None, tolerance=0.0):
        """The nearest state (in the metric) with Phi = 0 and J q_dot + b = 0."""
        phi, velocity, jacobian = self.residuals(q, v, t)
        for _ in range(12):
            if not phi.size or np.max(np.abs(phi)) <= tolerance:
                break
            W = self._metric(q, v, t, inverse_metric)
            J = jacobian[self.holonomic]
            dq = -W @ J.T @ np.linalg.solve(J @ W @ J.T, phi)
            q = q + dq
            phi, velocity, jacobian = self.residuals(q, v, t)
            if np.max(np.abs(dq)) <= 1e-15 * (1.0 + np.max(np.abs(q))):
                break
        if velocity.size and np.max(np.abs(velocity)) > tolerance:
            W = self._metric(q, v, t, inverse_metric)
            v = v - W @ jacobian.T @ np.linalg.solve(jacobian @ W @ jacobian.T, velocity)
        return q, v

    def _metric(self, q, v, t, inverse_metric):
        if inverse_metric is not None:
            return inverse_metric
        return np.linalg.inv(self.system.mass_matrix(q, v, t))

    def project_initial(self, q, v, t, given: Mapping[str, bool]):
        """Project the initial state, moving the values the user did not give where possible."""
        n = self.system.n
        names = list(given)
        free = np.array([not given[name] for name in names])
        # Euclidean metric restricted to the free entries; all entries if that is not enough.
        for mask in (free, np.ones(2 * n, dtype=bool)):
            try:
                q_new, _ = self.project(q, v, t, np.diag(mask[:n].astype(float)))
                _, v_new = self.project(q_new, v, t, np.diag(mask[n:].astype(float)))
                phi, velocity, _ = self.residuals(q_new, v_new, t)
                if np.max(np.abs(np.concatenate([phi, velocity])), initial=0.0) < 1e-10:
                    return q_new, v_new
            except np.linalg.LinAlgError:
                continue
        raise ModelError("the initial state cannot be brought onto the constraints "
                         "(Phi = 0 and its rate); check the initial values", field="initial")

    def correct(self, solver, start):
        """Project the solver's state if it drifted; returns the solver to continue with."""
        n = self.system.n
        y = solver.y
        phi, velocity, _ = self.residuals(y[:n], y[n:], solver.t)
        worst = np.max(np.abs(np.concatenate([phi, velocity])), initial=0.0)
        in_place = type(solver).__name__ in _IN_PLACE
        self.steps_since_restart += 1
        if worst <= (_DRIFT_IN_PLACE if in_place else _DRIFT_RESTART):
            return solver
        if not in_place and self.steps_since_restart < _STEPS_BETWEEN_RESTARTS:
            return solver
        self.steps_since_restart = 0
        q, v = self.project(y[:n], y[n:], solver.t, tolerance=1e-15)
        y_new = np.concatenate([q, v])
        if in_place:
            solver.y = y_new
            solver.f = solver.fun(solver.t, y_new)
            return solver
        self.nfev += solver.nfev
        return start(solver.t, y_new, first_step=min(solver.step_size, solver.t_bound - solver.t)
                     if solver.step_size else None)


# -- small compiled helpers --------------------------------------------------------------------

def _lambdify_rows(args, matrix, values) -> Callable:
    exprs = [as_expression(e).xreplace(values) for e in matrix]
    return sp.lambdify(args, exprs, modules="numpy", cse=True)


def _lambdify_scalar(args, expr, values) -> Callable:
    f = sp.lambdify(args, as_expression(expr).xreplace(values), modules="numpy")

    def event(q, v, t):
        return float(f(*q, *v, t))

    return event


def _row_values(f: Callable, q, v, t) -> np.ndarray:
    return np.array([float(x) for x in f(*q, *v, t)], dtype=float)


def _rows_batch(f: Callable, q, v, t, n: int) -> np.ndarray:
    k = len(t)
    rows = f(*q.T, *v.T, t)
    return np.stack([np.broadcast_to(np.asarray(r, dtype=float), (k,)) for r in rows], axis=-1) \
        if n else np.zeros((k, 0))
