"""Impacts and limit cycles in words and JSON: the impacts of a run (``simulate``) and a
walker's cycle (``cycle``), from the library's ImpactRecord and LimitCycle."""

from __future__ import annotations

from .simulation import finite

SHOWN_IMPACTS = 10  # the text lists the first ones; --json lists them all


def impacts_document(run) -> dict:
    """``simulate --json``'s impacts: each one (t, name, before, after, impulse in N s, energy
    lost in J, residual), their count and where they accumulate (s, or null)."""
    return finite({"count": len(run.impacts),
                   "accumulation_time": run.accumulation_time,
                   "list": [record.to_dict() for record in run.impacts]})


def impacts_text(run) -> str:
    """The impacts of a run, the first SHOWN_IMPACTS of them one a line."""
    records = run.impacts
    if not records:
        return "  no impact\n"
    lines = [f"  {len(records)} impact{'s' if len(records) != 1 else ''}:"]
    for record in records[:SHOWN_IMPACTS]:
        impulse = ", ".join(f"{x:.6g}" for x in record.impulse)
        lines.append(f"    t = {record.time:.12g} s  {record.name}: impulse ({impulse}) N s, "
                     f"energy lost {record.energy_lost:.6g} J")
    if len(records) > SHOWN_IMPACTS:
        lines.append(f"    ... {len(records) - SHOWN_IMPACTS} more (--json lists them all)")
    if run.accumulation_time is not None:
        lines.append(f"  impacts accumulate at t = {run.accumulation_time:.12g} s")
    return "\n".join(lines) + "\n"


def cycle_document(cycle) -> dict:
    """``cycle --json``: state (just after the impact), period (s), multipliers as [re, im],
    stable, the impact, Newton's iterations and the residual |P(x) - x|."""
    return finite(cycle.to_dict())


def cycle_text(cycle, model_name: str) -> str:
    """The cycle in words: period, stability, multipliers and the state after the impact."""
    kind = {"stable": "a stable", "unstable": "an unstable",
            "neutral": "a neutrally stable"}[cycle.stability]
    lines = [f"{model_name}: {kind} limit cycle through '{cycle.impact}', period "
             f"{cycle.period:.10g} s"]
    if cycle.stability == "neutral":  # not asymptotically stable: a perturbed start stays off
        lines.append("  a multiplier on the unit circle: nearby starts keep their own cycles "
                     "(a family of them), neither drawn back nor driven away")
    lines.append("  multipliers (linearized Poincare map): " + ", ".join(
        _complex(m) + f" (|{abs(m):.6g}|)" for m in cycle.multipliers))
    lines.append("  state just after the impact: " + ", ".join(
        f"{k} = {v:.10g}" for k, v in cycle.state.items()))
    lines.append(f"  Newton: {cycle.iterations} iterations, |P(x) - x| = {cycle.residual:.2e}")
    return "\n".join(lines) + "\n"


def _complex(m: complex) -> str:
    if abs(m.imag) < 1e-12 * max(1.0, abs(m)):
        return f"{m.real:.8g}"
    return f"{m.real:.8g}{m.imag:+.8g}i"
