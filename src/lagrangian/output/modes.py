"""Reports of equilibria and modes: JSON documents (public contracts), text, and the mode-shape plot."""

from __future__ import annotations

import io
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..analysis.equilibria import Equilibria
from ..analysis.modes import ModalAnalysis, Mode
from ..errors import ModelError
from ..kinds import ModeKind
from .files import atomic_write

# The plot shows at most this many modes (the lowest), in a grid of at most PLOT_COLUMNS columns.
PLOT_MAX_MODES = 12
PLOT_COLUMNS = 3
PANEL_INCHES = (4.0, 3.0)
PLOT_DPI = 100


# -- equilibria ---------------------------------------------------------------------------------


def equilibria_document(found: Equilibria) -> dict[str, Any]:
    """The `equilibria --json` document."""
    items = []
    for e in found:
        item: dict[str, Any] = {"coordinates": dict(e.coordinates), "stable": e.stable}
        if found.constraints:
            item["multipliers"] = dict(e.multipliers)
        items.append(item)
    if found.singular:  # only for bodies in space whose angles lock somewhere at rest
        return {"equilibria": items, "gimbal_lock": [dict(point) for point in found.singular]}
    return {"equilibria": items}


def equilibria_text(found: Equilibria) -> str:
    lines = [f"Equilibria of {found.model_name}", "=" * (14 + len(found.model_name))]
    if not len(found) and not found.singular:
        lines.append("No equilibrium found: at none of the configurations searched (from many "
                     "starting points over the coordinates' ranges) do the forces at rest balance.")
        return "\n".join(lines) + "\n"
    for i, e in enumerate(found, 1):
        where = ", ".join(f"{k} = {_number(v)}" for k, v in e.coordinates.items())
        lines.append(f"{i}. {where}   {'stable' if e.stable else 'unstable'}")
        if e.multipliers:
            reactions = ", ".join(f"lambda_{k} = {_number(v)}" for k, v in e.multipliers.items())
            lines.append(f"   multipliers: {reactions}")
    if found.singular:
        where = "; ".join(", ".join(f"{k} = {_number(v)}" for k, v in point.items())
                          for point in found.singular)
        lines += ["", f"Also at rest where a rotation sequence is singular (gimbal lock), its "
                      f"stability not decided in these coordinates: {where}"]
    neutral = found[0].neutral if len(found) else ()
    if neutral:
        lines += ["", f"Any value of {', '.join(neutral)} is also an equilibrium "
                      "(the equations at rest do not contain it); the model's initial value is shown."]
    return "\n".join(lines) + "\n"


# -- modes --------------------------------------------------------------------------------------


def modes_document(analysis: ModalAnalysis) -> dict[str, Any]:
    """The `modes --json` document; matrices in the coordinates listed under `coordinates`."""
    linear = analysis.linear_model
    return {
        "equilibrium": dict(linear.equilibrium),
        **({"steady": dict(linear.steady)} if linear.steady else {}),
        "stable": analysis.stable,
        "coordinates": list(linear.coordinates),
        "mass_matrix": _rows(linear.mass_matrix),
        "damping_matrix": _rows(linear.damping_matrix),
        "stiffness_matrix": _rows(linear.stiffness_matrix),
        "modes": [mode_document(m) for m in analysis.modes],
    }


def mode_document(mode: Mode) -> dict[str, Any]:
    return {
        "frequency": mode.frequency,
        "frequency_hz": mode.frequency_hz,
        "period": mode.period,
        # a damping ratio belongs to an oscillation: a real eigenvalue's is null, as the text's '–'
        "damping_ratio": None if mode.frequency == 0 else mode.damping_ratio,
        "growth_rate": mode.growth_rate,
        "shape": dict(mode.shape),
        **mode_phases(mode),
    }


