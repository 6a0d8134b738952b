"""Time-history plots of a simulation: coordinates, energy (and multipliers) against time."""

from __future__ import annotations

import functools
import io
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError
from .files import atomic_write

if TYPE_CHECKING:
    from ..simulation.result import SimulationResult

PLOT_FORMATS = (".png", ".svg", ".pdf")


def plain_text(text: str) -> str:
    """User text (a model's name, a coordinate's) for a matplotlib label, drawn as written:
    control characters dropped (no font has a glyph for them), each '$' escaped, so that text
    between two dollars is never parsed as mathtext (a name such as 'cost $\\frac$' raised a
    ParseSyntaxException deep in the drawing)."""
    return str(text).translate(_CONTROLS).replace("$", r"\$")


_CONTROLS = dict.fromkeys([*range(0x00, 0x0A), *range(0x0B, 0x20), 0x7F, *range(0x80, 0xA0),
                           *range(0x202A, 0x202F), *range(0x2066, 0x206A)])


def notebook_figure(**options):
    """A matplotlib Figure (drawn by Agg, never through pyplot, so nothing is left open) that
    shows itself in a notebook: the last line of a cell displays it as PNG with no
    %matplotlib magic. ``options`` go to Figure (figsize, dpi, layout)."""
    return _notebook_figure_class()(**options)


@functools.cache
def _notebook_figure_class():
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    class NotebookFigure(Figure):
        """A Figure with ``_repr_png_`` (Jupyter's image/png)."""

        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            FigureCanvasAgg(self)

        def _repr_png_(self) -> bytes:
            return figure_png(self)

    return NotebookFigure


def figure_png(figure, dpi: float = 100) -> bytes:
    """The figure as PNG bytes, rendered by Agg."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()


MARKED_IMPACTS = 200  # impacts marked on the time histories (an accumulation has many more)


def time_history_figure(result: SimulationResult, units: dict[str, str] | None = None):
    """A matplotlib Figure: coordinates (one panel per unit), energy T + V, multipliers.

    Built without pyplot, so it works headless; in Jupyter the Figure shows itself.
    """
    from .simulation import INVARIANT_WORDS  # the run's words: loaded with a run to plot

    units = units or {}
    groups: dict[str, list[int]] = {}
    for i, name in enumerate(result.coordinates):
        groups.setdefault(units.get(name, ""), []).append(i)
    panels = len(groups) + 1 + (1 if result.constraint_names else 0)
    figure = notebook_figure(figsize=(8, 2.4 * panels + 0.6), layout="constrained")
    axes = figure.subplots(panels, 1, sharex=True, squeeze=False)[:, 0]
    for ax, (unit, indices) in zip(axes, groups.items(), strict=False):
        for i in indices:
            ax.plot(result.t, result.q[:, i], label=plain_text(result.coordinates[i]))
        ax.set_ylabel(f"coordinate ({unit})" if unit else "coordinate")
        _legend_outside(ax)
    ax = axes[len(groups)]
    balance = result.balance
    if result.energy_conserved and len(result.energy):
        # Conserved: the change is what matters, so draw E - E0 rather than E near a big offset.
        ax.plot(result.t, result.energy - result.energy[0], color="black")
        ax.set_ylabel("E - E0 (J)")
        ax.set_title(f"energy T + V, E0 = {result.energy[0]:.6g} J, relative drift "
                     f"{result.energy_drift:.1e}", fontsize="small")
    elif result.invariant == "jacobi_integral" and balance is not None and len(balance):
        # h is what is conserved (T + V is not): draw h - h0.
        ax.plot(result.t, balance, color="black")
        ax.set_ylabel("h - h0 (J)")
        ax.set_title(f"{INVARIANT_WORDS[result.invariant]}, relative drift "
                     f"{result.invariant_drift:.1e}", fontsize="small")
    else:
        # The energy changes (by the work of the loads): draw it, and say how well the work
        # balance h - h0 - int P dt closes.
        ax.plot(result.t, result.energy, color="black")
        ax.set_ylabel("energy T + V (J)")
        if result.invariant == "work_balance" and result.invariant_drift is not None:
            ax.set_title(f"{INVARIANT_WORDS[result.invariant]}, relative drift "
                         f"{result.invariant_drift:.1e}", fontsize="small")
    if np.any(result.power != 0):
        power_axis = ax.twinx()
        power_axis.plot(result.t, result.power, color="tab:red", linewidth=0.8)
        power_axis.set_ylabel("power of loads (W)", color="tab:red")
    if result.constraint_names:
        ax = axes[-1]
        for i, name in enumerate(result.constraint_names):
            ax.plot(result.t, result.multipliers[:, i], label=plain_text(f"lambda_{name}"))
        ax.set_ylabel("multiplier")
        _legend_outside(ax)
    for record in getattr(result, "impacts", ())[:MARKED_IMPACTS]:  # a run through impacts
        for ax in axes:
            ax.axvline(record.time, color="0.75", linewidth=0.6, linestyle=":", zorder=0)
    axes[-1].set_xlabel("t (s)")
    status = "" if result.completed else f" ({result.status})"
    figure.suptitle(plain_text(f"{result.model_name}{status}"))
    return figure


def _legend_outside(ax) -> None:
    """The legend to the right of the panel, outside it, so it hides no curve (constrained
    layout narrows the panels to make room)."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize="small")


def save_figure(figure, path: str | Path, *, protect: tuple[Path, ...] = ()) -> Path:
    """Write a figure (format by suffix) through a temporary file and a rename."""
    path = check_plot_path(path)
    buffer = io.BytesIO()
    figure.savefig(buffer, format=path.suffix.lower().lstrip("."), dpi=110)
    return atomic_write(path, buffer.getvalue(), protect=protect)


def check_plot_path(path: str | Path) -> Path:
    """The path of a plot, refused unless it names a format we write (.png, .svg, .pdf)."""
    path = Path(path)
    if path.suffix.lower() not in PLOT_FORMATS:
        raise InputError(f"cannot write {path}: use a .png, .svg or .pdf file name", field="plot")
    return path
