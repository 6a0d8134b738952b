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

from typing import NamedTuple

import numpy as np

from ..errors import InputError
from ..model.model import Model
from ..simulation.result import SimulationResult
from .geometry import ISOMETRIC_VIEW, Frame, Mechanism, SpaceFrame, mechanism, view_projection
from .media import (  # noqa: F401 - re-exported: the names callers know from here
    ANIMATION_DPI,
    ANIMATION_FORMATS,
    DEFAULT_SIZE,
    HTML_DPI,
    _frame_images,
    check_animation_path,
    check_animation_target,
    check_fps,
    check_size,
    gif_bytes,
    playback_rate,
    player_html,
    save_animation,
    write_mp4,
)
from .plots import plain_text


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
                        view: object = None, size: object = None):
    """A matplotlib FuncAnimation of the mechanism over the run (planar x-y view; a model with
    bodies in space is seen from ``view`` = (azimuth, elevation) in degrees); ``size`` =
    (width, height) of its frames in pixels (default 400 x 400)."""
    check_animatable(result.model)
    samples_q, samples_v = result.q, result.q_dot
    if samples_q.shape[1] != samples_v.shape[1]:  # a ball's quaternion: the bodies' Euler hinges
        from ..simulation.tree_state import drawing_coordinates

        drawn = drawing_coordinates(result.model, result.t, samples_q, samples_v)
        if drawn is None:
            raise InputError("a floating base's run is not animated yet: its table and plot "
                             "are", field="animation")
        samples_q, samples_v = drawn
    view = check_view(view)
    size = check_size(size)
    fps = check_fps(fps)
    geometry = mechanism(result.model, result.parameters)
    times = animation_frames(result, fps, max_frames)
    q = np.column_stack([np.interp(times, result.t, samples_q[:, i])
                         for i in range(samples_q.shape[1])])
    v = np.column_stack([np.interp(times, result.t, samples_v[:, i])
                         for i in range(samples_q.shape[1])])
    figure = animation_figure(size)
    ax = figure.add_subplot()
    offsets = getattr(result, "pivot_offsets", None)  # a walker: where its pivot is by now
    shift = None if offsets is None else offsets[np.clip(
        np.searchsorted(result.t, times, side="right") - 1, 0, len(result.t) - 1)]
    panel = mechanism_panel(ax, geometry, q, v, times, view=view, trail=max(1, int(fps)),
                            title=plain_text(result.model_name), shift=shift)
    clock = _clock(ax)
    struck, labels = _impact_labels(ax, result, times)

    def draw(k):
        clock.set_text(f"{times[k]:.2f}")
        if struck is None:
            return [*panel.draw(k), clock]
        struck.set_text(labels[k])
        return [*panel.draw(k), clock, struck]

    animation = _animation(figure, draw, times, fps, html_dpi=None if size else HTML_DPI)
    animation.panels = (panel,)
    animation.impact_label = struck
    return animation


IMPACT_SHOWN_S = 0.15  # an impact's name stays this long on the frames after it (s)


def _impact_labels(ax, result, times: np.ndarray):
    """A run through impacts: a text in the corner and, per frame, "impact: <name>" on the
    frames within IMPACT_SHOWN_S (or one frame's spacing) after one, else ""."""
    records = getattr(result, "impacts", ())
    if not records:
        return None, None
    at = np.array([record.time for record in records])
    shown = max(IMPACT_SHOWN_S, float(np.max(np.diff(times)))) if len(times) > 1 \
        else IMPACT_SHOWN_S
    latest = np.searchsorted(at, times, side="right") - 1  # each frame's latest impact
    labels = [f"impact: {records[i].name}" if i >= 0 and t - at[i] <= shown else ""
              for i, t in zip(latest, times, strict=True)]
    return ax.text(0.02, 0.89, "", transform=ax.transAxes, color="C3"), labels  # under the clock


def mechanism_picture(model: Model, q=None, parameters=None, *, size: object = None,
                      view: object = None, title: str | None = None):
    """A still drawing of the mechanism at configuration ``q`` (coordinate name -> value, SI;
    the model's initial values where not given): a matplotlib Figure that shows itself in a
    notebook, drawn as the animations draw it."""
    from .plots import notebook_figure

    check_animatable(model)
    view, size = check_view(view), check_size(size) or DEFAULT_SIZE
    given = dict(q or {})
    state = np.array([[float(given.get(c.name, c.initial if c.initial is not None else 0.0))
                       for c in model.coordinates]])
    figure = notebook_figure(figsize=(size[0] / ANIMATION_DPI, size[1] / ANIMATION_DPI),
                             dpi=ANIMATION_DPI, layout="constrained")
    ax = figure.add_subplot()
    panel = mechanism_panel(ax, mechanism(model, parameters), state, np.zeros_like(state),
                            np.zeros(1), view=view, trail=1,
                            title=plain_text(model.name if title is None else title))
    panel.draw(0)
    return figure


