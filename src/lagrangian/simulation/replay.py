"""An open-loop input u(t) replayed through a right-hand side x' = f(x, u(t)) by DOP853, for
checking a collocated trajectory against an accurate integration (control/optimize.py)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def replay(rhs: Callable[[np.ndarray, np.ndarray], np.ndarray],
           input_at: Callable[[float], np.ndarray], t: np.ndarray, x0: np.ndarray,
           tolerance: float = 1e-10) -> np.ndarray | None:
    """The states at the times ``t`` (s) from x0 under u(t), rtol = atol = ``tolerance``, steps
    at most half a node interval (u has kinks at the nodes); None where the run fails."""
    from scipy.integrate import solve_ivp

    def f(time, y):
        return np.asarray(rhs(y, input_at(time)), dtype=float).ravel()

    step = float(np.min(np.diff(t))) / 2
    run = solve_ivp(f, (t[0], t[-1]), x0, method="DOP853", t_eval=t, rtol=tolerance,
                    atol=tolerance, max_step=step)
    if not run.success or run.y.shape[1] != len(t):
        return None
    return run.y


__all__ = ["replay"]
