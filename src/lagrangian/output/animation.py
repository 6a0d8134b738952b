"""Animation of the mechanism as a user sketches it: particles as dots, rods from their pivots
(hinges) and between linked points, carts and sliders as blocks on their tracks, bodies as bars
(a rolling body as a wheel on its surface), springs as zigzags and dampers as dashpots (GIF or a
self-contained HTML player). Bodies in space are drawn in 3D seen from a viewpoint (azimuth,
elevation): each as its body axes (x red, y green, z blue), the wire box of the same mass and
inertia, lines from its joint to its centre of mass and from its parent's joint to its own, and a
wheel on a rolling contact as its rim over a ground grid.

It draws the positions output/geometry.py computes (its ``sketch`` finds the rods, pivots,
blocks and wheels from the model's structure; a spring or damper with no ends found there is
left out); nothing here evaluates an expression. Frames are rendered by blitting: the still
parts once, the moving artists per frame.
"""

from __future__ import annotations

import base64
import html
import io
import os
import tempfile
import uuid
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..model.model import Model
from ..simulation.result import SimulationResult
from .files import atomic_write
from .geometry import ISOMETRIC_VIEW, mechanism, view_projection
from .plots import plain_text

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
        raise InputError("nothing to animate: the model has no particles or bodies "
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
        raise InputError(f"expected AZIMUTH,ELEVATION in degrees (e.g. 45,30), got {view!r}",
                         field="view") from None
    if not (np.isfinite(azimuth) and np.isfinite(elevation)) or abs(elevation) > 90:
        raise InputError(f"the azimuth must be finite and the elevation between -90 and 90 "
                         f"degrees, got {azimuth:g},{elevation:g}", field="view")
    return azimuth, elevation


def mechanism_animation(result: SimulationResult, *, fps: int = 25, max_frames: int = 250,
                        view: object = None):
    """A matplotlib FuncAnimation of the mechanism over the run (planar x-y view; a model with
    bodies in space is seen from ``view`` = (azimuth, elevation) in degrees)."""
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
    frame = geometry.frame(q, v, times)
    particles, bars, springs, dampers = frame.particles, frame.bars, frame.springs, frame.dampers
    rolling = {j: (radius, np.array(normal)) for j, radius, normal in geometry.rolling}
    # A rolling body's reach is its wheel, not its bar of the same inertia.
    wheels = [bars[:, j].mean(axis=1)[:, None, :] + abs(radius) * np.array(
        [[1, 0], [-1, 0], [0, 1], [0, -1]]) for j, (radius, _) in rolling.items()]
    everything = np.concatenate([particles.reshape(-1, 2), np.delete(bars, list(rolling), axis=1)
                                 .reshape(-1, 2), springs.reshape(-1, 2), dampers.reshape(-1, 2),
                                 frame.rods.reshape(-1, 2), frame.pivots.reshape(-1, 2),
                                 *(w.reshape(-1, 2) for w in wheels), [[0.0, 0.0]]])
    everything = everything[np.all(np.isfinite(everything), axis=1)]
    low, high = everything.min(axis=0), everything.max(axis=0)
    # A square view around the motion, so a mechanism moving along one line is not squashed.
    half = 0.6 * max(float(np.max(high - low)), 1e-3)
    if geometry.blocks:  # room for the blocks drawn around their particles (a 0.12 span box)
        block_paths = particles[:, [i for i, _ in geometry.blocks]].reshape(-1, 2)
        low = np.minimum(low, block_paths.min(axis=0) - 0.08 * 2 * half)
        high = np.maximum(high, block_paths.max(axis=0) + 0.08 * 2 * half)
        half = max(half, 0.5 * float(np.max(high - low)))
    centre = (low + high) / 2
    low, high = centre - half, centre + half
    span = 2 * half

    figure = Figure(figsize=(5, 5), dpi=80, layout="constrained")
    FigureCanvasAgg(figure)
    ax = figure.add_subplot()
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.plot([0], [0], marker="+", color="grey")
    if geometry.gravity is not None:
        _gravity_arrow(ax, geometry.gravity)
    gravity = None if geometry.gravity is None else np.array(geometry.gravity)
    # Still surfaces: each block's track and each rolling body's ground, with hatching.
    block_size = np.array([0.12, 0.07]) * span  # along, across the track
    for i, direction in geometry.blocks:
        d = np.array(direction)
        n = np.array([-d[1], d[0]])
        if gravity is not None and abs(gravity @ n) > 1e-9:
            n = n if gravity @ n < 0 else -n  # the track is under the block (against gravity)
            offset = block_size[1] / 2
        else:
            offset = 0.0  # along gravity (or none): a guide through the block
        path = particles[:, i] @ d
        base = particles[0, i] - (particles[0, i] @ d) * d - offset * n
        _surface(ax, base, d, -n if offset else None, path.min() - block_size[0],
                 path.max() + block_size[0], span)
    for j, (radius, normal) in rolling.items():
        d = np.array([normal[1], -normal[0]])
        contact = bars[:, j].mean(axis=1) - radius * normal  # centre - rho n
        path = contact @ d
        base = contact[0] - (contact[0] @ d) * d
        _surface(ax, base, d, -np.sign(radius) * normal, path.min() - 2 * abs(radius),
                 path.max() + 2 * abs(radius), span)
    spring_lines = [ax.plot([], [], color="tab:green", linewidth=1)[0] for _ in geometry.spring_names]
    damper_lines = [ax.plot([], [], color="tab:purple", linewidth=1.5)[0]
                    for _ in geometry.damper_names]
    rod_lines = [ax.plot([], [], color="black", linewidth=2, solid_capstyle="round",
                         label="rod")[0] for _ in range(geometry.rod_count)]
    bar_lines = {j: ax.plot([], [], color="tab:blue", linewidth=4, solid_capstyle="round",
                            label="bar")[0]
                 for j in range(len(geometry.body_names)) if j not in rolling}
    wheel_lines = {j: ax.plot([], [], color="tab:blue", linewidth=2, label="wheel")[0]
                   for j in rolling}
    pivot_marks = ax.plot([], [], "^", color="0.45", markersize=13, label="pivot")[0]
    hinges = ax.plot([], [], "o", color="white", markeredgecolor="black", markersize=5)[0]
    blocks = [ax.fill([], [], facecolor="tab:red", edgecolor="black", linewidth=1,
                      label="block")[0] for _ in geometry.blocks]
    block_of = {i for i, _ in geometry.blocks}
    free = [i for i in range(len(geometry.particle_names)) if i not in block_of]
    # Each particle leaves a short trail (its last second) so the motion reads in one frame.
    trails = [ax.plot([], [], color="tab:red", alpha=0.35, linewidth=1)[0] for _ in free]
    trail_length = max(1, int(fps))
    dots = ax.plot([], [], "o", color="tab:red", markersize=10, label="particles")[0]
    clock = _clock(ax)
    ax.set_title(plain_text(result.model_name))
    angles = np.linspace(0, 2 * np.pi, 41)
    circle = np.column_stack([np.cos(angles), np.sin(angles)])

    def draw(k):
        for line, (a, b) in zip(spring_lines, springs[k], strict=True):
            zig = _zigzag(a, b)
            line.set_data(zig[:, 0], zig[:, 1])
        for line, (a, b) in zip(damper_lines, dampers[k], strict=True):
            pot = _dashpot(a, b)
            line.set_data(pot[:, 0], pot[:, 1])
        for line, ends in zip(rod_lines, frame.rods[k], strict=True):
            line.set_data(ends[:, 0], ends[:, 1])
        for j, line in bar_lines.items():
            line.set_data(bars[k, j, :, 0], bars[k, j, :, 1])
        for j, line in wheel_lines.items():
            # The rim, and a spoke along the body's x axis so the turning shows.
            radius = abs(rolling[j][0])
            middle, end = bars[k, j].mean(axis=0), bars[k, j, 1]
            spoke = middle + radius * (end - middle) / max(np.hypot(*(end - middle)), 1e-300)
            rim = middle + radius * circle
            line.set_data([*rim[:, 0], np.nan, middle[0], spoke[0]],
                          [*rim[:, 1], np.nan, middle[1], spoke[1]])
        pivot_marks.set_data(frame.pivots[k][:, 0], frame.pivots[k][:, 1])
        hinges.set_data(frame.pivots[k][:, 0], frame.pivots[k][:, 1])
        for patch, (i, direction) in zip(blocks, geometry.blocks, strict=True):
            patch.set_xy(_box(particles[k, i], np.array(direction), block_size))
        for line, i in zip(trails, free, strict=True):
            path = particles[max(0, k - trail_length): k + 1, i]
            line.set_data(path[:, 0], path[:, 1])
        dots.set_data(particles[k, free, 0], particles[k, free, 1])
        clock.set_text(f"{times[k]:.2f}")
        return [*spring_lines, *damper_lines, *rod_lines, *bar_lines.values(),
                *wheel_lines.values(), *blocks, *trails, dots, pivot_marks, hinges, clock]

    return _animation(figure, draw, times, fps)


def _clock(ax):
    """The time in the corner: "t =" and "s" stay put (drawn once); only the number is redrawn
    per frame (text is the costliest artist, ~2 ms for the whole line)."""
    ax.text(0.02, 0.95, "t =", transform=ax.transAxes)
    ax.text(0.195, 0.95, "s", transform=ax.transAxes)
    return ax.text(0.185, 0.95, "", transform=ax.transAxes, ha="right")


def _box(centre: np.ndarray, d: np.ndarray, size: np.ndarray) -> np.ndarray:
    """Corners of a box centred at ``centre`` with its length along unit ``d``."""
    n = np.array([-d[1], d[0]])
    a, b = size[0] / 2 * d, size[1] / 2 * n
    return np.array([centre - a - b, centre + a - b, centre + a + b, centre - a + b])


def _surface(ax, base: np.ndarray, d: np.ndarray, inside: np.ndarray | None, start: float,
             stop: float, span: float) -> None:
    """A fixed line base + s d for s in [start, stop], hatched on the side ``inside`` (the
    ground's side; None: a bare guide line)."""
    ends = np.array([base + start * d, base + stop * d])
    ax.plot(ends[:, 0], ends[:, 1], color="0.3", linewidth=1.5, label="surface")
    if inside is None:
        return
    step = 0.03 * span
    marks = np.arange(start, stop, step)
    tick = 0.025 * span * (inside - 0.6 * d)
    xs = np.column_stack([base[0] + marks * d[0], base[0] + marks * d[0] + tick[0],
                          np.full(len(marks), np.nan)]).ravel()
    ys = np.column_stack([base[1] + marks * d[1], base[1] + marks * d[1] + tick[1],
                          np.full(len(marks), np.nan)]).ravel()
    ax.plot(xs, ys, color="0.5", linewidth=0.8)


def _gravity_arrow(ax, direction: tuple[float, float]) -> None:
    """A small arrow in the corner showing which way gravity pulls (an incline reads)."""
    start = np.array([0.92, 0.9]) - 0.05 * np.array(direction)
    end = start + 0.08 * np.array(direction)
    ax.annotate("", xy=end, xytext=start, xycoords="axes fraction",
                arrowprops={"arrowstyle": "-|>", "color": "0.4"})
    ax.text(*(start + np.array([-0.04, 0.0])), "g", transform=ax.transAxes, color="0.4",
            ha="center", va="center")


# The 12 edges of a box, as pairs of corners (signs of the half extents along its three axes).
_CORNERS = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], dtype=float)
_EDGES = [(a, b) for a in range(8) for b in range(a + 1, 8)
          if np.sum(_CORNERS[a] != _CORNERS[b]) == 1]


