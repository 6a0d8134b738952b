"""Time integration of the equations of motion: ODE, and constrained (index-1 DAE) models.

Unconstrained models integrate y = [q, q_dot], y' = [q_dot, M^-1 f]. Constrained models solve
the index-1 form [[M, Phi_q^T], [Phi_q, 0]] [q_ddot; lambda] = [f; gamma] at every call and
control drift by coordinate projection (simulation/drift.py). Units are SI throughout.

The driver: resolve the start, compile what the loop needs, run one loop (simulation/integration_loops.py),
then evaluate energy, power, multipliers and residuals on the saved samples.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from ..compile.functions import NumericSystem, numeric
from ..compile.lambdified import StateFunction
from ..derivation.equations import EquationsOfMotion
from ..errors import InputError
from ..kinds import InvariantKind, RunStatus
from ..model.model import Model
from ..model.rotations import gimbal_lock
from ..model.values import ParameterValues, State, resolve_parameters, resolve_state
from .control import Controller, ControlLoop
from .control_law import MODEL_LAW, ModelLaw
from .drift import DriftControl
from .events import StopCondition, parse_stop_condition
from .guards import check_start
from .integration_loops import LoopRun, integrate_compiled, integrate_steps
from .invariants import cumulative_work, energy_is_conserved, invariant_kind
from .options import METHODS, SaveAt, StepControl
from .result import STATUS_MESSAGES, SimulationResult

__all__ = ["METHODS", "STATUS_MESSAGES", "JointLimit", "SaveAt", "SimulationResult", "StepControl",
           "START_LIMITS", "StopCondition", "at_limit", "beyond_limits", "check_start_rates",
           "check_start_within",
           "exceeded_limits", "model_law", "parse_stop_condition", "simulate", "urdf_limits"]

DEFAULT_STEP_CONTROL = StepControl()  # DOP853, rtol = atol = 1e-9
DEFAULT_SAVE_AT = SaveAt()  # 1001 evenly spaced samples


def simulate(
    eom: EquationsOfMotion | None,
    t_end: float,
    *,
    initial: Mapping[str, float] | State | None = None,
    parameters: Mapping[str, float] | ParameterValues | None = None,
    step_control: StepControl = DEFAULT_STEP_CONTROL,
    save_at: SaveAt = DEFAULT_SAVE_AT,
    stop: StopCondition | None = None,
    progress: Callable[[float], None] | None = None,
    functions: NumericSystem | None = None,
    compiled_loop: bool = True,
    limits: Sequence[JointLimit] = (),
    controller: Controller | str | None = None,
    inputs: Sequence[str] = (),
    model: Model | None = None,
    start_beyond: str = "refuse",
    start_limits: Sequence[JointLimit] | None = None,
    canonical: CanonicalEquations | None = None,
) -> SimulationResult:
    """Integrate from the initial state to ``t_end`` (s), saving where ``save_at`` says.

    ``initial`` overrides the model's initial/rate values (names q, q_dot, and t for the start
    time). ``stop`` ends the run when its condition first turns true. ``progress`` is called with
    the time reached after each step. ``compiled_loop`` allows the DOP853 loop in C where it
    applies. Failures and Ctrl-C return the partial result with ``status`` 'failed' or
    'interrupted' and the time reached in ``message``. ``limits`` (a robot's URDF position
    limits, JointLimit) end the run with status 'limit' when a joint reaches one, naming it;
    velocity and effort limits exceeded are reported in ``limits_exceeded``. ``controller``
    (t, q, q_dot) -> u adds generalized forces (or, with ``inputs``, B u: simulation/control.py)
    to the model's own, in the scipy loop; ``controller="model"`` closes the loop with the
    model's own [control] laws instead, compiled with the equations (simulation/control_law.py).
    A start beyond a position or velocity limit (``start_limits``, default ``limits``) is
    refused, or with ``start_beyond`` "clamp" started at the limit, "ignore" where it is, each
    noted in the result's message (check_start_within, check_start_rates). A rate that makes the accelerations
    overflow at the start is refused naming it; a step size that collapses ends the run as
    'failed', each within a bounded number of calls (simulation/guards.py). ``canonical``
    (the model's Hamiltonian, analysis/hamilton.py) integrates Hamilton's equations in (q, p)
    instead, in the step loop: the samples' q_dot from p, the momenta in ``momenta``.

    ``eom`` None: the run of a kinematic tree's recursive algorithms (``functions``, of
    ``model``), with nothing derived: no constraints, no explicit t, T quadratic in q_dot, and
    the model's generalized forces its only loads.
    """
    if eom is None and (model is None or functions is None or functions.m):
        raise ValueError("a run without equations needs the model and a tree's functions")
    model = eom.model if eom is not None else model
    if eom is not None and model.impacts:  # through its impacts: simulation/hybrid.py
        from .hybrid import simulate_through_impacts

        return simulate_through_impacts(
            eom, t_end, initial=initial, parameters=parameters, step_control=step_control,
            save_at=save_at, progress=progress, functions=functions, stop=stop, limits=limits,
            controller=controller, inputs=inputs)
    start = resolve_state(model, initial, field="initial", what="coordinate or velocity (or t)")
    if not (math.isfinite(t_end) and t_end > start.t):
        raise InputError(f"the end time ({t_end} s) must be after the start time ({start.t} s)",
                         field="t_end")
    # Everything numeric is compiled here, once, before the loop.
    values = resolve_parameters(model, parameters)
    substitution = values.symbol_values(model)
    law = None
    if isinstance(controller, str):
        controller = model_law(eom, controller, inputs, substitution)
    if isinstance(controller, ModelLaw):  # built here, or once by the System
        if not controller.built_with(substitution):
            raise ValueError("a ModelLaw built for other parameter values")
        law, controller = controller, None
        eom, functions = law.equations, law.functions(values)
    functions = functions if functions is not None else numeric(eom, values)
    drift = DriftControl(functions, StateFunction(model, eom.velocity_bias, substitution)) \
        if functions.m else None
    event = _event(StateFunction(model, [stop.function], substitution)) if stop else None
    if canonical is not None:
        _refuse_canonical(functions, parameters, loop_wanted=controller is not None or law
                          is not None)
    positioned = [m for m in limits if m.lower is not None and m.upper is not None]
    forces = eom.generalized_forces if eom is not None else _tree_forces(model)
    power_terms = StateFunction(model, forces, substitution)

    q0, v0, projected = start.q_array(), start.q_dot_array(), {}
    q0, beyond_at_start = check_start_within(positioned if start_limits is None else start_limits,
                                             q0, start_beyond)
    v0, too_fast = check_start_rates(limits if start_limits is None else start_limits, v0,
                                     start_beyond)
    beyond_at_start = "; ".join(note for note in (beyond_at_start, too_fast) if note)
    if beyond_at_start:  # clamped (or ignored): the start as it was used
        start = replace(start, q=tuple(float(x) for x in q0), q_dot=tuple(float(x) for x in v0))
    beyond = beyond_limits(limits, q0) if limits else None
    if drift is not None:
        q0, v0, projected = _project_start(drift, start)

    loop = None
    if controller is not None:
        loop = ControlLoop(functions, controller, inputs, eom, substitution)
        loop.output(start.t, q0, v0)  # a wrong shape refused before the run
    grid = np.linspace(start.t, t_end, save_at.samples)
    y0 = np.concatenate([q0, v0])
    # a rate that overflows the accelerations at once: refused, not left to the step control
    # (the model's own motion: a controller is not called for it, its calls are the run's)
    check_start(functions.rhs, start.t, y0, start.velocities, start.given)
    began = time.perf_counter()
    momenta = None
    if canonical is not None:  # in (q, p): the events and limits read q_dot from p
        run, momenta = _integrate_canonical(canonical, y0, grid, step_control, event, progress,
                                            beyond)
    else:
        run = _integrate(functions, y0, grid, step_control, event, drift, progress,
                         compiled_loop and not functions.m and event is None and loop is None,
                         beyond, rhs=None if loop is None else loop.rhs)
    if beyond is not None and run.status == RunStatus.STOPPED:
        run = at_limit(run, positioned, beyond, event, functions.n)
    wall = time.perf_counter() - began
    if run.status == RunStatus.FAILED:
        run = replace(run, message=_explain_failure(functions, run))
    if beyond_at_start:
        run = replace(run, message=f"{run.message}; warning: {beyond_at_start}")
    if run.status == RunStatus.FAILED and model.rigid_bodies:  # an Euler-angle singularity, named
        where = {**substitution, **dict(zip(model.q, run.y[-1][:functions.n], strict=True))}
        lock = gimbal_lock(model.rigid_bodies, where)
        if lock:
            run = replace(run, message=f"{run.message}: {lock}")

    t, q, q_dot = run.t, run.y[:, :functions.n], run.y[:, functions.n:]
    with np.errstate(over="ignore", invalid="ignore"):  # a failed run's overflow: NaN, quietly
        energy = functions.energy(q, q_dot, t)
        kinetic = energy - functions.energy(q, np.zeros_like(q_dot), t)  # T: E less its V
    power = np.einsum("ki,ki->k", power_terms(q, q_dot, t), q_dot)
    controls = control_forces = None
    if loop is not None or law is not None:  # the controller's work enters the balance
        controls, control_forces = (loop or law).on_samples(t, q, q_dot)
        power = power + np.einsum("ki,ki->k", control_forces, q_dot)
    if functions.m:
        with np.errstate(all="ignore"):
            _, multipliers = functions.accelerations_and_multipliers(q, q_dot, t) \
                if loop is None else (None, loop.multipliers(t, q, q_dot, control_forces))
        residuals = functions.constraint_residual(q, q_dot, t)
    else:
        multipliers = residuals = np.zeros((len(t), 0))
    if eom is not None:
        controlled = loop is not None or law is not None
        kind, invariant, work = _invariant(eom, substitution, t, q, q_dot, energy, power,
                                           multipliers, controlled=controlled)
        conserved = energy_is_conserved(eom) and not controlled
    else:  # a tree: h = T + V, changed only by the generalized forces' (and controller's) work
        working = loop is not None or any(float(f.xreplace(substitution)) != 0 for f in forces)
        kind = InvariantKind.WORK_BALANCE if working else InvariantKind.ENERGY
        invariant, work = energy, (cumulative_work(t, power) if working else None)
        conserved = not working
    return SimulationResult(
        model=model, coordinates=functions.coordinates,
        constraint_names=functions.constraint_names, parameters=dict(functions.parameters),
        t=t, q=q, q_dot=q_dot, energy=energy, power=power, multipliers=multipliers,
        residuals=residuals, step_control=step_control, status=run.status, message=run.message,
        steps=run.steps, nfev=run.nfev, wall_time=wall, backend=run.backend,
        energy_conserved=conserved, t_end=float(t_end),
        stop_when=stop.text if stop else None, projected_initial_state=projected,
        kinetic_energy=kinetic, invariant=kind, invariant_values=invariant, work=work,
        limits_exceeded=exceeded_limits(limits, functions.parameters, t, q_dot),
        controls=controls, control_names=(loop or law).names if controls is not None else (),
        control_forces=control_forces, momenta=momenta,
    )


class CanonicalEquations(Protocol):
    """Hamilton's equations of a model (analysis/hamilton.Hamiltonian), SI units."""

    def rhs(self, q, p, t: float = 0.0) -> tuple[np.ndarray, np.ndarray]: ...
    def velocities_of(self, q, p, t: float = 0.0) -> np.ndarray: ...
    def momenta_of(self, q, q_dot, t: float = 0.0) -> np.ndarray: ...


