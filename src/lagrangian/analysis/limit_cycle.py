"""Periodic orbits through impacts (a walker's gait, a rimless wheel rolling down a slope):
the fixed point of the Poincare map on the section just after an impact, found by Newton's
method on P(x) - x with the map's exact Jacobian (simulation/poincare.py), and its multipliers.

The multipliers are the eigenvalues of DP at the fixed point less the one of the flow's own
direction (0: a start moved along the orbit returns to the same point); the cycle is stable
when every one is inside the unit circle. Units SI.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..model.values import resolve_state
from ..simulation.options import StepControl
from ..simulation.poincare import PoincareMap

TOLERANCE = 1e-10  # |P(x) - x| at convergence, relative to max(1, |x|)
MAX_ITERATIONS = 40
WARM_UP = 3  # plain returns of the map before Newton (a start off the section lands on it)
CYCLE_STEPS = StepControl(rtol=1e-11, atol=1e-11)
NEUTRAL = 1e-6  # |m| within this of 1 is on the unit circle (to the map's integration tolerance)


@dataclass(frozen=True)
class LimitCycle:
    """A periodic orbit through impacts: ``state`` just after its impact (by coordinate and
    velocity name, SI), ``period`` (s), ``multipliers`` (eigenvalues of the linearized
    Poincare map, the flow direction's 0 left out, largest first), ``stable``."""

    state: dict[str, float]
    period: float
    multipliers: tuple[complex, ...]
    stable: bool
    impact: str
    iterations: int
    residual: float
    monodromy: np.ndarray = field(repr=False, compare=False)

    @property
    def stability(self) -> str:
        """'stable' (every multiplier inside the unit circle), 'unstable' (one outside), or
        'neutral' (none outside, one on it: a family of cycles, an elastic ball's bounces)."""
        if self.stable:
            return "stable"
        return "unstable" if any(abs(m) > 1 + NEUTRAL for m in self.multipliers) else "neutral"

    def to_dict(self) -> dict:
        """JSON-ready: state, period, multipliers as [re, im], stable, stability, impact,
        residual."""
        return {"state": dict(self.state), "period": self.period,
                "multipliers": [[float(m.real), float(m.imag)] for m in self.multipliers],
                "stable": self.stable, "stability": self.stability, "impact": self.impact,
                "iterations": self.iterations, "residual": self.residual}

    def __repr__(self) -> str:
        values = ", ".join(f"{k} = {v:.9g}" for k, v in self.state.items())
        shown = ", ".join(_complex(m) for m in self.multipliers)
        return (f"LimitCycle(period = {self.period:.9g} s, {self.stability}; after '{self.impact}': "
                f"{values}; multipliers {shown})")

    def _repr_html_(self) -> str:
        rows = "".join(f"<tr><td>{k}</td><td>{v:.9g}</td></tr>" for k, v in self.state.items())
        shown = ", ".join(_complex(m) for m in self.multipliers)
        return (f"<p>Limit cycle through '{self.impact}': period {self.period:.9g} s, "
                f"{self.stability}; multipliers {shown}</p>"
                f"<table><tr><th>just after the impact</th><th>value (SI)</th></tr>{rows}"
                "</table>")


def _complex(m: complex) -> str:
    if abs(m.imag) < 1e-12 * max(1.0, abs(m)):
        return f"{m.real:.9g}"
    return f"{m.real:.9g}{m.imag:+.9g}j"


def limit_cycle(eom, substitution, functions, guess=None, *, step_control=CYCLE_STEPS,
                tolerance=TOLERANCE, max_iterations=MAX_ITERATIONS, maps=None) -> LimitCycle:
    """The periodic orbit through the model's impacts nearest ``guess`` (a state by name just
    after an impact; None: the model's initial state, first carried to an impact); ``maps``
    the derived impact maps where they are at hand."""
    model = eom.model
    if not model.impacts:
        raise InputError("the model has no impacts ([[impacts]]): no cycle through one",
                         field="impacts")
    n = len(model.coordinates)
    poincare = _poincare_map(eom, substitution, functions, step_control, maps)
    start = resolve_state(model, guess, field="guess", time=False,
                          what="coordinate or velocity")
    x = np.concatenate([start.q_array(), start.q_dot_array()])
    # what a failure names: the guess given, else the model's initial state (its coordinates)
    field, origin = ("guess", "the guess") if guess is not None else (
        "coordinates", "the model's initial state")
    returns: list[float] = []  # the plain returns' periods, before Newton
    if guess is None:
        for _ in range(WARM_UP):
            x, period, *_ = poincare(x, field=field)
            returns.append(period)
    for iteration in range(1, max_iterations + 1):
        try:
            x_next, period, name, DP = poincare(x, jacobian=True, field=field)
        except InputError as exc:
            _accumulating(returns, exc, field)
            raise
        residual = x_next - x
        scale = max(1.0, float(np.max(np.abs(x))))
        if float(np.max(np.abs(residual))) < tolerance * scale:
            flow = functions.rhs(0.0, x)
            return _cycle(model, x, period, name, DP, iteration, residual, flow)
        step = np.linalg.lstsq(DP - np.eye(2 * n), -residual, rcond=None)[0]
        x = x + _bounded(step, scale)
        if not np.all(np.isfinite(x)):
            break
    raise InputError(f"no limit cycle found from {origin} ({max_iterations} Newton steps "
                     "did not converge): give a guess nearer the cycle or "
                     "check the slope and parameters", field=field)


_MAPS: dict = {}  # the last few Poincare maps: their compiled sensitivities cost 0.4-0.7 s
_MAPS_KEPT = 8


def _poincare_map(eom, substitution, functions, step_control, maps) -> PoincareMap:
    """The Poincare map of these equations at these parameter values, built once: a second
    limit_cycle() of a System (or of a model loaded again: the derivation is shared by content)
    reuses its compiled flow sensitivities and impact derivatives."""
    key = (id(eom), id(functions), step_control,
           tuple(sorted((str(k), str(v)) for k, v in substitution.items())),
           None if maps is None else tuple(id(m) for m in maps))
    found = _MAPS.get(key)
    if found is not None and found[0] is eom and found[1] is functions:
        return found[2]
    if len(_MAPS) >= _MAPS_KEPT:
        _MAPS.pop(next(iter(_MAPS)))
    poincare = PoincareMap(eom, substitution, functions, step_control, maps)
    # eom and functions kept with it, so their ids stay theirs while the entry lives
    _MAPS[key] = (eom, functions, poincare, maps)
    return poincare


def _accumulating(returns: list[float], exc: InputError, field: str) -> None:
    """Raise the accumulation's own line where each plain return was shorter than the last
    (a ball with e < 1: the bounces shrink to rest, a point Newton then lands on)."""
    returns = returns[1:]  # the first runs from the start to an impact: not a return
    if len(returns) >= 2 and all(b < a for a, b in zip(returns[:-1], returns[1:], strict=True)):
        shown = " -> ".join(f"{p:.4g}" for p in returns)
        raise InputError(f"no limit cycle: the impacts accumulate (each return is shorter: "
                         f"{shown} s), so the motion comes to rest with no periodic orbit "
                         "(every impact loses energy that nothing gives back)",
                         field=field) from exc


def _bounded(step, scale, largest=0.5):
    size = float(np.max(np.abs(step)))
    return step if size <= largest * scale else step * (largest * scale / size)


def _cycle(model, x, period, name, DP, iterations, residual, flow) -> LimitCycle:
    eigenvalues, vectors = np.linalg.eig(DP)
    # the flow direction's: DP f(x*) = 0 (the zero eigenvalue whose vector is along the flow)
    along = np.abs(vectors.conj().T @ flow) / max(float(np.linalg.norm(flow)), 1e-300)
    small = np.abs(eigenvalues) < 1e-6 * max(1.0, float(np.max(np.abs(eigenvalues))))
    trivial = int(np.argmax(np.where(small, along, -1.0))) if small.any() \
        else int(np.argmin(np.abs(eigenvalues)))
    kept = sorted(np.delete(eigenvalues, trivial), key=lambda m: -abs(m))
    names = [c.name for c in model.coordinates] + [c.velocity.name for c in model.coordinates]
    state = {k: float(v) for k, v in zip(names, x, strict=True)}
    multipliers = tuple(complex(m) for m in kept)
    return LimitCycle(state, float(period), multipliers,
                      bool(all(abs(m) < 1 for m in multipliers)), name, iterations,
                      float(np.max(np.abs(residual))), DP)


__all__ = ["LimitCycle", "limit_cycle"]
