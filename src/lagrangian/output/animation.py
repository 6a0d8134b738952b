"""Animation of the mechanism: particles as dots, bodies as bars, springs as zigzags and
dampers as dashpots (GIF/HTML). Bodies in space are drawn in 3D seen from a viewpoint (azimuth,
elevation): each as its body axes (x red, y green, z blue), the wire box of the same mass and
inertia, and lines from its joint to its centre of mass and from its parent's joint to its own.

It draws the positions numerics/geometry.py computes (a spring or damper with no ends found
there is left out); nothing here evaluates an expression.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from ..errors import ModelError
from ..model.model import Model
from ..numerics.geometry import ISOMETRIC_VIEW, mechanism, view_projection
from ..numerics.result import SimulationResult
from .files import atomic_write

ANIMATION_FORMATS = (".gif", ".html")


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
    if not (model.particles or model.bodies or model.rigid_bodies):
        raise ModelError("nothing to animate: the model has no particles or bodies "
                         "(it is given by its energies only)", field="animation")


def check_view(view: object) -> tuple[float, float]:
    """The viewpoint (azimuth, elevation) in degrees, from a pair or the text "AZ,EL";
    None gives the isometric view (45, 35.26)."""
    if view is None:
        return ISOMETRIC_VIEW
    parts = view.split(",") if isinstance(view, str) else view
    try:
        azimuth, elevation = (float(p) for p in parts)
    except (TypeError, ValueError):
        raise ModelError(f"expected AZIMUTH,ELEVATION in degrees (e.g. 45,30), got {view!r}",
                         field="view") from None
    if not (np.isfinite(azimuth) and np.isfinite(elevation)) or abs(elevation) > 90:
        raise ModelError(f"the azimuth must be finite and the elevation between -90 and 90 "
                         f"degrees, got {azimuth:g},{elevation:g}", field="view")
    return azimuth, elevation


def mechanism_animation(result: SimulationResult, *, fps: int = 25, max_frames: int = 250,
                        view: object = None):
    """A matplotlib FuncAnimation of the mechanism over the run (planar x-y view; a model with
    bodies in space is seen from ``view`` = (azimuth, elevation) in degrees)."""
    from matplotlib.animation import FuncAnimation
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    check_animatable(result.model)
    view = check_view(view)
    geometry = mechanism(result.model, result.parameters)
    times = animation_frames(result, fps, max_frames)
    q = np.column_stack([np.interp(times, result.t, result.q[:, i])
                         for i in range(result.q.shape[1])])
    v = np.column_stack([np.interp(times, result.t, result.q_dot[:, i])
                         for i in range(result.q.shape[1])])
    if geometry.rigid_body_names:
        return _space_animation(result, geometry, times, q, v, view, fps)
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


# The 12 edges of a box, as pairs of corners (signs of the half extents along its three axes).
_CORNERS = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], dtype=float)
_EDGES = [(a, b) for a in range(8) for b in range(a + 1, 8)
          if np.sum(_CORNERS[a] != _CORNERS[b]) == 1]


def _space_animation(result, geometry, times, q, v, view, fps):
    """The 3D mechanism projected on the screen seen from ``view`` (azimuth, elevation)."""
    from matplotlib.animation import FuncAnimation
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    space = geometry.space_frame(q, v, times)
    screen = view_projection(*view)

    def project(points: np.ndarray) -> np.ndarray:
        return points @ screen.T

    # Axes as long as the body's largest half extent (at least a tenth of its joint-to-centre
    # line), so a thin disc or a point-like body still shows all three.
    reach = np.linalg.norm(space.centres - space.origins, axis=-1)
    length = np.maximum(space.half_extents.max(axis=-1), 0.1 * reach)
    length = np.where(length > 0, length, 1.0)
    tips = space.centres[..., None, :] + \
        np.swapaxes(space.rotations, -1, -2) * length[..., None, None]  # (k, B, axis, 3)
    corners = space.centres[..., None, :] + np.einsum(
        "cj,kbij->kbci", _CORNERS, space.principal_axes * space.half_extents[..., None, :])
    everything = np.concatenate([
        space.particles.reshape(-1, 3), space.centres.reshape(-1, 3), tips.reshape(-1, 3),
        corners.reshape(-1, 3), space.links.reshape(-1, 3), space.bars.reshape(-1, 3),
        space.springs.reshape(-1, 3), space.dampers.reshape(-1, 3), [[0.0, 0.0, 0.0]]])
    flat = project(everything)
    flat = flat[np.all(np.isfinite(flat), axis=1)]
    low, high = flat.min(axis=0), flat.max(axis=0)
    half = 0.55 * max(float(np.max(high - low)), 1e-3)
    centre = (low + high) / 2

    figure = Figure(figsize=(5, 5), dpi=80, layout="constrained")
    FigureCanvasAgg(figure)
    ax = figure.add_subplot()
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(f"{result.model_name}\n(azimuth {view[0]:.4g}°, elevation {view[1]:.4g}°)")
    # The world axes at the origin, short and grey, so the viewpoint reads.
    for unit in np.eye(3):
        end = project(unit * 0.3 * half)
        ax.plot([0, end[0]], [0, end[1]], color="grey", linewidth=0.8)
    ax.plot([0], [0], marker="+", color="grey")
    boxes = [ax.plot([], [], color="0.55", linewidth=0.8)[0] for _ in geometry.rigid_body_names]
    links = [ax.plot([], [], color="black", linewidth=2.5, solid_capstyle="round")[0]
             for _ in range(space.links.shape[1])]
    bars = [ax.plot([], [], color="tab:blue", linewidth=4)[0] for _ in geometry.body_names]
    spring_lines = [ax.plot([], [], color="tab:green", linewidth=1)[0]
                    for _ in geometry.spring_names]
    damper_lines = [ax.plot([], [], color="tab:purple", linewidth=1.5)[0]
                    for _ in geometry.damper_names]
    colours = ("tab:red", "tab:green", "tab:blue")
    axes = [[ax.plot([], [], color=c, linewidth=2)[0] for c in colours]
            for _ in geometry.rigid_body_names]
    dots = ax.plot([], [], "o", color="tab:red", markersize=8)[0]
    clock = ax.text(0.02, 0.95, "", transform=ax.transAxes)
    gap = np.full((1, 2), np.nan)

    def draw(k):
        for b, line in enumerate(boxes):
            pieces = [np.vstack([project(corners[k, b, [i, j]]), gap]) for i, j in _EDGES]
            box = np.vstack(pieces)
            line.set_data(box[:, 0], box[:, 1])
        for line, ends in zip(links, space.links[k], strict=True):
            flat_ends = project(ends)
            line.set_data(flat_ends[:, 0], flat_ends[:, 1])
        for line, ends in zip(bars, space.bars[k], strict=True):
            flat_ends = project(ends)
            line.set_data(flat_ends[:, 0], flat_ends[:, 1])
        for line, (a, b) in zip(spring_lines, space.springs[k], strict=True):
            zig = _zigzag(project(a), project(b))
            line.set_data(zig[:, 0], zig[:, 1])
        for line, (a, b) in zip(damper_lines, space.dampers[k], strict=True):
            pot = _dashpot(project(a), project(b))
            line.set_data(pot[:, 0], pot[:, 1])
        for b, triad in enumerate(axes):
            start = project(space.centres[k, b])
            for line, tip in zip(triad, tips[k, b], strict=True):
                end = project(tip)
                line.set_data([start[0], end[0]], [start[1], end[1]])
        flat_particles = project(space.particles[k])
        dots.set_data(flat_particles[:, 0], flat_particles[:, 1])
        clock.set_text(f"t = {times[k]:.2f} s")
        return [*boxes, *links, *bars, *spring_lines, *damper_lines,
                *(line for triad in axes for line in triad), dots, clock]

    return FuncAnimation(figure, draw, frames=len(times), interval=1000 / fps, blit=False)


def save_animation(animation, path: str | Path, *, fps: int = 25,
                   protect: tuple[Path, ...] = (), progress=None) -> Path:
    """Save a built animation as .gif or .html, through a temporary file and a rename.
    ``progress(frame, frames)`` is called as each GIF frame is written (for a progress bar)."""
    path = check_animation_path(path)
    if path.suffix.lower() == ".html":
        return atomic_write(path, animation.to_jshtml(fps=fps), protect=protect)
    from matplotlib.animation import PillowWriter

    handle, temporary = tempfile.mkstemp(suffix=".gif")
    os.close(handle)
    try:
        animation.save(temporary, writer=PillowWriter(fps=fps), progress_callback=progress)
        data = Path(temporary).read_bytes()
    finally:
        os.unlink(temporary)
    return atomic_write(path, data, protect=protect)


def check_animation_path(path: str | Path) -> Path:
    """The path, if it names a .gif or .html file."""
    path = Path(path)
    if path.suffix.lower() not in ANIMATION_FORMATS:
        raise ModelError(f"cannot write {path}: use a .gif or .html file name", field="animation")
    return path