def _refuse_canonical(functions: NumericSystem, parameters, loop_wanted: bool) -> None:
    """What a run in (q, p) does not take yet, in one line each."""
    if functions.m:
        raise InputError("Hamilton's equations here are for a model without constraints",
                         field="canonical")
    if loop_wanted:
        raise InputError("a run in (q, p) takes no controller (yet): run it in (q, q_dot)",
                         field="canonical")
    if parameters:
        raise InputError("a run in (q, p) uses the model's own parameter values: give them to "
                         "the model (with_parameters)", field="canonical")


def _integrate_canonical(canonical: CanonicalEquations, y0, grid, step_control, event,
                         progress, beyond) -> tuple[LoopRun, np.ndarray]:
    """Hamilton's equations q_dot = M^-1 (p - b), p_dot = dL/dq + Q in the step loop, from the
    start's p = M q_dot + b; the events and limits see q_dot. The run's states as [q, q_dot]
    (q_dot from each sample's p), and the momenta p (N, n)."""
    n = len(y0) // 2
    start = np.concatenate([y0[:n], canonical.momenta_of(y0[:n], y0[n:], float(grid[0]))])

    def rhs(t, y):
        q_dot, p_dot = canonical.rhs(y[:n], y[n:], t)
        return np.concatenate([q_dot, p_dot])

    def seen(function):
        return None if function is None else (
            lambda q, p, t: function(q, canonical.velocities_of(q, p, t), t))

    if beyond is not None:
        user = event
        event = beyond if user is None else (lambda q, v, t: max(user(q, v, t), beyond(q, v, t)))
    run = integrate_steps(rhs, float(grid[0]), start, float(grid[-1]), grid, step_control,
                          seen(event), None, progress)
    q, p = run.y[:, :n], run.y[:, n:]
    y = np.concatenate([q, _velocities(canonical, run.t, q, p)], axis=1)
    return replace(run, y=y, backend=f"{run.backend}, Hamilton's equations in (q, p)"), p


