"""Ensembles by the compiled DOP853 loop of a model's C module: parameters and initial state per
member, a whole chunk of members in one C call without the GIL (SI units)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def integrate_member(module, parameters: np.ndarray, y0: np.ndarray, grid: np.ndarray,
                     rtol: float, atol: float, max_steps: int = 10_000_000):
    """One ensemble member by the compiled DOP853 loop onto ``grid`` (s): (t, y, status, t_reached);
    status 0 when it reached the end (the codes of simulation/compiled_loop.py otherwise)."""
    t, y, _, _, status, t_reached = module.dop853(
        np.ascontiguousarray(parameters, float), float(grid[0]), float(grid[-1]),
        np.ascontiguousarray(y0, float), float(rtol), float(atol), grid, int(max_steps))
    return t, np.asarray(y).reshape(len(t), -1), int(status), float(t_reached)


@dataclass(frozen=True)
class EnsembleRun:
    """Per-member summaries of an ensemble integrated onto a common grid (SI; NaN where a member
    failed): final state, extremes over the samples, end time (s), energy drift, the loop's status
    code (0: reached the end; simulation/compiled_loop.py's codes otherwise), the time reached (s), and the
    samples (members x times x 2n) when asked."""

    final: np.ndarray
    minimum: np.ndarray
    maximum: np.ndarray
    t_final: np.ndarray
    drift: np.ndarray
    status: np.ndarray
    t_reached: np.ndarray
    trajectory: np.ndarray | None


def integrate_ensemble(module, parameters: np.ndarray, y0: np.ndarray, grid: np.ndarray,
                       rtol: float, atol: float, max_steps: int = 10_000_000,
                       trajectories: bool = False, vector: bool = True) -> EnsembleRun:
    """Every member (rows of ``parameters`` and ``y0``) by the module's DOP853 loop onto
    ``grid`` (s) in one C call without the GIL: the same steps as ``integrate_member`` per
    member, several members per vector instruction where the module has a vector kernel
    (``module.lanes`` > 1, unless ``vector`` is False)."""
    parameters = np.ascontiguousarray(parameters, float)
    y0 = np.ascontiguousarray(y0, float)
    grid = np.ascontiguousarray(grid, float)
    run = module.ensemble(parameters, y0, grid, float(rtol), float(atol), int(max_steps),
                          bool(trajectories), bool(vector))
    return EnsembleRun(*run)


__all__ = ["EnsembleRun", "integrate_ensemble", "integrate_member"]
