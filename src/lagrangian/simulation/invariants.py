"""Which quantity a run should conserve, asked of the symbolic equations once per run, and
the work that changes it.

The derivation decides (EquationsOfMotion.invariant_kind, by value): "energy" (T + V), the
"jacobi_integral" h = q_dot . dL/dq_dot - L (conserved when L has no explicit t and no load does
work: a rotating frame, a charged particle), or a "work_balance" h(t) - h(0) - int P dt = 0 with
P the power of the loads that do work, dissipation, explicit time and moving constraints.
"""

from __future__ import annotations

import numpy as np

from ..derivation.equations import EquationsOfMotion
from ..kinds import InvariantKind

INVARIANTS = tuple(InvariantKind)


def invariant_kind(eom: EquationsOfMotion) -> str:
    """'energy', 'jacobi_integral' or 'work_balance' (see the module docstring)."""
    return eom.invariant_kind


def energy_is_conserved(eom: EquationsOfMotion) -> bool:
    """T + V itself is conserved (the published ``energy_conserved``)."""
    return eom.invariant_kind == InvariantKind.ENERGY


def relative_drift(change: np.ndarray, initial: float, others=(), *,
                   against_others: bool = False) -> float:
    """max |change| relative to the size of the quantity: |I0|, or where I0 is near zero (below
    1e-9 of the largest of ``others``: kinetic energy, work done, J) the largest of them; with
    ``against_others`` the largest of all (a work balance). Dimensionless."""
    scale = abs(float(initial))
    sizes = [float(np.max(np.abs(x))) for x in others if x is not None and len(x)]
    if sizes and (against_others or scale <= 1e-9 * max(sizes)):
        scale = max([scale, *sizes]) if against_others else max(sizes)
    return float(np.max(np.abs(change))) / scale if scale > 0 else 0.0


def energy_drift(energy: np.ndarray, kinetic: np.ndarray | None = None) -> float:
    """max |E - E0| / |E0| of a run's energy samples (relative to the largest T where E0 = 0).
    The one definition: SimulationResult.energy_drift and the compiled ensembles' summary
    (compile/template_ensemble.c lg_summary, tested against this) agree with it."""
    return relative_drift(energy - energy[0], energy[0], () if kinetic is None else (kinetic,))


def cumulative_work(t: np.ndarray, power: np.ndarray) -> np.ndarray:
    """int_t0^t P dt at every sample (J): Simpson's rule on the saved samples (trapezoids for
    fewer than three), so the balance closes to the integration and sampling accuracy."""
    if len(t) < 3:
        steps = np.diff(t) * (power[1:] + power[:-1]) / 2 if len(t) > 1 else np.zeros(0)
        return np.concatenate([[0.0], np.cumsum(steps)])
    from scipy.integrate import cumulative_simpson

    return cumulative_simpson(power, x=t, initial=0.0)