def _velocities(canonical: CanonicalEquations, t, q, p) -> np.ndarray:
    """q_dot at each sample from its (q, p); NaN past a failed run's last finite sample."""
    out = np.full(q.shape, np.nan)
    for k in range(len(t)):
        if np.isfinite(q[k]).all() and np.isfinite(p[k]).all():
            out[k] = canonical.velocities_of(q[k], p[k], float(t[k]))
    return out


def model_law(eom, controller: str, inputs, substitution) -> ModelLaw:
    """The model's [control] laws closed into its equations (controller="model")."""
    if controller != MODEL_LAW:
        raise InputError(f"unknown controller {controller!r}: a callable (t, q, q_dot) -> u, or "
                         f"{MODEL_LAW!r} for the model's [control] laws", field="controller")
    if eom is None:
        raise InputError("a robot's tree has no [control] table; pass a callable",
                         field="controller")
    if inputs:
        raise InputError("the [control] laws name their own inputs; leave inputs out",
                         field="inputs")
    return ModelLaw(eom, substitution)


def _tree_forces(model: Model) -> list:
    """Each coordinate's generalized force (N m or N): the sum of the model's, 0 where none."""
    import sympy as sp

    given: dict[str, list] = {}
    for coordinate, force in model.generalized_forces:
        given.setdefault(coordinate, []).append(force)
    return [sp.Add(*given.get(c.name, [])) for c in model.coordinates]


