"""Pictures for the report page (report/page.py), each inline as a data: URI so the page needs
nothing from anywhere else: a drawing of the mechanism, the time-history plot, and animated GIFs
of the simulation and of each mode (a GIF plays in any browser without JavaScript).

The drawings are output/animation.py's (``mechanism_animation``), fed a motion: the simulated
one, the initial state held still, or a mode's motion q(t) = q0 + a Re(phi e^(i omega t)) over
one period about its equilibrium.
"""

from __future__ import annotations

import base64
import io
from dataclasses import dataclass

import numpy as np

from ..analysis.modes import ModalAnalysis, Mode
from ..errors import ModelError
from ..model.model import Model
from ..output.animation import HTML_DPI, gif_bytes, mechanism_animation, playback_rate
from ..output.geometry import mechanism

# A mode's motion: this many frames over one period, played in MODE_CYCLE seconds whatever the
# period (a 0.01 s mode and a 10 s mode both read), and the largest point of the mechanism moved
# by MODE_REACH of the drawing's size (at most MODE_MAX_ANGLE rad in any angle).
MODE_FRAMES = 24
MODE_CYCLE = 1.6
MODE_REACH = 0.2
MODE_MAX_ANGLE = 0.5
MODES_ANIMATED = 6  # the lowest modes get an animation; the others their numbers only
# The simulation's animation: frames a second and at most this many (a page stays ~1 MB).
SIMULATION_FPS = 20
SIMULATION_FRAMES = 120


NOTHING_TO_DRAW = ("Nothing to draw: the model is given by its energies only, with no particle "
                   "or body to place in space.")


def drawable(model: Model) -> bool:
    """Whether the model has something to draw: a particle or a body."""
    return bool(model.particles or model.bodies or model.rigid_bodies)


def data_uri(data: bytes, mime: str) -> str:
    return f"data:{mime};base64,{base64.b64encode(data).decode('ascii')}"


def figure_png(figure, dpi: float = 80) -> bytes:
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()


@dataclass(frozen=True)
class Motion:
    """What output/animation.py draws: the model, its parameters (SI) and states q, q_dot (k, n)
    at times t (s)."""

    model: Model
    parameters: dict
    t: np.ndarray
    q: np.ndarray
    q_dot: np.ndarray
    title: str

    @property
    def model_name(self) -> str:
        return self.title


def _parameters(model: Model) -> dict:
    return {p.name: p.value for p in model.parameters}


def _png(frame: np.ndarray) -> bytes:
    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(frame).save(buffer, format="PNG", optimize=True)
    return buffer.getvalue()


def drawing_png(model: Model, q: np.ndarray) -> bytes:
    """The mechanism drawn at the configuration q (SI, model order), at rest."""
    missing = [p.name for p in model.parameters if p.value is None]
    if missing:  # the drawing is made of numbers
        raise ModelError(f"no value for {', '.join(missing)} (the drawing needs numbers: give "
                         "each a value)", field="parameters")
    still = Motion(model, _parameters(model), np.array([0.0, 1.0]), np.array([q, q], float),
                   np.zeros((2, len(q))), model.name)
    animation = mechanism_animation(still, fps=1, max_frames=2)
    frame = next(iter(animation.frame_images(dpi=HTML_DPI)))
    return _png(frame)


def simulation_gif(result, *, size: tuple[int, int] | None = None,
                   fps: float | None = None) -> bytes:
    """The simulated run as an endlessly looping GIF, in real time where the frames allow;
    ``size`` (width, height) in pixels, ``fps`` frames a second (the same stretch of the run
    is shown at any rate: at most SIMULATION_FRAMES frames at SIMULATION_FPS)."""
    rate = SIMULATION_FPS if fps is None else fps
    animation = mechanism_animation(result, fps=rate, size=size,
                                    max_frames=max(2, round(SIMULATION_FRAMES * rate
                                                            / SIMULATION_FPS)))
    frames = list(animation.frame_images(dpi=None if size else HTML_DPI))
    return gif_bytes(frames, playback_rate(animation.times, rate))


def mode_motion(model: Model, analysis: ModalAnalysis, mode: Mode, index: int) -> Motion:
    """One period of mode ``index`` (1-based) about its equilibrium: q0 + a Re(phi e^(i w t)),
    the amplitude a chosen so the drawing moves visibly but stays near the linear range."""
    names = [c.name for c in model.coordinates]
    defaults = [c.initial or 0.0 for c in model.coordinates]
    q0 = np.array([analysis.equilibrium.get(n, d) for n, d in zip(names, defaults, strict=True)],
                  dtype=float)
    shape = np.array([complex(_shape_entry(mode, analysis, n)) for n in names])
    theta = 2 * np.pi * np.arange(MODE_FRAMES) / MODE_FRAMES
    omega = mode.frequency
    motion = np.real(shape[None, :] * np.exp(1j * theta)[:, None])  # (frames, n)
    rates = np.real(1j * omega * shape[None, :] * np.exp(1j * theta)[:, None])
    a = _amplitude(model, q0, np.real(shape))
    t = theta / omega
    title = f"{model.name}: mode {index}"
    return Motion(model, _parameters(model), t, q0 + a * motion, a * rates, title)


