"""What `System.simulate` returns: the sampled run, as a table, a plot or an animation."""

from __future__ import annotations

from pathlib import Path

from .model.model import Model
from .numerics.simulate import SimulationResult


class Simulation:
    """A finished (or stopped, interrupted, failed) run of a system's equations of motion.

    ``result`` holds the arrays (t, q, q_dot, energy, power, multipliers, residuals, SI units);
    ``to_pandas()``, ``plot()`` and ``animate()`` show them.
    """

    def __init__(self, result: SimulationResult, model: Model):
        self.result = result
        self.model = model

    # The arrays, for convenience.
    def __getattr__(self, name: str):
        if name in ("result", "model"):
            raise AttributeError(name)
        return getattr(self.result, name)

    def __getitem__(self, column: str):
        """One column by name: 't', 'theta', 'theta_dot', 'energy', 'lambda_rod', ..."""
        columns = self.result.columns()
        if column not in columns:
            raise KeyError(f"no column {column!r}; columns are {', '.join(columns)}")
        return columns[column]

    def to_pandas(self):
        """A pandas DataFrame with the columns t, <q>, <q>_dot, energy, lambda_*, residual_*,
        power."""
        from .output.tables import result_frame

        return result_frame(self.result)

    def save(self, path: str | Path) -> Path:
        """Write the table as CSV or Parquet (by suffix), atomically."""
        from .output.tables import write_table

        return write_table(self.result, path, protect=self._inputs())

    def plot(self, path: str | Path | None = None):
        """Coordinates, energy (and multipliers) against time; a matplotlib Figure, also
        written to ``path`` (PNG, SVG or PDF) when given."""
        from .output.plots import save_figure, time_history_figure

        figure = time_history_figure(self.result, {c.name: c.unit for c in self.model.coordinates})
        if path is not None:
            save_figure(figure, path, protect=self._inputs())
        return figure

    def animate(self, path: str | Path | None = None, *, fps: int = 25, max_frames: int = 250):
        """The mechanism moving: a matplotlib animation, also written to ``path`` (.gif or
        .html with a player) when given. In Jupyter, ``HTML(sim.animate().to_jshtml())``."""
        from .output.animation import _check_suffix, mechanism_animation, save_animation

        if path is not None:
            _check_suffix(path)
        animation = mechanism_animation(self.result, self.model, fps=fps, max_frames=max_frames)
        if path is not None:
            save_animation(animation, path, fps=fps, protect=self._inputs())
        return animation

    def summary(self) -> dict:
        """JSON-ready summary: final state, steps, wall time, energy drift, largest residual."""
        return self.result.summary()

    def _inputs(self) -> tuple[Path, ...]:
        source = self.model.source
        return (Path(source),) if source and not source.startswith("example:") else ()

    def __repr__(self) -> str:
        r = self.result
        parts = [f"{r.status}", f"t = {r.t[0]:g}..{r.t[-1]:g} s", f"{len(r.t)} samples",
                 f"{r.method}"]
        if r.energy_drift is not None:
            parts.append(f"energy drift {r.energy_drift:.1e}")
        if r.max_residual is not None:
            parts.append(f"max residual {r.max_residual:.1e}")
        return f"Simulation({r.model_name!r}: {', '.join(parts)})"