def _invariant(eom, substitution, t, q, q_dot, energy, power, multipliers, controlled=False):
    """(kind, the monitored quantity on the samples, the work done on the system up to each
    sample or None): T + V, the Jacobi integral h, or h with int P dt for a work balance, where
    P = Q . q_dot - dL/dt + lambda . b (b: the velocity bias of moving constraints). Under a
    controller (its power in ``power``) every kind becomes a work balance."""
    kind = invariant_kind(eom)
    if kind == InvariantKind.ENERGY:
        if controlled:
            return InvariantKind.WORK_BALANCE, energy, cumulative_work(t, power)
        return kind, energy, None
    model = eom.model
    values = StateFunction(model, [eom.jacobi_integral], substitution)(q, q_dot, t)[:, 0]
    if kind == InvariantKind.JACOBI_INTEGRAL and not controlled:
        return kind, values, None
    kind = InvariantKind.WORK_BALANCE
    supplied = np.array(power, dtype=float)
    if eom.explicit_time_power != 0:
        supplied = supplied + StateFunction(model, [eom.explicit_time_power],
                                            substitution)(q, q_dot, t)[:, 0]
    if multipliers.shape[1] and any(b != 0 for b in eom.velocity_bias):
        bias = StateFunction(model, eom.velocity_bias, substitution)(q, q_dot, t)
        supplied = supplied + np.einsum("kc,kc->k", multipliers, bias)
    return kind, values, cumulative_work(t, supplied)


