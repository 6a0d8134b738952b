"""The mechanism's geometry as numbers: particle positions, body bars, spring and damper ends.

Positions come from the model (particle and body positions, body angles), in the plane, in m.
A spring or damper given ``between`` two points has its kept ends, exactly. A spring given by its
length only gets end points guessed from that length (see ``spring_end_points``), or none when
none fit; a damper given by its rate only has none. output/animation.py draws what this gives.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import sympy as sp

from ..model.model import Model
from ..model.values import ParameterValues, resolve_parameters
from .lambdified import StateFunction


class Frame(NamedTuple):
    """Batched positions (m) at k instants: particles (k, P, 2), bar ends (k, B, 2, 2), spring
    ends (k, S, 2, 2), damper ends (k, D, 2, 2)."""

    particles: np.ndarray
    bars: np.ndarray
    springs: np.ndarray
    dampers: np.ndarray


@dataclass(frozen=True)
class Mechanism:
    """Compiled geometry: functions of (q, q_dot, t) arrays giving points in the plane (m)."""

    particle_names: tuple[str, ...]
    body_names: tuple[str, ...]
    spring_names: tuple[str, ...]
    damper_names: tuple[str, ...]
    _particles: StateFunction
    _bodies: StateFunction
    _springs: StateFunction
    _dampers: StateFunction

    def frame(self, q: np.ndarray, v: np.ndarray, t: np.ndarray) -> Frame:
        """Batched positions of everything drawn, for states q, v (k, n) at times t (k,)."""
        k = len(t)

        def stack(f: StateFunction, count: int, shape: tuple[int, ...]) -> np.ndarray:
            return f(q, v, t).reshape((k, count) + shape)

        particles = stack(self._particles, len(self.particle_names), (2,))
        raw = stack(self._bodies, len(self.body_names), (4,))  # x, y, angle, half length
        c, s = np.cos(raw[..., 2]), np.sin(raw[..., 2])
        half = raw[..., 3]
        centre = raw[..., :2]
        offset = np.stack([c * half, s * half], axis=-1)
        bars = np.stack([centre - offset, centre + offset], axis=-2)
        springs = stack(self._springs, len(self.spring_names), (2, 2))
        dampers = stack(self._dampers, len(self.damper_names), (2, 2))
        return Frame(particles, bars, springs, dampers)


def mechanism(model: Model, parameters: Mapping[str, float | None] | ParameterValues | None = None
              ) -> Mechanism:
    """Compile the drawable geometry of ``model`` once (parameters by name, SI; the model's
    values where not given)."""
    if isinstance(parameters, Mapping):  # a symbolic-only parameter (None) keeps its symbol
        parameters = {k: v for k, v in parameters.items() if v is not None}
    values = resolve_parameters(model, parameters, require=False).symbol_values(model)

    def compile_(exprs) -> StateFunction:
        return StateFunction(model, exprs, values)

    particles = [e for p in model.particles for e in p.position[:2]]
    bodies = []
    for body in model.bodies:
        mass, inertia = body.mass.xreplace(values), body.inertia.xreplace(values)
        # Drawn as the uniform bar of the same mass and inertia: length sqrt(12 I / m).
        half = sp.sqrt(3 * inertia / mass) if mass != 0 else sp.S.Zero
        bodies.extend([body.position[0], body.position[1], body.angle, half])
    ends = spring_end_points(model, values)
    springs = [e for name in ends for point in ends[name] for e in point[:2]]
    damper_ends = {d.name: (d.ends[0].point, d.ends[1].point) for d in model.dampers
                   if d.ends is not None}
    dampers = [e for name in damper_ends for point in damper_ends[name] for e in point[:2]]
    return Mechanism(
        particle_names=tuple(p.name for p in model.particles),
        body_names=tuple(b.name for b in model.bodies),
        spring_names=tuple(ends),
        damper_names=tuple(damper_ends),
        _particles=compile_(particles), _bodies=compile_(bodies), _springs=compile_(springs),
        _dampers=compile_(dampers),
    )


def spring_end_points(model: Model, values: Mapping[sp.Symbol, sp.Expr]) -> dict[str, tuple]:
    """Spring name -> (point A, point B), in the model's order.

    A spring given ``between`` two points has its kept ends. For one given by its length only,
    A and B are guessed where the length equals |A - B| at sampled states: candidates are the
    origin and the particle and body centres; failing a pair, one moving candidate and a fixed
    anchor found by least squares. Springs matching neither are skipped.
    """
    guessed = _guessed_end_points(model, [s for s in model.springs if s.ends is None], values)
    found = {}
    for spring in model.springs:
        if spring.ends is not None:
            found[spring.name] = (spring.ends[0].point, spring.ends[1].point)
        elif spring.name in guessed:
            found[spring.name] = guessed[spring.name]
    return found


def _guessed_end_points(model: Model, springs: list, values: Mapping) -> dict[str, tuple]:
    if not springs:
        return {}
    candidates = [(0, 0, 0)] + [p.position for p in model.particles] + \
        [b.position for b in model.bodies]
    n = len(model.q)
    rng = np.random.default_rng(7)
    samples = rng.uniform(-1.0, 1.0, size=(6, 2 * n + 1))  # rows of (q, q_dot, t)

    def sample(expr) -> np.ndarray:
        with np.errstate(all="ignore"):
            return StateFunction(model, [expr], values)(
                samples[:, :n], samples[:, n:2 * n], samples[:, -1])[:, 0]

    try:
        points = [np.stack([sample(c) for c in point], axis=-1) for point in candidates]
    except (TypeError, ValueError, ZeroDivisionError):
        return {}
    found = {}
    for spring in springs:
        try:
            length = sample(spring.length)
        except (TypeError, ValueError, ZeroDivisionError):
            continue
        if not np.all(np.isfinite(length)):
            continue
        scale = 1.0 + np.max(np.abs(length))
        match = None
        for i, a in enumerate(points):
            for j in range(i + 1, len(points)):
                distance = np.linalg.norm(a - points[j], axis=-1)
                if np.allclose(distance, np.abs(length), rtol=1e-9, atol=1e-12 * scale):
                    match = (candidates[i], candidates[j])
                    break
            if match:
                break
        if match is None:
            match = _fixed_anchor(points, candidates, length)
        if match is not None:
            found[spring.name] = match
    return found


def _fixed_anchor(points, candidates, length):
    for point, expr in zip(points[1:], candidates[1:], strict=True):
        # |P - A|^2 = L^2  <=>  2 P.A - c = |P|^2 - L^2 with c = |A|^2 (linear in A, c)
        matrix = np.column_stack([2 * point, -np.ones(len(point))])
        rhs = np.sum(point**2, axis=-1) - length**2
        solution, *_ = np.linalg.lstsq(matrix, rhs, rcond=None)
        anchor, c = solution[:3], solution[3]
        if np.allclose(matrix @ solution, rhs, atol=1e-9 * (1 + np.max(np.abs(rhs)))) and \
                abs(c - anchor @ anchor) < 1e-9 * (1 + abs(c)):
            return (tuple(sp.Float(x) for x in anchor), expr)
    return None
