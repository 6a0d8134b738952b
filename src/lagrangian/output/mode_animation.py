"""The mechanism oscillating in a mode: q(phi) = q0 + a Re(u e^(i phi)) over one period.

q0 is the equilibrium the modes are about, u the mode's (complex) shape in the coordinates and a
an amplitude chosen so that the point that moves most moves an eighth of the drawing (angles at
most 0.35 rad), so the linear motion stays a small one. Each mode plays one period per loop at
the same pace whatever its frequency (its growth or decay left out), so modes side by side are
compared by their shapes: in phase (the masses move together) or out of phase (against each
other). A model given by its energies only (no particles or bodies) is drawn as its coordinates:
each length a block on a line, each angle a rod from a pivot, said so in the title.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..analysis.modes import ModalAnalysis, Mode
from ..errors import InputError
from ..model.model import Model
from .animation import (
    DEFAULT_SIZE,
    _animation,
    animation_figure,
    check_fps,
    check_size,
    check_view,
    mechanism_panel,
)
from .geometry import Frame, mechanism
from .modes import _title
from .plots import plain_text

# At most this many modes (the lowest) are drawn side by side, in at most MODE_COLUMNS columns.
MODE_ANIMATION_MAX = 6
MODE_COLUMNS = 3
# One period lasts this long when played (s): 2 * fps frames.
PERIOD_SECONDS = 2.0
# The point that moves most moves this fraction of the drawing's size; an angle at most MAX_ANGLE.
MOTION_FRACTION = 0.125
MAX_ANGLE = 0.35


@dataclass(frozen=True)
class ModeMotion:
    """One mode's motion as drawn: the phases phi (rad) over one period, the states q (and
    q_dot, for the drawing's velocity-dependent parts) in the model's coordinates, the
    amplitude a (the scale of the shape u in q = q0 + a Re(u e^(i phi))) and the real time of
    each frame, t = phi / omega (s; phi / (2 pi) periods of PERIOD_SECONDS for a
    zero-frequency mode)."""

    number: int
    mode: Mode
    phases: np.ndarray
    q: np.ndarray
    q_dot: np.ndarray
    amplitude: float
    times: np.ndarray


def mode_numbers(analysis: ModalAnalysis, mode: int | None) -> list[int]:
    """The modes drawn, numbered from 1 as printed: ``mode`` alone, or the lowest
    MODE_ANIMATION_MAX."""
    count = len(analysis.modes)
    if not count:
        raise InputError("there are no modes to animate (no degree of freedom)", field="mode")
    if mode is None:
        return list(range(1, min(count, MODE_ANIMATION_MAX) + 1))
    if isinstance(mode, bool) or not isinstance(mode, (int, np.integer)) or not 1 <= mode <= count:
        raise InputError(f"modes are numbered 1 to {count} (as printed), got {mode!r}",
                         field="mode")
    return [int(mode)]


def mode_motion(analysis: ModalAnalysis, model: Model, number: int, frames: int = 40,
                geometry=None) -> ModeMotion:
    """Mode ``number`` (from 1) over one period in ``frames`` frames (see the module's text)."""
    mode = analysis.modes[number - 1]
    names = [c.name for c in model.coordinates]
    shape_by_name = dict(zip(analysis.linear_model.user_coordinates, mode.complex_shape,
                             strict=True))
    shape = np.array([shape_by_name.get(n, 0j) for n in names], dtype=complex)
    q0 = np.array([analysis.equilibrium.get(n, 0.0) for n in names], dtype=float)
    phases = 2 * np.pi * np.arange(frames) / frames
    oscillating = mode.frequency > 0
    if not oscillating:  # a rigid-body or divergent mode: back and forth along its shape
        shape = shape.real.astype(complex) * -1j  # Re(-i u e^(i phi)) = u sin(phi)
    amplitude = _amplitude(model, q0, shape, geometry)
    wave = np.exp(1j * phases)[:, None]
    q = q0 + amplitude * np.real(shape[None, :] * wave)
    omega = mode.frequency if oscillating else 2 * np.pi / PERIOD_SECONDS
    q_dot = amplitude * np.real(1j * omega * shape[None, :] * wave)
    return ModeMotion(number, mode, phases, q, q_dot, float(amplitude), phases / omega)


def _amplitude(model: Model, q0: np.ndarray, shape: np.ndarray, geometry) -> float:
    """a such that the point that moves most moves MOTION_FRACTION of the drawing, measured on
    the drawing itself (a first-order difference); angles at most MAX_ANGLE."""
    size = np.abs(shape)
    if not size.any():
        return 0.0
    cap = np.inf
    for c, s in zip(model.coordinates, size, strict=True):
        if s > 0 and c.unit in ("rad", "radian"):
            cap = min(cap, MAX_ANGLE / s)
    step = 1e-6
    states = np.stack([q0, q0 + step * shape.real, q0 + step * shape.imag])
    points = _drawn_points(geometry, states)
    if points is None or not points.size:
        return float(min(cap, 1.0 / size.max() * 0.25))
    finite = np.all(np.isfinite(points), axis=(0, 2))
    points = points[:, finite]
    at_rest = np.concatenate([points[0], np.zeros((1, points.shape[-1]))])
    extent = float(np.max(at_rest.max(axis=0) - at_rest.min(axis=0))) if len(at_rest) else 0.0
    moved = max(float(np.max(np.linalg.norm(points[1] - points[0], axis=-1), initial=0.0)),
                float(np.max(np.linalg.norm(points[2] - points[0], axis=-1), initial=0.0))) / step
    if moved <= 0 or extent <= 0:
        return float(min(cap, 0.25 / size.max()))
    return float(min(cap, MOTION_FRACTION * extent / moved))


def _drawn_points(geometry, states: np.ndarray) -> np.ndarray | None:
    """The points the drawing puts on the screen (particles, bar ends, rod ends; for bodies in
    space their joints and centres too) at each state, (states, points, dims)."""
    if geometry is None:
        return None
    zeros = np.zeros_like(states)
    t = np.zeros(len(states))
    with np.errstate(all="ignore"):
        if getattr(geometry, "rigid_body_names", ()):
            space = geometry.space_frame(states, zeros, t)
            parts = [space.particles, space.origins, space.centres,
                     space.bars.reshape(len(t), -1, 3)]
        else:
            frame = geometry.frame(states, zeros, t)
            parts = [frame.particles, frame.bars.reshape(len(t), -1, 2),
                     frame.rods.reshape(len(t), -1, 2)]
    return np.concatenate(parts, axis=1)


class CoordinateSketch:
    """The drawing of a model given by its energies only: each coordinate with a length unit a
    block sliding along its line (x = its index, spaced 1 apart, plus its change from rest),
    each angle a rod of length 0.8 from a pivot at its index. It answers what the mechanism
    panel asks of a geometry.Mechanism."""

    body_names: tuple = ()
    spring_names: tuple = ()
    damper_names: tuple = ()
    rigid_body_names: tuple = ()
    rolling: tuple = ()
    aimed: tuple = ()
    gravity = None

    def __init__(self, model: Model, q0: np.ndarray):
        self.q0 = q0
        self.angles = [c.unit in ("rad", "radian") for c in model.coordinates]
        self.particle_names = tuple(c.name for c in model.coordinates)
        self.blocks = tuple((i, (1.0, 0.0)) for i, angle in enumerate(self.angles) if not angle)
        self.rod_count = self.pivot_count = sum(self.angles)

    def frame(self, q: np.ndarray, v: np.ndarray, t: np.ndarray) -> Frame:
        k = len(t)
        change = q - self.q0
        points = np.zeros((k, len(self.angles), 2))
        rods, pivots = [], []
        for i, angle in enumerate(self.angles):
            if angle:
                pivot = np.array([float(i), 0.4])
                points[:, i] = pivot + 0.8 * np.column_stack([np.sin(change[:, i]),
                                                              -np.cos(change[:, i])])
                rods.append(np.stack([np.broadcast_to(pivot, (k, 2)), points[:, i]], axis=1))
                pivots.append(np.broadcast_to(pivot, (k, 2)))
            else:
                points[:, i, 0] = i + change[:, i]
        empty = np.zeros((k, 0, 2, 2))
        return Frame(points, empty, empty, empty,
                     np.stack(rods, axis=1) if rods else empty,
                     np.stack(pivots, axis=1) if pivots else np.zeros((k, 0, 2)))


def _rest(ax, geometry, q0: np.ndarray, drawable: bool, names: list[str]) -> None:
    """The configuration at rest, still and pale behind the motion (what the mode moves away
    from); the coordinates' names under a coordinate drawing."""
    if getattr(geometry, "rigid_body_names", ()):
        return
    at_rest = geometry.frame(q0[None, :], np.zeros((1, len(q0))), np.zeros(1))
    for a, b in at_rest.rods[0]:
        ax.plot([a[0], b[0]], [a[1], b[1]], color="0.8", linewidth=1.5, linestyle="--", zorder=0)
    for a, b in at_rest.bars[0]:
        ax.plot([a[0], b[0]], [a[1], b[1]], color="0.8", linewidth=3, zorder=0)
    points = at_rest.particles[0]
    ax.plot(points[:, 0], points[:, 1], "o", markerfacecolor="none", markeredgecolor="0.6",
            markersize=10, zorder=0, label="at rest")
    if not drawable:
        for name, point in zip(names, points, strict=True):
            ax.annotate(plain_text(name), point, xytext=(0, -22), textcoords="offset points",
                        ha="center", fontsize=9, color="0.3")


def mode_animation(analysis: ModalAnalysis, model: Model, parameters=None, *, mode: int | None = None,
                   fps: int = 20, size: object = None, view: object = None):
    """The mechanism oscillating in mode ``mode`` (numbered from 1 as printed), or in each of
    the lowest six side by side: a MechanismAnimation (save it with media.save_animation as
    .gif, .html or .mp4; in a notebook it shows itself as a player). One period lasts
    PERIOD_SECONDS at ``fps`` frames a second; ``size`` = (width, height) in pixels (default
    400 x 400 a mode); ``view`` = (azimuth, elevation) for bodies in space. Each panel's
    ``frame`` holds the positions drawn, ``motions`` each mode's ModeMotion."""
    numbers = mode_numbers(analysis, mode)
    fps = check_fps(fps)
    size = check_size(size)
    view = check_view(view)
    names = [c.name for c in model.coordinates]
    q0 = np.array([analysis.equilibrium.get(n, 0.0) for n in names], dtype=float)
    drawable = bool(model.particles or model.bodies or model.rigid_bodies)
    geometry = mechanism(model, parameters) if drawable else CoordinateSketch(model, q0)
    frames = int(max(12, min(240, round(PERIOD_SECONDS * fps))))
    motions = [mode_motion(analysis, model, n, frames, geometry) for n in numbers]
    columns = min(MODE_COLUMNS, len(numbers))
    rows = math.ceil(len(numbers) / columns)
    if size is None:
        size = (DEFAULT_SIZE[0] * columns, DEFAULT_SIZE[1] * rows)
    figure = animation_figure(size)
    zero_t = np.zeros(frames)
    panels = []
    for index, motion in enumerate(motions):
        ax = figure.add_subplot(rows, columns, index + 1)
        panels.append(mechanism_panel(
            ax, geometry, motion.q, motion.q_dot, zero_t, view=view, trail=frames // 4,
            title=f"mode {motion.number}: {_title(motion.mode)}",
            show_axes=drawable and len(numbers) == 1))
        ax.title.set_fontsize(9 if len(numbers) > 1 else 10)
        _rest(ax, geometry, q0, drawable, names)
    heading = f"Modes of {plain_text(analysis.model_name)}" if len(numbers) > 1 else \
        f"Mode {numbers[0]} of {plain_text(analysis.model_name)}"
    if len(numbers) < len(analysis.modes) and mode is None:
        heading += f" (lowest {len(numbers)} of {len(analysis.modes)})"
    if not drawable:
        heading += "\n(drawn as its coordinates: the model gives no positions)"
    figure.suptitle(heading, fontsize=10)
    phase = figure.axes[0].text(0.02, 0.95, "", transform=figure.axes[0].transAxes,
                                fontsize=8)
    degrees = np.degrees(motions[0].phases)

    def draw(k):
        phase.set_text(f"phase {degrees[k]:3.0f}°")
        return [artist for panel in panels for artist in panel.draw(k)] + [phase]

    animation = _animation(figure, draw, degrees, fps, html_dpi=None, real_time=False,
                           clock="phase {:.0f}°")
    animation.title = heading.split("\n")[0]
    animation.panels = tuple(panels)
    animation.motions = tuple(motions)
    return animation