def _integrate(functions, y0, grid, step_control, event, drift, progress, compiled,
               beyond=None, rhs=None) -> LoopRun:
    """The compiled DOP853 loop where it applies (and is there), else the scipy step loop.
    With position limits (``beyond``) the compiled loop's samples are checked, and a run with a
    sample at or beyond a limit is run again in the step loop, whose event finds the time the
    joint reaches it (integration_loops.touch_inside: also a touch that leaves again within one
    step, unless shorter than about an eighth of it)."""
    n = len(y0) // 2
    if compiled and step_control.method == "DOP853" and math.isinf(step_control.max_step):
        run = integrate_compiled(functions, (float(grid[0]), float(grid[-1])), y0, step_control,
                                 grid, progress)
        if run is not None and (beyond is None or not any(
                beyond(y[:n], y[n:], t) >= 0 for t, y in zip(run.t[1:], run.y[1:], strict=True))):
            return run
    if beyond is not None:
        user = event
        event = beyond if user is None else (
            lambda q, v, t: max(user(q, v, t), beyond(q, v, t)))
    return integrate_steps(rhs or functions.rhs, float(grid[0]), y0, float(grid[-1]), grid,
                           step_control, event, drift, progress)


@dataclass(frozen=True)
class JointLimit:
    """A URDF joint's limits on one coordinate: position (rad or m; None: none), velocity
    (rad/s or m/s) and effort (N m or N, on its actuator parameter), as the file gives them."""

    coordinate: int  # index in the model's coordinates
    name: str  # the coordinate's name
    joint: str  # the URDF's joint name
    lower: float | None = None
    upper: float | None = None
    unit: str = "rad"
    velocity: float | None = None
    effort: float | None = None
    actuator: str | None = None  # the parameter of its generalized force (tau_<joint>)


def urdf_limits(model, positions: bool = True) -> tuple[JointLimit, ...]:
    """A robot read from URDF: its joints' limits per coordinate (the position limits left out
    where ``positions`` is False); () for other models."""
    coordinates = {c.name: (i, c) for i, c in enumerate(model.coordinates)}
    ratings = {name: (velocity, effort) for name, velocity, effort in model.source_ratings}
    parameters = {p.name for p in model.parameters}
    out = []
    for name, joint in model.source_names:
        if name not in coordinates:
            continue
        i, c = coordinates[name]
        lower, upper = c.range if positions and c.range is not None else (None, None)
        actuator = f"tau_{name}" if f"tau_{name}" in parameters else None
        out.append(JointLimit(i, name, joint, lower, upper, c.unit,
                              *ratings.get(name, (None, None)), actuator))
    return tuple(out)


def exceeded_limits(limits: Sequence[JointLimit], parameters: Mapping[str, float], t, q_dot
              ) -> tuple[dict, ...]:
    """Velocity limits exceeded on the samples (the largest |q_dot|, and when) and effort
    limits exceeded by the actuator parameters, one record each."""
    out = []
    for limit in limits:
        if limit.velocity is not None and len(t):
            speeds = np.abs(q_dot[:, limit.coordinate])
            k = int(np.argmax(speeds))
            if speeds[k] > limit.velocity:
                out.append({"joint": limit.joint, "coordinate": limit.name,
                            "quantity": "velocity", "limit": limit.velocity,
                            "value": float(speeds[k]), "t": float(t[k]),
                            "unit": f"{limit.unit}/s"})
        value = parameters.get(limit.actuator) if limit.actuator else None
        if limit.effort is not None and value is not None and abs(value) > limit.effort:
            out.append({"joint": limit.joint, "coordinate": limit.name, "quantity": "effort",
                        "limit": limit.effort, "value": float(abs(value)), "t": None,
                        "unit": "N" if limit.unit == "m" else "N m"})
    return tuple(out)


START_LIMITS = ("refuse", "clamp", "ignore")
# A joint that starts on its limit (a clamped start, the Panda's finger at 0) counts as beyond
# it once past by this much, relative to 1 + |limit|: at 0 it would mask every other joint.
_ON_LIMIT = 1e-9


