"""A simulation's report: its JSON summary (``simulate --json``, ``Simulation.summary()``) and
its text summary (``simulate``), from one SimulationResult."""

from __future__ import annotations

import math

from ..simulation.result import SimulationResult

# What each monitored quantity is, in the text summary and the plot's title.
INVARIANT_WORDS = {
    "energy": "energy T + V",
    "jacobi_integral": "Jacobi integral h = q_dot . dL/dq_dot - L",
    "work_balance": "work balance h - h0 - int P dt",
}


def simulation_summary(result: SimulationResult) -> dict:
    """JSON-ready summary: final state, steps, wall time, drift, largest residual."""
    return {
        "model": result.model_name,
        "status": result.status,
        "message": result.message,
        "method": result.method,
        "backend": result.backend,
        "rtol": result.rtol,
        "atol": result.atol,
        "t_start": float(result.t[0]),
        "t_end": result.t_end,
        "t_final": float(result.t[-1]),
        "stop_when": result.stop_when,
        "final_state": result.final_state,
        "steps": result.steps,
        "nfev": result.nfev,
        "samples": int(len(result.t)),
        "wall_time_s": result.wall_time,
        "energy_conserved": result.energy_conserved,
        "relative_energy_drift": result.energy_drift,
        "invariant": result.invariant,
        "relative_invariant_drift": result.invariant_drift,
        "max_constraint_residual": result.max_residual,
        "projected_initial_state": {
            name: {"given": given, "used": used}
            for name, (given, used) in result.projected_initial_state.items()
        },
        "limits_exceeded": [dict(record) for record in result.limits_exceeded],
        **({} if result.momenta is None else {"final_momenta": _final_momenta(result)}),
    }


def _final_momenta(result: SimulationResult) -> dict[str, float]:
    """A run in (q, p): p_<q> at the last sample (kg m/s or kg m^2/s)."""
    return {f"p_{name}": float(result.momenta[-1, i]) for i, name in enumerate(result.coordinates)}


def simulation_document(result: SimulationResult, outputs: dict[str, str]) -> dict:
    """The ``simulate --json`` document: the summary (NaN and inf as null) and the files written."""
    document = finite(simulation_summary(result))
    document["outputs"] = outputs
    return document


def simulation_text(result: SimulationResult, written: dict[str, str]) -> str:
    """The text summary: how the run ended, its cost, the final state, drift and residual."""
    lines = [f"{result.model_name}: {result.message} "
             f"({result.method}, rtol {result.rtol:g}, atol {result.atol:g}, {result.backend})"]
    steps = f"{result.steps} steps, " if result.steps is not None else ""
    lines.append(f"  {steps}{result.nfev} right-hand-side calls, wall time {result.wall_time:.3g} s")
    state = ", ".join(f"{k} = {v:.9g}" for k, v in result.final_state.items())
    lines.append(f"  final state: {state}")
    if result.momenta is not None:
        momenta = ", ".join(f"{k} = {v:.9g}" for k, v in _final_momenta(result).items())
        lines.append(f"  final momenta: {momenta}")
    if result.energy_drift is not None:
        lines.append(f"  relative energy drift: {result.energy_drift:.2e}")
    elif result.invariant_drift is not None:
        lines.append(f"  {INVARIANT_WORDS[result.invariant]}, relative drift: "
                     f"{result.invariant_drift:.2e}")
    if result.max_residual is not None:
        lines.append(f"  largest constraint residual: {result.max_residual:.2e}")
    for r in result.limits_exceeded:
        when = f" at t = {r['t']:.6g} s" if r["t"] is not None else ""
        lines.append(f"  {r['quantity']} limit exceeded: joint '{r['joint']}' ({r['coordinate']}) "
                     f"{r['value']:.6g} {r['unit']} > {r['limit']:.6g} {r['unit']}{when}")
    for path in written.values():
        lines.append(f"  wrote {path}")
    return "\n".join(lines) + "\n"


def projection_warning(result: SimulationResult) -> str | None:
    """The warning when the initial state had to be moved onto the constraints, else None.

    A move within the integrator's own error per step (atol + rtol |value|, tenfold) is the
    rounding of a state given to a dozen digits, not a violation: no warning for it."""
    control = result.step_control
    moved = {name: (given, used) for name, (given, used) in result.projected_initial_state.items()
             if abs(used - given) > 10 * (control.atol + control.rtol * abs(given))}
    if not moved:
        return None
    changes = ", ".join(f"{name} {given:.12g} -> {used:.12g}"
                        for name, (given, used) in moved.items())
    return "warning: the initial state violates the constraints; projected onto them: " + changes


def finite(value):
    """JSON has no NaN/inf: such numbers become null."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [finite(v) for v in value]
    return value