def mode_phases(mode: Mode) -> dict[str, dict[str, float]]:
    """Amplitude and phase (rad, in (-pi, pi]) of each coordinate in the complex shape: the
    coordinate moves as amplitude * e^(growth t) * cos(omega_d t + phase), the reference
    coordinate (largest, +1) at phase 0; a real mode's negative components are at phase pi."""
    names = list(mode.shape)
    amplitude, phase = {}, {}
    for name, value in zip(names, mode.complex_shape, strict=True):
        amplitude[name] = float(abs(value))
        angle = float(np.angle(value)) + 0.0 if abs(value) > 0 else 0.0
        phase[name] = math.pi if angle <= -math.pi + 1e-12 else angle  # -1 - 0j: pi, not -pi
    return {"amplitude": amplitude, "phase": phase}


def modes_text(analysis: ModalAnalysis) -> str:
    linear = analysis.linear_model
    title = f"Modes of {analysis.model_name}"
    lines = [title, "=" * len(title)]
    about = ", ".join(f"{k} = {_number(v)}" for k, v in linear.equilibrium.items())
    if linear.steady:
        rates = ", ".join(f"{k} = {_number(v)}" for k, v in linear.steady.items())
        lines.append(f"About the steady motion {about} with {rates} "
                     f"({'stable' if analysis.stable else 'unstable'})")
    else:
        lines.append(f"About the equilibrium {about} "
                     f"({'stable' if analysis.stable else 'unstable'})")
    if linear.multipliers:
        lines.append("Multipliers: " + ", ".join(f"lambda_{k} = {_number(v)}"
                                                 for k, v in linear.multipliers.items()))
    if linear.velocity_constraints.size:
        lines.append("Velocity constraints restrict the motion, not the configuration: the state "
                     "keeps only velocities that satisfy them.")
    if linear.coordinates != linear.user_coordinates:
        lines.append(f"Matrices in the independent coordinates ({', '.join(linear.coordinates)}); "
                     "shapes in all coordinates.")
    lines.append("")
    # A coordinate named M, C or K labels rows and columns: the matrices then lose their letter.
    letter = {n: ("" if n in linear.user_coordinates else f" {n}") for n in "MCK"}
    for label, matrix in ((f"Mass matrix{letter['M']}", linear.mass_matrix),
                          (f"Damping matrix{letter['C']} (dissipation + gyroscopic)",
                           linear.damping_matrix),
                          (f"Stiffness matrix{letter['K']}", linear.stiffness_matrix)):
        lines.append(f"{label}:")
        lines += _matrix_lines(matrix, linear.coordinates)
        lines.append("")
    if not analysis.modes:
        lines.append("No modes: the model has no degree of freedom left.")
        return "\n".join(lines) + "\n"
    names = linear.user_coordinates
    header = f"{'mode':>4}  {'omega [rad/s]':>13}  {'f [Hz]':>10}  {'period [s]':>10}  " \
             f"{'zeta':>8}  {'growth [1/s]':>12}  " + "  ".join(f"{n:>9}" for n in names)
    lines += ["Modes (ascending frequency; shapes scaled so the largest component is +1):",
              header]
    for i, m in enumerate(analysis.modes, 1):
        period = "-" if m.period is None else _number(m.period)
        # a damping ratio belongs to an oscillation: a real eigenvalue (frequency 0) has none
        zeta = "–" if m.damping_ratio is None or m.frequency == 0 else _number(m.damping_ratio)
        shape = "  ".join(f"{_number(m.shape[n]):>9}" for n in names)
        lines.append(f"{i:>4}  {_number(m.frequency):>13}  {_number(m.frequency_hz):>10}  "
                     f"{period:>10}  {zeta:>8}  {_number(m.growth_rate):>12}  {shape}  "
                     f"{_kind_note(m)}".rstrip())
    complex_modes = [(i, m) for i, m in enumerate(analysis.modes, 1)
                     if any(abs(v.imag) > 1e-9 for v in m.complex_shape)]
    if complex_modes:
        lines += ["", "Complex modes (gyroscopic or non-proportional damping): the shape above is "
                      "the snapshot when the reference coordinate peaks;",
                  "amplitude and phase of each coordinate:"]
        for i, m in complex_modes:
            parts = ", ".join(f"{n} {abs(v):.4g} at {math.degrees(np.angle(v)):+.1f} deg"
                              for n, v in zip(names, m.complex_shape, strict=True))
            lines.append(f"  mode {i}: {parts}")
    return "\n".join(lines) + "\n"