def check_start_within(limits: Sequence[JointLimit], q: np.ndarray, start: str = "refuse"
                       ) -> tuple[np.ndarray, str]:
    """A start beyond a joint's position limit (the event fires only on a crossing, so such a
    run went on without a word): refused in one line naming the joint, its value and its limit
    (``start`` "refuse"), or started at the limit ("clamp") or where it is ("ignore"), with a
    note for the result's message (empty where every joint starts inside). Returns (q, note)."""
    if start not in START_LIMITS:
        raise InputError(f"unknown start {start!r}: refuse, clamp or ignore", field="limits")
    q, notes = np.array(q, dtype=float), []
    for limit in limits:
        if limit.lower is None or limit.upper is None:
            continue
        x = float(q[limit.coordinate])
        if limit.lower <= x <= limit.upper:
            continue
        side, bound = ("below", limit.lower) if x < limit.lower else ("above", limit.upper)
        where = (f"joint '{limit.joint}' ({limit.name}) starts at {x:.6g}, {side} its position "
                 f"limit {bound:.6g} (range {limit.lower:.6g} to {limit.upper:.6g})")
        if start == "refuse":
            raise InputError(f"{where}; start it inside, clamp it to the limit or run with the "
                             "position limits ignored", field="initial")
        if start == "clamp":  # on the limit: the event sees it leave (beyond_limits)
            q[limit.coordinate] = bound
            notes.append(f"{where} {limit.unit}: clamped to the limit")
        else:
            notes.append(f"{where} {limit.unit}: started there, the limits ignored")
    return q, "; ".join(notes)


def check_start_rates(limits: Sequence[JointLimit], v: np.ndarray, start: str = "refuse"
                      ) -> tuple[np.ndarray, str]:
    """A start faster than a joint's velocity limit (a URDF <limit velocity>): refused in one
    line naming the joint, its rate and its limit (``start`` "refuse"), or started at the
    limit's speed ("clamp") or as given ("ignore"), with a note for the result's message.
    Returns (v, note)."""
    if start not in START_LIMITS:
        raise InputError(f"unknown start {start!r}: refuse, clamp or ignore", field="limits")
    v, notes = np.array(v, dtype=float), []
    for limit in limits:
        if limit.velocity is None:
            continue
        rate = float(v[limit.coordinate])
        if abs(rate) <= limit.velocity:
            continue
        where = (f"joint '{limit.joint}' ({limit.name}) starts at the rate {rate:.6g} "
                 f"{limit.unit}/s, beyond its velocity limit {limit.velocity:.6g} {limit.unit}/s")
        if start == "refuse":
            raise InputError(f"{where}; start it slower, clamp it to the limit or run with the "
                             "limits ignored", field="initial")
        if start == "clamp":
            v[limit.coordinate] = math.copysign(limit.velocity, rate)
            notes.append(f"{where}: clamped to the limit")
        else:
            notes.append(f"{where}: started so, the limits ignored")
    return v, "; ".join(notes)


def beyond_limits(limits: Sequence[JointLimit], q0: np.ndarray | None = None):
    """h(q) = the largest distance beyond a position limit (< 0 while every joint is inside):
    the event turns true when a joint reaches its limit; None without position limits. A joint
    that starts on a limit (in ``q0``) turns it true once past it by _ON_LIMIT (relative): at 0
    from the start, h would hide every other joint's crossing."""
    limits = [limit for limit in limits if limit.lower is not None and limit.upper is not None]
    if not limits:
        return None
    index = np.array([limit.coordinate for limit in limits])
    lower = np.array([limit.lower for limit in limits])
    upper = np.array([limit.upper for limit in limits])
    low_margin, high_margin = np.zeros(len(limits)), np.zeros(len(limits))
    if q0 is not None:
        x0 = np.asarray(q0, dtype=float)[index]
        low_margin = np.where(x0 <= lower, _ON_LIMIT * (1 + np.abs(lower)), 0.0)
        high_margin = np.where(x0 >= upper, _ON_LIMIT * (1 + np.abs(upper)), 0.0)

    def distances(q) -> np.ndarray:
        x = np.asarray(q, dtype=float)[index]
        return np.maximum(lower - x - low_margin, x - upper - high_margin)

    def beyond(q, v, t) -> float:
        return float(np.max(distances(q)))

    beyond.limits, beyond.distances = limits, distances  # at_limit names the one reached
    return beyond


