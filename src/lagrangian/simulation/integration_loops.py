"""The two integration loops: DOP853 in compiled C, and scipy's solvers stepped by hand.

Both save onto a time grid (dense output), report progress and keep what was computed when
a step fails or the user presses Ctrl-C; the scipy loop also stops at a stop condition and
projects constrained states after each step (simulation/drift.py).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..compile.functions import NumericSystem
from ..kinds import RunStatus
from .drift import DriftControl
from .guards import (
    COLLAPSE_STEPS,
    MAX_STEPS,
    GuardedRhs,
    StepCollapse,
    collapse_message,
    end_spacing,
)
from .options import StepControl
from .result import STATUS_MESSAGES


@dataclass(frozen=True)
class LoopRun:
    """The states y = [q, q_dot] at the saved times t, and how the loop ended."""

    t: np.ndarray
    y: np.ndarray
    status: str
    message: str
    steps: int | None
    nfev: int
    backend: str = "scipy"  # or "compiled": the DOP853 loop in C


def integrate_compiled(functions: NumericSystem, t_span: tuple[float, float], y0: np.ndarray,
                       step: StepControl, grid: np.ndarray,
                       progress: Callable[[float], None] | None = None) -> LoopRun | None:
    """The compiled integration loop of simulation.compiled_loop when it is there; None to fall back.

    With a ``progress`` callback the run goes in pieces between output samples (a first short
    piece times the loop; the rest in one call when it will take under a second), so a long run
    can report progress; Ctrl-C inside the C loop keeps the states computed so far.
    """
    try:
        from .compiled_loop import integrate_fast
    except ImportError:
        return None
    spacing = end_spacing(float(grid[0]), float(grid[-1]))
    pieces = [(0, len(grid) - 1)]
    if progress is not None and len(grid) > 2:
        first = max(1, (len(grid) - 1) // 100)
        pieces = [(0, first), (first, len(grid) - 1)]
    ts, ys, nfev, steps = [], [], 0, 0
    y_start = y0
    status, message = RunStatus.FINISHED, STATUS_MESSAGES["finished"]
    while pieces:
        a, b = pieces.pop(0)
        began = time.perf_counter()
        result, tries = _piece(integrate_fast, functions, grid, a, b, y_start, step, spacing,
                               steps or 0)
        if result is None:
            return None
        nfev += tries
        t = np.asarray(result.t, dtype=float)
        y = np.asarray(result.y, dtype=float).reshape(len(t), len(y_start))
        skip = 1 if ts and len(t) and t[0] == ts[-1][-1] else 0
        ts.append(t[skip:])
        ys.append(y[skip:])
        nfev += int(result.nfev)
        piece_steps = getattr(result, "steps", getattr(result, "nsteps", None))
        steps = None if piece_steps is None or steps is None else steps + int(piece_steps)
        if not result.success:
            text = str(result.message).rstrip(".")
            status = RunStatus.INTERRUPTED if text.lower().startswith("interrupted") \
                else RunStatus.FAILED
            reached = float(t[-1]) if len(t) else float(grid[a])
            message = text if "t =" in text else f"{text} (stopped at t = {reached:.9g} s)"
            break
        if progress is not None:
            try:
                progress(float(t[-1]))
            except KeyboardInterrupt:
                if not pieces:  # the run was complete already
                    break
                status = RunStatus.INTERRUPTED
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
    if not any(len(piece) for piece in ts):  # failed at the first step: keep the start
        ts, ys = [grid[:1].astype(float)], [np.asarray(y0, dtype=float)[None, :]]
    return LoopRun(np.concatenate(ts), np.concatenate(ys), status, message, steps, nfev,
                   "compiled")


def _piece(integrate_fast, functions, grid, a, b, y_start, step, spacing, taken):
    """One piece of the compiled loop, grid[a] to grid[b], with the collapse test: first at
    most COLLAPSE_STEPS steps, then as many as their mean step says the piece needs (x10 at
    least); a capped try whose mean step is below the end time's float spacing, or would pass
    MAX_STEPS in all (``taken`` before the piece), is a collapse. Returns (the result, the
    calls of the tries before it)."""
    from .compiled_loop import STEP_LIMIT, FastResult

    t_a, t_b, cap, tries = float(grid[a]), float(grid[b]), COLLAPSE_STEPS, 0
    while True:
        result = integrate_fast(functions, (t_a, t_b), y_start, rtol=step.rtol, atol=step.atol,
                                t_eval=grid[a:b + 1], max_steps=cap)
        if result is None or result.status != STEP_LIMIT or cap >= MAX_STEPS:
            return result, tries
        why = collapse_message(cap, t_a, result.t_reached, spacing, float(grid[-1]), taken)
        if why:
            return FastResult(result.t, result.y, result.nfev, False, why, result.steps,
                              result.status, result.t_reached), tries
        tries += result.nfev
        mean = (result.t_reached - t_a) / cap
        cap = int(min(MAX_STEPS, max(10 * cap, 2 * (t_b - t_a) / mean)))


def integrate_steps(fun: Callable[[float, np.ndarray], np.ndarray], t0: float, y0: np.ndarray,
                    t_end: float, grid: np.ndarray, step: StepControl,
                    event: Callable | None = None, drift: DriftControl | None = None,
                    progress: Callable[[float], None] | None = None) -> LoopRun:
    """Step a scipy OdeSolver by hand: dense output onto the grid, events, projection, Ctrl-C."""
    # scipy is imported where it is used: at module level it cost every command (derive
    # included) half a second of start-up.
    from scipy import integrate

    solver_class = getattr(integrate, step.method)
    guarded = GuardedRhs(fun, step.method, len(y0), t0, t_end)  # rejections, NaN h, collapse

    def start(t, y, first_step=None):
        return solver_class(guarded, t, y, t_end, rtol=step.rtol, atol=step.atol,
                            max_step=step.max_step, first_step=first_step)

    ts, ys = [t0], [y0.copy()]
    index = 1
    status, message = RunStatus.FINISHED, STATUS_MESSAGES["finished"]
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
                    status = RunStatus.FAILED
                    message = (f"{(failure or 'the step failed').rstrip('.')} "
                               f"(stopped at t = {solver.t:.9g} s)")
                    break
                if not np.all(np.isfinite(solver.y)):
                    status = RunStatus.FAILED
                    message = ("the state became infinite or NaN "
                               f"(stopped at t = {solver.t_old:.9g} s)")
                    break
                steps += 1
                guarded.accepted(solver.t)
                dense = solver.dense_output()
                t_stop, hit = solver.t, False
                if event is not None:
                    g_new = event(solver.y[:n], solver.y[n:], solver.t)
                    touch = None if not armed or g_new >= 0 else touch_inside(
                        event, dense, solver.t_old, solver.t, n)
                    if armed and (g_new >= 0 or touch is not None):
                        end = solver.t if touch is None else touch
                        t_stop, hit = crossing_time(event, dense, solver.t_old, end, n), True
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
                    status, message = RunStatus.STOPPED, f"stop condition met at t = {t_stop:.12g} s"
                    break
                if drift is not None and solver.status == "running":
                    solver = drift.correct(solver, start)
                if progress is not None:
                    progress(solver.t)
    except KeyboardInterrupt:
        status = RunStatus.INTERRUPTED
        message = f"interrupted by the user (Ctrl-C) at t = {_reached(solver, t0):.9g} s"
    except StepCollapse as collapse:
        status, message = RunStatus.FAILED, collapse.message
    except ValueError:  # Radau's or BDF's LU of a Jacobian that is not finite
        collapse = guarded.jacobian_failure()
        if collapse is None:
            raise
        status, message = RunStatus.FAILED, collapse.message
    except np.linalg.LinAlgError:
        status = RunStatus.FAILED
        message = ("singular mass matrix (or constraint Jacobian without full rank) "
                   f"near t = {_reached(solver, t0):.9g} s")
    if status in (RunStatus.FAILED, RunStatus.INTERRUPTED) and solver is not None and solver.t > ts[-1] \
            and np.all(np.isfinite(solver.y)):
        ts.append(float(solver.t))
        ys.append(np.array(solver.y, dtype=float))
    nfev = nfev_done + (solver.nfev if solver is not None else 0)
    if drift is not None:
        nfev += drift.nfev
    return LoopRun(np.array(ts), np.array(ys), status, message, steps, int(nfev))


def _reached(solver, t0: float) -> float:
    return float(solver.t) if solver is not None else float(t0)


# where a step's dense output is looked at between its ends: a condition (a guard, a stop
# condition, a joint limit) that turns true and back within one step shows there, unless it
# stays true for less than about an eighth of the step
INSIDE = tuple(k / 8 for k in range(1, 8))


def touch_inside(event, dense, t_old: float, t_new: float, n: int) -> float | None:
    """The first of the step's inner points (INSIDE) where the event function is >= 0 though
    both ends are < 0 (a touch that leaves again within the step), else None."""
    for fraction in INSIDE:
        t = t_old + fraction * (t_new - t_old)
        y = dense(t)
        if event(y[:n], y[n:], t) >= 0:
            return t
    return None


def crossing_time(event, dense, t_old: float, t_new: float, n: int) -> float:
    """The time in [t_old, t_new] where the event function event(y[:n], y[n:], t) turns from
    negative to >= 0 (y = [q, v]; n the length of q)."""
    def g(t):
        y = dense(t)
        return event(y[:n], y[n:], t)

    if g(t_old) >= 0:
        return t_old
    from scipy import optimize

    return float(optimize.brentq(g, t_old, t_new, xtol=1e-15 * max(1.0, abs(t_new)),
                                 rtol=4 * np.finfo(float).eps, maxiter=200))