def _kind_note(mode: Mode) -> str:
    kind = mode.kind
    if kind == ModeKind.DIVERGENT:
        return "(unstable: grows without oscillating)"
    if kind == ModeKind.RIGID_BODY:
        return "(rigid-body: zero frequency)"
    if mode.growth_rate > 0:
        return "(unstable: growing oscillation)"
    if kind == ModeKind.OVERDAMPED:
        return "(overdamped)"
    return ""


# -- the mode-shape plot ------------------------------------------------------------------------


def mode_plot_size(mode_count: int) -> tuple[int, int]:
    """Pixel size (width, height) of the mode-shape plot for this many modes."""
    shown = max(1, min(mode_count, PLOT_MAX_MODES))
    columns = min(PLOT_COLUMNS, shown)
    rows = math.ceil(shown / columns)
    return (round(PANEL_INCHES[0] * columns * PLOT_DPI), round(PANEL_INCHES[1] * rows * PLOT_DPI))


def mode_shape_figure(analysis: ModalAnalysis):
    """A matplotlib Figure with one panel per mode (the lowest twelve): the shape per coordinate."""
    from .plots import notebook_figure, plain_text  # the figure's helpers: loaded by a plot

    modes = analysis.modes[:PLOT_MAX_MODES]
    if not modes:
        raise ModelError("there are no modes to plot (no degree of freedom)", field="plot")
    width, height = mode_plot_size(len(modes))
    figure = notebook_figure(figsize=(width / PLOT_DPI, height / PLOT_DPI), dpi=PLOT_DPI,
                             layout="constrained")
    columns = min(PLOT_COLUMNS, len(modes))
    rows = math.ceil(len(modes) / columns)
    axes = figure.subplots(rows, columns, squeeze=False).ravel()
    names = list(analysis.linear_model.user_coordinates)
    positions = np.arange(len(names))
    for i, (ax, mode) in enumerate(zip(axes, modes, strict=False), 1):
        values = [mode.shape[n] for n in names]
        if len(names) <= 12:
            ax.bar(positions, values, color=["tab:blue" if v >= 0 else "tab:red" for v in values])
            ax.set_xticks(positions, [plain_text(n) for n in names], fontsize=8)
        else:  # a chain of many coordinates reads better as a line
            from matplotlib.ticker import MaxNLocator

            ax.plot(positions + 1, values, marker=".", color="tab:blue")
            ax.xaxis.set_major_locator(MaxNLocator(integer=True))
            ax.set_xlabel("coordinate number", fontsize=8)
        ax.axhline(0.0, color="black", linewidth=0.6)
        if _is_complex(mode):
            _draw_motion(ax, mode, positions if len(names) <= 12 else positions + 1,
                         bars=len(names) <= 12)
        ax.set_ylim(-1.15, 1.15)
        ax.set_title(f"mode {i}: {_title(mode)}", fontsize=9)
        ax.tick_params(labelsize=8)
    for ax in axes[len(modes):]:
        ax.set_visible(False)
    title = f"Mode shapes of {plain_text(analysis.model_name)}"
    if len(analysis.modes) > len(modes):
        title += f" (lowest {len(modes)} of {len(analysis.modes)} modes)"
    figure.suptitle(title, fontsize=10)
    return figure


# A complex mode is drawn over one period as this many snapshots of Re(shape e^(i theta)).
MOTION_SNAPSHOTS = 8


def _is_complex(mode: Mode) -> bool:
    return any(abs(v.imag) > 1e-9 for v in mode.complex_shape)