def at_limit(run: LoopRun, limits, beyond, event, n: int) -> LoopRun:
    """A run the step loop stopped: at a joint's limit (status 'limit', the joint named) unless
    the user's stop condition turned true there first."""
    t, y = float(run.t[-1]), run.y[-1]
    h = beyond(y[:n], y[n:], t)
    if event is not None and event(y[:n], y[n:], t) > h:
        return run
    x = y[:n]
    # the joint whose distance decided h, margins included: a joint resting on its limit (0 m
    # away) was named in place of the one that crossed (-1e-13 away at the event's root)
    reached = beyond.limits[int(np.argmax(beyond.distances(x)))]
    side = reached.lower if x[reached.coordinate] < 0.5 * (reached.lower + reached.upper) \
        else reached.upper
    return replace(run, status=RunStatus.LIMIT, message=(
        f"joint '{reached.joint}' ({reached.name}) reached its position limit {side:.6g} "
        f"{reached.unit} at t = {t:.12g} s"))


_TOO_LARGE = 1e100  # beyond this a step of any size overflows somewhere in the loop


def _explain_failure(functions: NumericSystem, run: LoopRun) -> str:
    """The loop's message, with why from the last state kept: a state or an acceleration too
    large for floating point (g = 1e308, theta_dot = 1e300) makes every step size fail."""
    if "singular" in run.message.lower():
        return run.message
    n, t, y = functions.n, float(run.t[-1]), run.y[-1]
    names = [*functions.coordinates, *(f"{c}_dot" for c in functions.coordinates)]
    for name, value in zip(names, y, strict=True):
        if not abs(value) < _TOO_LARGE:
            return (f"{run.message}: {name} = {value:.3g} there is too large to integrate "
                    "(check the parameters and initial values)")
    try:
        with np.errstate(all="ignore"):
            q_ddot, _ = functions.accelerations_and_multipliers(y[:n], y[n:], t)
    except (np.linalg.LinAlgError, ValueError, ZeroDivisionError, OverflowError):
        return run.message
    q_ddot = np.ravel(q_ddot)
    if np.any(np.isnan(q_ddot)):
        return f"{run.message}: {_undefined_part(functions, y[:n], y[n:], t)}"
    for name, value in zip(functions.coordinates, q_ddot, strict=True):
        if not abs(value) < _TOO_LARGE:
            return (f"{run.message}: the acceleration of {name} is {value:.3g} there, too large "
                    "to integrate (check the parameters and initial values)")
    return run.message


def _undefined_part(functions: NumericSystem, q: np.ndarray, q_dot: np.ndarray, t: float) -> str:
    """Which part of the model is NaN at a state: T (its mass matrix), V or the forces."""
    with np.errstate(all="ignore"):
        potential = functions.energy(q, np.zeros_like(q_dot), t)
        mass = functions.mass_matrix(q, q_dot, t)
    if not np.all(np.isfinite(mass)):  # first: T at q_dot = 0 enters the energy below
        what = "the kinetic energy T (its mass matrix)"
    elif not np.all(np.isfinite(potential)):
        what = "the potential energy V"
    else:
        what = "the generalized forces"
    return (f"{what} is not a real number there (NaN: a square root or logarithm of a negative "
            "value?)")


def _project_start(drift: DriftControl, start: State):
    """Move the start onto the constraints, keeping the given values where possible; returns
    (q0, q_dot0, name -> (given, used) for the values that changed)."""
    q0, v0 = start.q_array(), start.q_dot_array()
    given = {name: name in start.given for name in start.names}
    q_new, v_new = drift.project_initial(q0, v0, start.t, given)
    projected = {}
    for name, old, new in zip(start.names, np.concatenate([q0, v0]),
                              np.concatenate([q_new, v_new]), strict=True):
        if abs(new - old) > 1e-12 * max(1.0, abs(old)):
            projected[name] = (float(old), float(new))
    return q_new, v_new, projected


def _event(g: StateFunction) -> Callable[[np.ndarray, np.ndarray, float], float]:
    def event(q, v, t) -> float:
        return float(g.at(q, v, t)[0])

    return event
