"""Runs that cannot integrate, found in a bounded number of right-hand-side calls.

Three tests, each on the numbers the loop already has (no wall-clock timer):
- the start: accelerations not finite at t0 where one initial rate, set to 0, makes them
  finite (that rate overflows the motion: refused in one line, naming it);
- rejections: more than MAX_REJECTED steps rejected in a row, or a step size that is not a
  number (scipy's loop never ends on a NaN step: NaN < min_step is false); an implicit
  method's Jacobian that is not finite (scipy's LU raises ValueError: jacobian_failure);
- collapse: COLLAPSE_STEPS accepted steps whose mean is below the float spacing of t at the end
  time, where t + h == t: the end could only be reached by a step grown by that factor; or
  whose mean step would need more than MAX_STEPS steps in all to reach the end time (the
  compiled loop's own limit, found after its first window instead of at the limit).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence

import numpy as np

from ..errors import DynamicsWarning, InputError, LagrangianError

MAX_REJECTED = 100  # each rejection shrinks h (by 0.2 on a NaN error): 100 in a row is a collapse
COLLAPSE_STEPS = 1000  # accepted steps in one window of the collapse test
MAX_STEPS = 10_000_000  # accepted steps of a run at most (about 10 s of the compiled loop)
# right-hand-side calls of one attempted step: the explicit pairs' stages, else a Newton
# solve's few calls and a finite-difference Jacobian's one per state (Radau, BDF, LSODA)
_STAGES = {"DOP853": 12, "RK45": 6, "RK23": 3}


class StepCollapse(Exception):
    """The loop cannot go on: ``message`` says why (rejections, a NaN step, a collapse, or
    for an implicit method a derivative that is not finite)."""

    def __init__(self, message: str):
        super().__init__(message)
        self.message = message


def end_spacing(t0: float, t_end: float) -> float:
    """The float spacing of t at the end of the run (s): a step below it leaves t unchanged."""
    return float(np.spacing(max(abs(t0), abs(t_end))))


def collapse_message(steps: int, t_from: float, t_to: float, spacing: float,
                     t_end: float | None = None, taken: int = 0) -> str | None:
    """Why ``steps`` accepted steps from ``t_from`` to ``t_to`` (s) are a collapse, or None:
    their mean step is below ``spacing``, the float spacing of t at the end time, or at that
    mean step the run would pass MAX_STEPS (``taken`` so far) before ``t_end``."""
    if steps <= 0:
        return None
    mean, stopped = (t_to - t_from) / steps, f" (stopped at t = {t_to:.9g} s)"
    if mean < spacing:
        return (f"the step size collapsed: {steps} steps took t only from {t_from:.9g} to "
                f"{t_to:.9g} s, a mean step of {mean:.3g} s, below the float spacing "
                f"{spacing:.3g} s of t at the end time{stopped}")
    needed = math.inf if t_end is None else (t_end - t_to) / mean
    if t_end is not None and taken + needed > MAX_STEPS:
        return (f"the step size collapsed: at the mean step of its last {steps} steps, "
                f"{mean:.3g} s, the run would need about {needed:.2g} more to reach the end "
                f"time {t_end:.9g} s, past the limit of {MAX_STEPS:,} steps{stopped}")
    return None


class GuardedRhs:
    """fun(t, y) counted, raising StepCollapse on a NaN step or MAX_REJECTED rejections in a
    row; ``accepted(t)`` after each accepted step runs the collapse test on its window."""

    def __init__(self, fun: Callable, method: str, size: int, t0: float, t_end: float):
        self.fun, self.calls, self.since = fun, 0, 0
        self.cap = MAX_REJECTED * _STAGES.get(method, size + 10)
        self.implicit = method not in _STAGES  # Radau, BDF, LSODA: a Jacobian's LU
        self.not_finite: float | None = None  # the first t (s) of a derivative not finite
        self.spacing, self.t_end = end_spacing(t0, t_end), float(t_end)
        self.window_t, self.window_steps, self.t, self.taken = t0, 0, t0, 0

    def __call__(self, t, y):
        self.calls += 1
        self.since += 1
        if not math.isfinite(t):
            raise StepCollapse(f"the step size is not a number (a derivative at "
                               f"t = {self.t:.9g} s is not finite)")
        if self.since > self.cap:
            raise StepCollapse(f"the step size collapsed: {MAX_REJECTED} steps rejected in a "
                               f"row (stopped at t = {self.t:.9g} s)")
        value = self.fun(t, y)
        if self.implicit and self.not_finite is None and not np.all(np.isfinite(value)):
            self.not_finite = float(t)  # its LU will refuse the Jacobian: jacobian_failure
        return value

    def jacobian_failure(self) -> StepCollapse | None:
        """The ValueError of an implicit method's LU (a Jacobian not finite) as a stop, where
        a derivative was not finite; None where none was (the error is another's)."""
        if self.not_finite is None:
            return None
        return StepCollapse(f"the accelerations are not finite at t = {self.not_finite:.9g} s, "
                            f"and the implicit method's Jacobian with them (stopped at "
                            f"t = {self.t:.9g} s)")

    def accepted(self, t: float) -> None:
        """After an accepted step to ``t`` (s): raise StepCollapse where the window's mean
        step is below the end time's float spacing, or too short to end within MAX_STEPS."""
        self.since, self.t = 0, float(t)
        self.window_steps += 1
        self.taken += 1
        if self.window_steps < COLLAPSE_STEPS:
            return
        why = collapse_message(self.window_steps, self.window_t, self.t, self.spacing,
                               self.t_end, self.taken)
        if why:
            raise StepCollapse(why)
        self.window_t, self.window_steps = self.t, 0


def check_start(rhs: Callable, t0: float, y0: np.ndarray, rates: Sequence[str],
                given: Sequence[str] = ()) -> int:
    """Refuse a start whose accelerations are not finite at t0 because of one rate: the
    largest rate (rad/s or m/s) whose value set to 0 makes them finite is named (field
    initial.<name>). ``rates`` names y0's last len(rates) entries; returns the calls made."""
    calls = 1
    finite = _finite_rhs(rhs, t0, y0)
    if finite is not False:  # finite, or a fault of its own (singular M): the loop's to report
        return calls
    first = len(y0) - len(rates)
    for i in sorted(range(first, len(y0)), key=lambda k: -abs(y0[k])):
        if y0[i] == 0:
            break
        trial = np.array(y0, dtype=float)
        trial[i] = 0.0
        calls += 1
        if _finite_rhs(rhs, t0, trial):
            name = rates[i - first]
            where = "initial." + name if name in given else None
            what = "" if where else f"the initial rate {name} = "
            raise InputError(f"{what}{y0[i]:.6g} makes the motion overflow (the accelerations "
                             f"are not finite at t = {t0:.9g} s)", field=where)
    return calls


def _finite_rhs(rhs: Callable, t: float, y: np.ndarray) -> bool | None:
    """Whether rhs(t, y) is finite; None where it raises (a singular M: not an overflow)."""
    try:  # a probe: its NaN rows are not the user's to be warned about
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", DynamicsWarning)
            return bool(np.all(np.isfinite(rhs(t, y))))
    except (ArithmeticError, ValueError, np.linalg.LinAlgError, LagrangianError):
        return None