def _shape_entry(mode: Mode, analysis: ModalAnalysis, name: str) -> complex:
    users = list(analysis.linear_model.user_coordinates)
    if name in users and len(mode.complex_shape) == len(users):
        return mode.complex_shape[users.index(name)]
    return mode.shape.get(name, 0.0)


def _amplitude(model: Model, q0: np.ndarray, shape: np.ndarray) -> float:
    """The amplitude a: the drawn points move by at most MODE_REACH of the drawing's span
    (measured by a small step along the shape), and no angle by more than MODE_MAX_ANGLE."""
    largest = float(np.max(np.abs(shape))) or 1.0
    angles = [abs(s) for s, c in zip(shape, model.coordinates, strict=True) if c.unit == "rad"]
    cap = MODE_MAX_ANGLE / max(angles) if angles and max(angles) > 0 else np.inf
    if model.rigid_bodies:
        return float(min(0.3 / largest, cap))
    geometry = mechanism(model, _parameters(model))
    step = 1e-4 / largest
    states = np.array([q0, q0 + step * shape])
    frame = geometry.frame(states, np.zeros_like(states), np.zeros(2))
    pieces = [part.reshape(2, -1, 2) for part in (frame.particles, frame.bars, frame.rods)
              if part is not None and part.size]
    if not pieces:
        return float(min(0.3 / largest, cap))
    points = np.concatenate(pieces, axis=1)
    finite = np.all(np.isfinite(points), axis=(0, 2))
    points = points[:, finite]
    span = float(np.max(np.ptp(np.concatenate([points[0], [[0.0, 0.0]]]), axis=0))) or 1.0
    moved = float(np.max(np.hypot(*(points[1] - points[0]).T))) / step if points.size else 0.0
    if moved <= 0:
        return float(min(0.3 / largest, cap))
    return float(min(MODE_REACH * span / moved, cap))


def mode_gif(model: Model, analysis: ModalAnalysis, mode: Mode, index: int, *,
             size: tuple[int, int] | None = None, fps: float | None = None) -> bytes:
    """Mode ``index`` (1-based) drawn moving over one period, as a looping GIF: the modes
    command's own animation (output/mode_animation.py), one period in MODE_CYCLE seconds;
    ``size`` (width, height) in pixels (default 320 x 320), ``fps`` frames a second."""
    from ..output.mode_animation import mode_animation

    fps = round(MODE_FRAMES / MODE_CYCLE) if fps is None else fps
    animation = mode_animation(analysis, model, mode=index, fps=fps, size=size or (320, 320))
    return gif_bytes(list(animation.frame_images()), fps)


def coordinate_mode_gif(analysis: ModalAnalysis, mode: Mode, index: int, units: dict, *,
                        size: tuple[int, int] | None = None, fps: float | None = None) -> bytes:
    """A model given by its energies has nothing to draw: mode ``index`` (1-based) shown as each
    coordinate's dot moving along its own track, q_i = Re(phi_i e^(i theta)) over one period
    (largest +-1), so in phase and out of phase read at a glance; ``size`` in pixels, ``fps``
    frames a second (one period in MODE_CYCLE seconds)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ..output.plots import plain_text

    names = list(analysis.linear_model.user_coordinates)
    shape = np.array([complex(_shape_entry(mode, analysis, n)) for n in names])
    shape = shape / (np.max(np.abs(shape)) or 1.0)
    rows = len(names)
    inches = (5, 1.2 + 0.55 * rows) if size is None else (size[0] / HTML_DPI, size[1] / HTML_DPI)
    count = MODE_FRAMES if fps is None else int(min(240, max(8, round(fps * MODE_CYCLE))))
    figure = Figure(figsize=inches, dpi=HTML_DPI, layout="constrained")
    FigureCanvasAgg(figure)
    ax = figure.add_subplot()
    ax.set_xlim(-1.3, 1.3)
    ax.set_ylim(rows - 0.4, -0.6)
    ax.set_yticks(range(rows), [f"{plain_text(n)} ({units.get(n) or '1'})" for n in names])
    ax.set_xticks([-1, 0, 1], ["-a", "0", "+a"])
    for row in range(rows):
        ax.plot([-1.1, 1.1], [row, row], color="0.6", linewidth=1)
        ax.plot([0, 0], [row - 0.15, row + 0.15], color="0.6", linewidth=1)
    dots = ax.plot(np.zeros(rows), np.arange(rows), "o", color="tab:red", markersize=12)[0]
    ax.set_title(f"mode {index}: each coordinate's motion (a: the largest amplitude)",
                 fontsize=9)
    frames = []
    for theta in 2 * np.pi * np.arange(count) / count:
        dots.set_xdata(np.real(shape * np.exp(1j * theta)))
        figure.canvas.draw()
        frames.append(np.asarray(figure.canvas.buffer_rgba())[..., :3].copy())
    return gif_bytes(frames, count / MODE_CYCLE)
