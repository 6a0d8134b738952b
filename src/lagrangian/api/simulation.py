"""What `System.simulate` returns: the SimulationResult, with its table, plot and animation."""

from __future__ import annotations

from dataclasses import fields
from pathlib import Path

from ..simulation.result import SimulationResult


class Simulation(SimulationResult):
    """A finished (or stopped, interrupted, failed) run of a system's equations of motion.

    The arrays (t, q, q_dot, energy, power, multipliers, residuals, SI units) and run statistics
    of a SimulationResult; ``to_pandas()``, ``save()``, ``plot()`` and ``animate()`` show them.
    """

    # a run through impacts (simulation/hybrid.py): each ImpactRecord, and where they
    # accumulate (s); () and None for other runs
    impacts: tuple = ()
    accumulation_time: float | None = None
    pivot_offsets = None  # (N, d) m: where a walker's pivot is at each sample

    @classmethod
    def of(cls, result: SimulationResult) -> Simulation:
        """The same run (the same arrays, not copied) with the methods that show it."""
        run = cls(**{f.name: getattr(result, f.name) for f in fields(SimulationResult)})
        for name in ("impacts", "accumulation_time", "pivot_offsets"):  # a HybridResult's
            if hasattr(result, name):
                object.__setattr__(run, name, getattr(result, name))
        return run

    def __getitem__(self, column: str):
        """One column by name: 't', 'theta', 'theta_dot', 'energy', 'lambda_rod', ..."""
        columns = self.columns()
        if column not in columns:
            raise KeyError(f"no column {column!r}; columns are {', '.join(columns)}")
        return columns[column]

    def to_pandas(self):
        """A pandas DataFrame with the columns t, <q>, <q>_dot, energy, lambda_*, residual_*,
        power."""
        from ..output.tables import result_frame

        return result_frame(self)

    def save(self, path: str | Path) -> Path:
        """Write the table as CSV or Parquet (by suffix), atomically."""
        from ..output.tables import write_table

        return write_table(self, path, protect=self._inputs())

    def plot(self, path: str | Path | None = None):
        """Coordinates, energy (and multipliers) against time; a matplotlib Figure, also
        written to ``path`` (PNG, SVG or PDF) when given."""
        from ..output.plots import save_figure, time_history_figure

        figure = time_history_figure(self, {c.name: c.unit for c in self.model.coordinates})
        if path is not None:
            save_figure(figure, path, protect=self._inputs())
        return figure

    def animate(self, path: str | Path | None = None, *, fps: int = 20, max_frames: int = 250,
                view: tuple[float, float] | str | None = None, progress=None,
                size: tuple[int, int] | str | None = None):
        """The mechanism moving: a matplotlib animation, also written to ``path`` (.gif, .html
        with a player, or .mp4 with the extra lagrangian[mp4]) when given; ``size`` = (width,
        height) of its frames in pixels (default 400 x 400). Bodies in space are seen from
        ``view`` = (azimuth, elevation) in degrees (default isometric). In a notebook it shows
        itself as a player. ``progress(frame, frames)`` follows the frames' writing."""
        from ..output.animation import check_animation_target, mechanism_animation, save_animation

        if path is not None:
            check_animation_target(path)
        animation = mechanism_animation(self, fps=fps, max_frames=max_frames, view=view,
                                        size=size)
        if path is not None:
            save_animation(animation, path, fps=fps, protect=self._inputs(), progress=progress)
        return animation

    def _repr_png_(self) -> bytes:
        """Jupyter: the time histories (``plot()``) as a PNG image, with no %matplotlib magic."""
        from ..output.plots import figure_png

        return figure_png(self.plot())

    def summary(self) -> dict:
        """JSON-ready summary: final state, steps, wall time, energy drift, largest residual."""
        from ..output.simulation import simulation_summary

        return simulation_summary(self)

    def _inputs(self) -> tuple[Path, ...]:
        source = self.model.source
        return (Path(source),) if source and not source.startswith("example:") else ()

