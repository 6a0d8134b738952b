"""Animation of the mechanism: particles as dots, bodies as bars, springs as zigzags and
dampers as dashpots (GIF/HTML).

Positions come from the model (particle and body positions, body angles). A spring or damper
given ``between`` two points is drawn between its kept ends, exactly. A spring given by its
length only is drawn between end points guessed from that length (see ``spring_end_points``),
or left out when none fit; a damper given by its rate only is left out.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np
import sympy as sp

from ..errors import ModelError
from ..model.expressions import as_expression
from ..model.model import Model
from ..numerics.simulate import SimulationResult
from .files import atomic_write

ANIMATION_FORMATS = (".gif", ".html")


class Frame(NamedTuple):
    """Batched positions (m) at k instants: particles (k, P, 2), bar ends (k, B, 2, 2), spring
    ends (k, S, 2, 2), damper ends (k, D, 2, 2)."""

    particles: np.ndarray
    bars: np.ndarray
    springs: np.ndarray
    dampers: np.ndarray


@dataclass(frozen=True)
class Mechanism:
    """Compiled geometry: callables of (q, q_dot, t) arrays giving points in the plane (m)."""

    particle_names: tuple[str, ...]
    body_names: tuple[str, ...]
    spring_names: tuple[str, ...]
    _particles: object
    _bodies: object
    _springs: object
    damper_names: tuple[str, ...] = ()
    _dampers: object = None

    def frame(self, q: np.ndarray, v: np.ndarray, t: np.ndarray) -> Frame:
        """Batched positions of everything drawn, for states q, v (k, n) at times t (k,)."""
        k = len(t)

        def stack(f, count, shape):
            if not count:
                return np.zeros((k, 0) + shape)
            values = [np.broadcast_to(np.asarray(x, dtype=float), (k,)) for x in f(*q.T, *v.T, t)]
            return np.stack(values, axis=-1).reshape((k, count) + shape)

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


def mechanism(model: Model, parameters: dict[str, float]) -> Mechanism:
    """Compile the drawable geometry of ``model`` once (parameters by name, SI)."""
    values = {p.symbol: sp.Float(parameters[p.name]) for p in model.parameters
              if p.name in parameters}
    args = [*model.q, *model.q_dot, model.time]

    def compile_(exprs):
        exprs = [as_expression(e).xreplace(values) for e in exprs]
        return sp.lambdify(args, exprs, modules="numpy") if exprs else None

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
        _particles=compile_(particles), _bodies=compile_(bodies), _springs=compile_(springs),
        damper_names=tuple(damper_ends), _dampers=compile_(dampers),
    )


def spring_end_points(model: Model, values: dict) -> dict[str, tuple]:
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


def _guessed_end_points(model: Model, springs: list, values: dict) -> dict[str, tuple]:
    if not springs:
        return {}
    candidates = [(0, 0, 0)] + [p.position for p in model.particles] + \
        [b.position for b in model.bodies]
    args = [*model.q, *model.q_dot, model.time]
    rng = np.random.default_rng(7)
    samples = rng.uniform(-1.0, 1.0, size=(6, len(args)))

    def sample(expr):
        f = sp.lambdify(args, as_expression(expr).xreplace(values), modules="numpy")
        with np.errstate(all="ignore"):
            return np.array([float(np.real(f(*row))) for row in samples])

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


def _zigzag(a: np.ndarray, b: np.ndarray, turns: int = 8, width: float = 0.06):
    """Points of a zigzag from a to b (width relative to its length, with straight ends)."""
    d = b - a
    length = np.hypot(*d)
    if length == 0:
        return np.array([a, b])
    u = d / length
    normal = np.array([-u[1], u[0]])
    s = np.concatenate([[0, 0.1], 0.1 + 0.8 * (np.arange(1, 2 * turns) / (2 * turns)), [0.9, 1]])
    side = np.zeros_like(s)
    side[2:-2] = np.where(np.arange(len(s) - 4) % 2 == 0, 1.0, -1.0)
    return a + np.outer(s * length, u) + np.outer(side * width * max(length, 0.05), normal)


def _dashpot(a: np.ndarray, b: np.ndarray, width: float = 0.08):
    """Points of a dashpot from a to b: rod, open cylinder, piston plate, rod (NaN-separated)."""
    d = b - a
    length = np.hypot(*d)
    if length == 0:
        return np.array([a, b])
    u = d / length
    n = np.array([-u[1], u[0]]) * width * max(length, 0.05)

    def at(s: float) -> np.ndarray:  # the point a fraction s of the way from a to b
        return a + s * d

    gap = np.full(2, np.nan)  # a NaN breaks the line between the pieces
    cylinder = [at(0.65) + n, at(0.35) + n, at(0.35) - n, at(0.65) - n]
    piston = [at(0.55) + 0.8 * n, at(0.55) - 0.8 * n]
    return np.array([a, at(0.35), gap, *cylinder, gap, *piston, gap, at(0.55), b])


def animation_frames(result: SimulationResult, fps: int = 25, max_frames: int = 250):
    """Frame times: real time at ``fps``, at most ``max_frames`` frames over the run."""
    t0, t1 = float(result.t[0]), float(result.t[-1])
    count = int(min(max_frames, max(2, round((t1 - t0) * fps) + 1)))
    return np.linspace(t0, t1, count)


def check_animatable(model: Model) -> None:
    """Refuse a model with nothing to draw (given by its energies only)."""
    if not (model.particles or model.bodies):
        raise ModelError("nothing to animate: the model has no particles or bodies "
                         "(it is given by its energies only)", field="--animate")


def mechanism_animation(result: SimulationResult, model: Model, *, fps: int = 25,
                        max_frames: int = 250):
    """A matplotlib FuncAnimation of the mechanism over the run (planar x-y view)."""
    from matplotlib.animation import FuncAnimation
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    check_animatable(model)
    geometry = mechanism(model, result.parameters)
    times = animation_frames(result, fps, max_frames)
    q = np.column_stack([np.interp(times, result.t, result.q[:, i])
                         for i in range(result.q.shape[1])])
    v = np.column_stack([np.interp(times, result.t, result.q_dot[:, i])
                         for i in range(result.q.shape[1])])
    particles, bars, springs, dampers = geometry.frame(q, v, times)
    everything = np.concatenate([particles.reshape(-1, 2), bars.reshape(-1, 2),
                                 springs.reshape(-1, 2), dampers.reshape(-1, 2), [[0.0, 0.0]]])
    everything = everything[np.all(np.isfinite(everything), axis=1)]
    low, high = everything.min(axis=0), everything.max(axis=0)
    # A square view around the motion, so a mechanism moving along one line is not squashed.
    half = 0.55 * max(float(np.max(high - low)), 1e-3)
    centre = (low + high) / 2
    low, high, pad = centre - half, centre + half, 0.0

    figure = Figure(figsize=(5, 5), dpi=80, layout="constrained")
    FigureCanvasAgg(figure)
    ax = figure.add_subplot()
    ax.set_xlim(low[0] - pad, high[0] + pad)
    ax.set_ylim(low[1] - pad, high[1] + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.plot([0], [0], marker="+", color="grey")
    spring_lines = [ax.plot([], [], color="tab:green", linewidth=1)[0] for _ in geometry.spring_names]
    damper_lines = [ax.plot([], [], color="tab:purple", linewidth=1.5)[0]
                    for _ in geometry.damper_names]
    bar_lines = [ax.plot([], [], color="tab:blue", linewidth=4, solid_capstyle="round")[0]
                 for _ in geometry.body_names]
    # Each particle leaves a short trail (its last second) so the motion reads in one frame.
    trails = [ax.plot([], [], color="tab:red", alpha=0.35, linewidth=1)[0]
              for _ in geometry.particle_names]
    trail_length = max(1, int(fps))
    dots = ax.plot([], [], "o", color="tab:red", markersize=10)[0]
    clock = ax.text(0.02, 0.95, "", transform=ax.transAxes)
    ax.set_title(result.model_name)

    def draw(k):
        for line, (a, b) in zip(spring_lines, springs[k], strict=True):
            zig = _zigzag(a, b)
            line.set_data(zig[:, 0], zig[:, 1])
        for line, (a, b) in zip(damper_lines, dampers[k], strict=True):
            pot = _dashpot(a, b)
            line.set_data(pot[:, 0], pot[:, 1])
        for line, ends in zip(bar_lines, bars[k], strict=True):
            line.set_data(ends[:, 0], ends[:, 1])
        for i, line in enumerate(trails):
            path = particles[max(0, k - trail_length): k + 1, i]
            line.set_data(path[:, 0], path[:, 1])
        dots.set_data(particles[k][:, 0], particles[k][:, 1])
        clock.set_text(f"t = {times[k]:.2f} s")
        return [*spring_lines, *damper_lines, *bar_lines, *trails, dots, clock]

    return FuncAnimation(figure, draw, frames=len(times), interval=1000 / fps, blit=False)


def save_animation(animation, path: str | Path, *, fps: int = 25,
                   protect: tuple[Path, ...] = ()) -> Path:
    """Save a built animation as .gif or .html, through a temporary file and a rename."""
    path = _check_suffix(path)
    if path.suffix.lower() == ".html":
        return atomic_write(path, animation.to_jshtml(fps=fps), protect=protect)
    from matplotlib.animation import PillowWriter

    handle, temporary = tempfile.mkstemp(suffix=".gif")
    os.close(handle)
    try:
        animation.save(temporary, writer=PillowWriter(fps=fps))
        data = Path(temporary).read_bytes()
    finally:
        os.unlink(temporary)
    return atomic_write(path, data, protect=protect)


def _check_suffix(path: str | Path) -> Path:
    path = Path(path)
    if path.suffix.lower() not in ANIMATION_FORMATS:
        raise ModelError(f"cannot write {path}: use a .gif or .html file name", field="--animate")
    return path