def animation_figure(size: tuple[int, int] | None = None, dpi: float = ANIMATION_DPI):
    """A Figure drawn by Agg (never pyplot: nothing is left open) of ``size`` pixels."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    width, height = size or DEFAULT_SIZE
    figure = Figure(figsize=(width / dpi, height / dpi), dpi=dpi, layout="constrained")
    FigureCanvasAgg(figure)
    return figure


class Panel(NamedTuple):
    """One drawing of the mechanism on its axes: ``draw(k)`` puts frame k on it and returns the
    artists it moved; ``frame`` holds the positions drawn (geometry.Frame in the plane,
    geometry.SpaceFrame for bodies in space), frame by frame."""

    draw: object
    frame: Frame | SpaceFrame


def mechanism_panel(ax, geometry: Mechanism, q: np.ndarray, v: np.ndarray, times: np.ndarray, *,
                    view: tuple[float, float] = ISOMETRIC_VIEW, trail: int = 25, title: str = "",
                    show_axes: bool = True, shift: np.ndarray | None = None) -> Panel:
    """Draw the mechanism at states q, v (k, n) on ``ax`` (equal scales; a non-square panel
    gets a square drawing in its middle); each particle leaves a trail of ``trail`` frames.
    ``shift`` (k, 2) moves each frame's drawing (a walker's pivot, m)."""
    if geometry.rigid_body_names:
        return _space_panel(ax, geometry, times, q, v, view, title)
    frame = geometry.frame(q, v, times)
    if shift is not None:
        frame = _shifted(frame, np.asarray(shift, dtype=float)[:, :2])
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

    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_aspect("equal")
    if show_axes:
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    else:
        ax.set_xticks([])
        ax.set_yticks([])
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
    trail_length = max(1, int(trail))
    dots = ax.plot([], [], "o", color="tab:red", markersize=10, label="particles")[0]
    ax.set_title(title)
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
        return [*spring_lines, *damper_lines, *rod_lines, *bar_lines.values(),
                *wheel_lines.values(), *blocks, *trails, dots, pivot_marks, hinges]

    return Panel(draw, frame)


def _shifted(frame, shift: np.ndarray):
    """Every position of a Frame moved by shift (k, 2) m."""
    def moved(points, depth):
        if points is None:
            return None
        return points + shift.reshape((len(shift),) + (1,) * depth + (2,))

    return frame._replace(particles=moved(frame.particles, 1), bars=moved(frame.bars, 2),
                          springs=moved(frame.springs, 2), dampers=moved(frame.dampers, 2),
                          rods=moved(frame.rods, 2), pivots=moved(frame.pivots, 1))


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


def _space_panel(ax, geometry, times, q, v, view, title) -> Panel:
    """The 3D mechanism projected on the screen seen from ``view`` (azimuth, elevation)."""
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

    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(title + f"\n(azimuth {view[0]:.4g}°, elevation {view[1]:.4g}°)")
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
        return [*tracks, *wheel_lines, *boxes, *links, *bars, *rods, *spring_lines, *damper_lines,
                *(line for triad in axes for line in triad), dots]

    return Panel(draw, space)


def _animation(figure, draw, times: np.ndarray, fps: int, *, html_dpi: float | None = HTML_DPI,
               real_time: bool = True, clock: str = "t = {:.2f} s"):
    """Wrap a figure and its per-frame ``draw(k)`` (returning the artists it changed).
    ``html_dpi``: the HTML player's resolution (None: the figure's own); ``real_time``: the
    frames play at the run's pace (False: at ``fps``, a mode over one period); ``clock``
    formats a frame's time under the HTML player."""
    from matplotlib.animation import FuncAnimation

    class MechanismAnimation(FuncAnimation):
        """A matplotlib FuncAnimation that also renders its frames fast (``frame_images``: one
        full draw of the still parts, then only the moving artists per frame), whose
        ``to_jshtml`` is a self-contained player (no remote font or script) and which shows
        itself as that player in a notebook (``_repr_html_``)."""

        def draw(self, k: int) -> list:
            """Put frame k on the figure; the artists it moved."""
            self._draw_was_started = True  # drawn: matplotlib need not warn when it is deleted
            return draw(k)

        def frame_images(self, *, dpi: float | None = None, progress=None):
            self._draw_was_started = True
            return _frame_images(figure, draw, len(times), dpi=dpi, progress=progress)

        def to_jshtml(self, fps=None, embed_frames=True, default_mode=None, *,
                      fragment: bool = False):
            rate = fps or self.fps
            return player_html(self.frame_images(dpi=self.html_dpi),
                               fps=playback_rate(times, rate) if self.real_time else rate,
                               times=times, title=self.title, fragment=fragment,
                               clock=self.clock_format)

        def _repr_html_(self):
            # The player, with no %matplotlib magic and nothing from the network.
            return self.to_jshtml(fragment=True)

    animation = MechanismAnimation(figure, draw, frames=len(times), interval=1000 / fps,
                                   blit=False)
    # Frames are drawn on demand (a file, a player), not by a GUI event loop: an animation
    # kept for its geometry alone is not a forgotten one, so matplotlib need not warn about it.
    animation._draw_was_started = True
    animation.fps = fps
    animation.times = times
    animation.title = figure.axes[0].get_title()
    animation.html_dpi = html_dpi
    animation.real_time = real_time
    animation.clock_format = clock
    return animation


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