def mode_snapshots(mode: Mode, count: int = MOTION_SNAPSHOTS) -> tuple[np.ndarray, np.ndarray]:
    """Phases theta_k = 2 pi k / count over one period and the shapes Re(shape e^(i theta_k))
    (count, coordinates): the mode's motion, its growth or decay left out."""
    theta = 2 * np.pi * np.arange(count) / count
    shape = np.array(mode.complex_shape)
    return theta, np.real(shape[None, :] * np.exp(1j * theta)[:, None])


def _draw_motion(ax, mode: Mode, positions: np.ndarray, bars: bool) -> None:
    """A complex (gyroscopic, non-proportionally damped) mode moves its coordinates out of step.
    Bars: over each coordinate's bar, its motion Re(a e^(i theta)) over one period (theta from
    0 at the bar's left to 2 pi at its right), so the phase shifts show. Many coordinates: the
    shape at snapshots over one period, coloured by phase (a wave along a chain)."""
    if bars:
        theta = np.linspace(0, 2 * np.pi, 49)
        for position, value in zip(positions, mode.complex_shape, strict=True):
            ax.plot(position + 0.8 * (theta / (2 * np.pi) - 0.5),
                    np.real(value * np.exp(1j * theta)), color="tab:orange", linewidth=1.4,
                    label="motion")
            if abs(value) > 0:
                ax.text(position, -1.08, f"{math.degrees(np.angle(value)):+.0f}°", ha="center",
                        fontsize=7, color="tab:orange")
        ax.text(0.02, 0.03, "orange: each coordinate over one period", transform=ax.transAxes,
                fontsize=7, color="0.35")
        return
    from matplotlib import colormaps

    theta, snapshots = mode_snapshots(mode)
    colours = colormaps["twilight"](theta / (2 * np.pi))
    for snapshot, colour in zip(snapshots, colours, strict=True):
        ax.plot(positions, snapshot, color=colour, linewidth=0.9, alpha=0.8, label="snapshot")
    ax.text(0.02, 0.03, f"{len(theta)} snapshots over one period", transform=ax.transAxes,
            fontsize=7, color="0.35")


def write_mode_plot(analysis: ModalAnalysis, path: str | Path, *,
                    protect: tuple[Path, ...] = ()) -> Path:
    """Draw the mode shapes to a PNG file (written atomically, never over an input file)."""
    if Path(path).suffix.lower() != ".png":
        raise ModelError(f"the plot is written as PNG; name the file *.png (got '{path}')",
                         field="plot")
    figure = mode_shape_figure(analysis)
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=PLOT_DPI)
    return atomic_write(path, buffer.getvalue(), protect=protect)


def _title(mode: Mode) -> str:
    if mode.frequency > 0:
        text = f"{mode.frequency:.4g} rad/s ({mode.frequency_hz:.4g} Hz)"
        if mode.damping_ratio:
            text += f", zeta {mode.damping_ratio:.3g}"
        return text
    if mode.growth_rate > 0:
        return f"unstable, grows at {mode.growth_rate:.4g} 1/s"
    return "rigid-body (0 rad/s)"


# -- helpers ------------------------------------------------------------------------------------


def _rows(matrix: np.ndarray) -> list[list[float]]:
    return [[float(v) + 0.0 for v in row] for row in np.asarray(matrix, dtype=float)]


def _number(value: float) -> str:
    value = float(value)
    if value == 0:
        return "0"
    return f"{value:.6g}"


def _matrix_lines(matrix: np.ndarray, names) -> list[str]:
    width = max([9, *(len(n) for n in names)])
    lines = ["  " + " " * width + "  " + "  ".join(f"{n:>{width}}" for n in names)]
    for name, row in zip(names, np.asarray(matrix), strict=True):
        lines.append(f"  {name:>{width}}  " + "  ".join(f"{_number(v):>{width}}" for v in row))
    return lines
