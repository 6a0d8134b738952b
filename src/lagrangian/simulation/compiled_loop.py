"""Adaptive DOP853 integration of an unconstrained NumericSystem with the loop outside Python.

The integrator is C code compiled into the model's module (template.c), calling the generated
right-hand side directly: no Python per step.

Same method and error control as scipy's ``solve_ivp(method="DOP853")`` (Hairer's coefficients),
so step counts and accuracy are comparable; returns None when it cannot be used.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..compile.functions import NumericSystem
from .guards import MAX_STEPS


@dataclass(frozen=True)
class FastResult:
    """States y = [q, q_dot] (SI) at times t (s), and how the integration went."""

    t: np.ndarray  # (k,)
    y: np.ndarray  # (k, 2n)  states [q, q_dot]
    nfev: int
    success: bool
    message: str
    steps: int = 0  # accepted steps
    status: int = 0  # the C loop's code: _MESSAGES (1: max_steps reached)
    t_reached: float = 0.0  # s: the time the loop got to


STEP_LIMIT = 1  # the C loop's status when it reached max_steps

_MESSAGES = {
    0: "The solver successfully reached the end of the integration interval.",
    1: "Reached the limit of {max_steps} steps at t = {t:.17g} s.",
    2: "Required step size is less than spacing between numbers at t = {t:.17g} s.",
    3: "Singular mass matrix at t = {t:.17g} s.",
    4: "Out of memory at t = {t:.17g} s.",
    5: "Interrupted at t = {t:.17g} s; the states computed so far are kept.",
}


def integrate_fast(
    functions: NumericSystem,
    t_span: tuple[float, float],
    y0: np.ndarray,
    *,
    rtol: float,
    atol: float,
    t_eval: np.ndarray | None = None,
    max_steps: int = MAX_STEPS,
) -> FastResult | None:
    """Integrate y' = rhs(t, y), y = [q, q_dot], over t_span (s) by DOP853 in compiled C.

    Records every accepted step, or the 7th-order dense output at ``t_eval`` (as scipy does).
    Returns None for constrained systems and without the C backend; a failure (step size
    underflow, singular M, Ctrl-C) returns the states up to the time reached, success False.
    """
    kernel = functions._kernel
    if functions.m or getattr(kernel, "backend", None) != "c":
        return None
    t0, t1 = (float(v) for v in t_span)
    y0 = np.ascontiguousarray(y0, dtype=float)
    if y0.shape != (2 * functions.n,):
        raise ValueError(f"y0 must hold {2 * functions.n} numbers [q, q_dot], not shape {y0.shape}")
    if not (np.isfinite(t0) and np.isfinite(t1)):
        raise ValueError("t_span must be finite")
    if not (rtol > 0 and atol >= 0):
        raise ValueError("rtol must be positive and atol non-negative")
    if t_eval is not None:
        t_eval = np.ascontiguousarray(t_eval, dtype=float)
        if t_eval.ndim != 1:
            raise ValueError("t_eval must be 1-dimensional")
        if np.any(t_eval < min(t0, t1)) or np.any(t_eval > max(t0, t1)):
            raise ValueError("values in t_eval are not within t_span")
        steps = np.diff(t_eval)
        if (t1 >= t0 and np.any(steps <= 0)) or (t1 < t0 and np.any(steps >= 0)):
            raise ValueError("values in t_eval are not properly sorted")
    t, y, nfev, steps, status, t_reached = kernel.module.dop853(
        kernel.parameter_values, t0, t1, y0, float(rtol), float(atol), t_eval, int(max_steps))
    message = _MESSAGES[status].format(max_steps=max_steps, t=t_reached)
    return FastResult(t=t, y=y, nfev=int(nfev), success=status == 0, message=message,
                      steps=int(steps), status=int(status), t_reached=float(t_reached))