def _space_animation(result, geometry, times, q, v, view, fps):
    """The 3D mechanism projected on the screen seen from ``view`` (azimuth, elevation)."""
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
    rims, contacts = geometry.wheel_frame(space)
    grid = _ground_grid(geometry, contacts)
    everything = np.concatenate([
        rims.reshape(-1, 3), grid.reshape(-1, 3), space.particles.reshape(-1, 3),
        space.centres.reshape(-1, 3), tips.reshape(-1, 3),
        corners.reshape(-1, 3), space.links.reshape(-1, 3), space.bars.reshape(-1, 3),
        space.rods.reshape(-1, 3),
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
    ax.set_title(plain_text(result.model_name)
                 + f"\n(azimuth {view[0]:.4g}°, elevation {view[1]:.4g}°)")
    # The world axes at the origin, short and grey, so the viewpoint reads.
    for unit in np.eye(3):
        end = project(unit * 0.3 * half)
        ax.plot([0, end[0]], [0, end[1]], color="grey", linewidth=0.8)
    ax.plot([0], [0], marker="+", color="grey")
    if len(grid):  # the ground the wheels roll on, still
        flat_grid = project(grid.reshape(-1, 3)).reshape(len(grid), 2, 2)
        pieces = np.concatenate([flat_grid, np.full((len(grid), 1, 2), np.nan)], axis=1)
        ax.plot(pieces[..., 0].ravel(), pieces[..., 1].ravel(), color="0.75", linewidth=0.7,
                label="ground")
    tracks = [ax.plot([], [], color="tab:brown", alpha=0.6, linewidth=1, label="track")[0]
              for _ in geometry.wheels]
    wheel_lines = [ax.plot([], [], color="tab:blue", linewidth=2, label="wheel")[0]
                   for _ in geometry.wheels]
    boxes = [ax.plot([], [], color="0.55", linewidth=0.8)[0] for _ in geometry.rigid_body_names]
    links = [ax.plot([], [], color="black", linewidth=2.5, solid_capstyle="round")[0]
             for _ in range(space.links.shape[1])]
    bars = [ax.plot([], [], color="tab:blue", linewidth=4)[0] for _ in geometry.body_names]
    rods = [ax.plot([], [], color="black", linewidth=2, label="rod")[0]
            for _ in range(space.rods.shape[1])]
    spring_lines = [ax.plot([], [], color="tab:green", linewidth=1)[0]
                    for _ in geometry.spring_names]
    damper_lines = [ax.plot([], [], color="tab:purple", linewidth=1.5)[0]
                    for _ in geometry.damper_names]
    colours = ("tab:red", "tab:green", "tab:blue")
    axes = [[ax.plot([], [], color=c, linewidth=2)[0] for c in colours]
            for _ in geometry.rigid_body_names]
    dots = ax.plot([], [], "o", color="tab:red", markersize=8)[0]
    clock = _clock(ax)
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
        for w, (line, track) in enumerate(zip(wheel_lines, tracks, strict=True)):
            rim = project(rims[k, w])
            line.set_data(rim[:, 0], rim[:, 1])
            trace = project(contacts[: k + 1, w])  # where it has touched the ground so far
            track.set_data(trace[:, 0], trace[:, 1])
        for line, ends in zip(rods, space.rods[k], strict=True):
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
        clock.set_text(f"{times[k]:.2f}")
        return [*tracks, *wheel_lines, *boxes, *links, *bars, *rods, *spring_lines, *damper_lines,
                *(line for triad in axes for line in triad), dots, clock]

    return _animation(figure, draw, times, fps)


def _animation(figure, draw, times: np.ndarray, fps: int):
    """Wrap a figure and its per-frame ``draw(k)`` (returning the artists it changed)."""
    from matplotlib.animation import FuncAnimation

    class MechanismAnimation(FuncAnimation):
        """A matplotlib FuncAnimation that also renders its frames fast (``frame_images``: one
        full draw of the still parts, then only the moving artists per frame) and whose
        ``to_jshtml`` is a self-contained player (no remote font or script)."""

        def draw(self, k: int) -> list:
            """Put frame k on the figure; the artists it moved."""
            self._draw_was_started = True  # drawn: matplotlib need not warn when it is deleted
            return draw(k)

        def frame_images(self, *, dpi: float | None = None, progress=None):
            self._draw_was_started = True
            return _frame_images(figure, draw, len(times), dpi=dpi, progress=progress)

        def to_jshtml(self, fps=None, embed_frames=True, default_mode=None):
            return player_html(self.frame_images(dpi=HTML_DPI),
                               fps=playback_rate(times, fps or self.fps), times=times,
                               title=self.title)

        def _repr_html_(self):
            # As matplotlib: shown inline only where rcParams["animation.html"] asks for it.
            from matplotlib import rcParams

            if rcParams["animation.html"] == "jshtml":
                return self.to_jshtml()
            return super()._repr_html_()

    animation = MechanismAnimation(figure, draw, frames=len(times), interval=1000 / fps,
                                   blit=False)
    animation.fps = fps
    animation.times = times
    animation.title = figure.axes[0].get_title()
    return animation


# The HTML player's frames are drawn smaller than the GIF's (80 dpi, 400 px): a page of
# many embedded images stays small.
HTML_DPI = 64
# Colours in the GIF's shared palette (the drawing has a dozen colours and their antialiasing).
GIF_COLOURS = 64


def _frame_images(figure, draw, count: int, *, dpi: float | None = None, progress=None):
    """RGB frames (H, W, 3) uint8: the still parts (axes, ticks, labels) are drawn once and
    restored as a background; each frame draws only the artists ``draw(k)`` moves (blitting).
    ``progress(frame, frames)`` is called after each frame."""
    canvas = figure.canvas
    if dpi is not None:
        figure.set_dpi(dpi)
    moving = draw(0)
    for artist in moving:
        artist.set_animated(True)  # left out of the full draw: the background
    try:
        canvas.draw()
        background = canvas.copy_from_bbox(figure.bbox)
        for k in range(count):
            canvas.restore_region(background)
            for artist in draw(k):
                artist.axes.draw_artist(artist)
            yield np.asarray(canvas.buffer_rgba())[..., :3].copy()
            if progress is not None:
                progress(k, count)
    finally:
        for artist in moving:
            artist.set_animated(False)


def _palette_frames(frames) -> list:
    """The frames as palette images sharing one palette (taken from a few spread frames), so
    the GIF needs no per-frame quantization search and its colours do not flicker."""
    from PIL import Image

    frames = list(frames)
    picks = sorted({0, len(frames) // 3, 2 * len(frames) // 3, len(frames) - 1})
    mosaic = Image.fromarray(np.concatenate([frames[i] for i in picks], axis=0))
    palette = mosaic.quantize(colors=GIF_COLOURS, method=Image.Quantize.MEDIANCUT)
    # Pillow maps a colour to a palette entry through a coarse lookup, so pure white landed on
    # a near-white neighbour (an off-white background): an entry within 12 levels of a more
    # used one becomes that one.
    entries = np.array(palette.getpalette()[:3 * GIF_COLOURS]).reshape(-1, 3)
    used = np.array(palette.histogram()[:len(entries)])
    for a in np.argsort(-used, kind="stable"):
        near = (used < used[a]) & (np.abs(entries - entries[a]).max(axis=1) <= 12)
        entries[near] = entries[a]
    palette.putpalette([int(c) for c in entries.ravel()])
    return [Image.fromarray(f).quantize(palette=palette, dither=Image.Dither.NONE)
            for f in frames]


def gif_bytes(frames, fps: float) -> bytes:
    """An endlessly looping GIF of the RGB frames at ``fps``."""
    images = _palette_frames(frames)
    buffer = io.BytesIO()
    images[0].save(buffer, format="GIF", save_all=True, append_images=images[1:],
                   duration=round(1000 / fps), loop=0)
    return buffer.getvalue()


def player_html(frames, *, fps: float, times: np.ndarray, title: str = "") -> str:
    """A self-contained HTML page that plays the RGB frames: play/pause, step, a slider and
    the time; every image is embedded (palette PNG, base64) and nothing is loaded from
    elsewhere, so it works offline."""
    images = _palette_frames(frames)
    encoded = []
    for image in images:
        buffer = io.BytesIO()
        image.save(buffer, format="PNG", optimize=True)
        encoded.append(base64.b64encode(buffer.getvalue()).decode("ascii"))
    lines = "\n".join(f'frames[{k}] = "data:image/png;base64,{data}";'
                      for k, data in enumerate(encoded))
    stamps = ", ".join(f"{t:.3f}" for t in times[:len(encoded)])
    return _PLAYER.format(id=f"lagrangian-{uuid.uuid4().hex[:12]}",
                          title=html.escape(title or "animation"), frames=lines,
                          times=stamps, count=len(encoded), last=len(encoded) - 1,
                          interval=round(1000 / fps))


_PLAYER = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title></head>
<body style="font-family: sans-serif">
<div class="lagrangian-animation" id="{id}">
<img id="{id}-frame" alt="{title}" style="display: block">
<div>
<button id="{id}-back" title="previous frame">&#9664;&#9664;</button>
<button id="{id}-play" title="play / pause">&#9654;</button>
<button id="{id}-next" title="next frame">&#9654;&#9654;</button>
<input id="{id}-slider" type="range" min="0" max="{last}" value="0" style="width: 60%">
<span id="{id}-clock"></span>
<label><input id="{id}-loop" type="checkbox" checked> loop</label>
</div>
</div>
<script>
(function () {{
// The animation's frames, embedded: this page needs nothing from the network. Ids carry a
// prefix of their own, so several players on one page (a notebook) stay apart.
var frames = new Array({count});
{frames}
var times = [{times}];
var k = 0, timer = null;
function part(name) {{ return document.getElementById("{id}-" + name); }}
var img = part("frame"), slider = part("slider"), play = part("play"), clock = part("clock");
function show(i) {{
  k = (i + frames.length) % frames.length;
  img.src = frames[k]; slider.value = k; clock.textContent = "t = " + times[k].toFixed(2) + " s";
}}
function stop() {{ clearInterval(timer); timer = null; play.innerHTML = "&#9654;"; }}
function tick() {{
  if (k == frames.length - 1 && !part("loop").checked) {{ stop(); return; }}
  show(k + 1);
}}
play.onclick = function () {{
  if (timer) {{ stop(); return; }}
  timer = setInterval(tick, {interval}); play.innerHTML = "&#10074;&#10074;";
}};
part("back").onclick = function () {{ stop(); show(k - 1); }};
part("next").onclick = function () {{ stop(); show(k + 1); }};
slider.oninput = function () {{ stop(); show(parseInt(slider.value)); }};
show(0);
}})();
</script>
</body></html>
"""


def _ground_grid(geometry, contacts: np.ndarray, lines: int = 7) -> np.ndarray:
    """Segments (G, 2, 3) of a square grid on the ground plane r . n = 0 around where the
    wheels touch it over the run (a wheel's diameter of margin)."""
    if not geometry.wheels:
        return np.zeros((0, 2, 3))
    n = np.array(geometry.wheels[0][3], dtype=float)
    helper = np.eye(3)[int(np.argmin(np.abs(n)))]
    t1 = helper - (helper @ n) * n
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    flat = contacts.reshape(-1, 3)
    flat = flat[np.all(np.isfinite(flat), axis=1)]
    if not len(flat):
        return np.zeros((0, 2, 3))
    margin = 2 * max(w[1] for w in geometry.wheels)
    a, b = flat @ t1, flat @ t2
    middle = np.array([(a.min() + a.max()) / 2, (b.min() + b.max()) / 2])
    half = max(a.max() - a.min(), b.max() - b.min()) / 2 + margin
    ticks = np.linspace(-half, half, lines)
    segments = []
    for x in ticks:
        segments.append([(middle[0] + x) * t1 + (middle[1] - half) * t2,
                         (middle[0] + x) * t1 + (middle[1] + half) * t2])
        segments.append([(middle[0] - half) * t1 + (middle[1] + x) * t2,
                         (middle[0] + half) * t1 + (middle[1] + x) * t2])
    return np.array(segments)


def save_animation(animation, path: str | Path, *, fps: int = 25,
                   protect: tuple[Path, ...] = (), progress=None) -> Path:
    """Save a built animation as .gif or .html (a self-contained player), through a temporary
    file and a rename. ``progress(frame, frames)`` is called as each frame is drawn."""
    path = check_animation_path(path)
    if not hasattr(animation, "frame_images"):  # any other matplotlib animation
        return _save_with_matplotlib(animation, path, fps=fps, protect=protect,
                                     progress=progress)
    fps = playback_rate(animation.times, fps)
    if path.suffix.lower() == ".html":
        frames = animation.frame_images(dpi=HTML_DPI, progress=progress)
        page = player_html(frames, fps=fps, times=animation.times, title=animation.title)
        return atomic_write(path, page, protect=protect)
    return atomic_write(path, gif_bytes(animation.frame_images(progress=progress), fps),
                        protect=protect)


def playback_rate(times: np.ndarray, fps: float) -> float:
    """Frames a second that play the frames in real time: ``fps``, or fewer where the run was
    longer than ``max_frames`` allow at ``fps`` (the frames are then further apart)."""
    span = float(times[-1] - times[0]) if len(times) > 1 else 0.0
    return min(float(fps), (len(times) - 1) / span) if span > 0 else float(fps)


def _save_with_matplotlib(animation, path: Path, *, fps, protect, progress) -> Path:
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
        raise InputError(f"cannot write {path}: use a .gif or .html file name", field="animation")
    return path
