"""What `System.modes` returns: the ModalAnalysis with the model it came from, so it can draw
its mode shapes (``plot``), animate the mechanism in a mode (``animate``) and show both in a
notebook on its own (``_repr_mimebundle_``: the table as LaTeX, the shapes as PNG)."""

from __future__ import annotations

import base64
import html
from dataclasses import dataclass, fields
from pathlib import Path

from ..analysis import modes as analysis_modes
from ..model.model import Model


@dataclass(frozen=True, repr=False)
class ModalAnalysis(analysis_modes.ModalAnalysis):
    """The modes of a linear model, in ascending frequency (numbered from 1 as printed), with
    the model they came from: ``plot()`` draws the shapes, ``animate(mode=k)`` the mechanism
    oscillating in mode k (all, side by side, without k)."""

    model: Model | None = None

    @classmethod
    def of(cls, analysis: analysis_modes.ModalAnalysis, model: Model) -> ModalAnalysis:
        """The same analysis (not copied) with its model."""
        names = [f.name for f in fields(analysis_modes.ModalAnalysis)]
        return cls(**{name: getattr(analysis, name) for name in names}, model=model)

    def plot(self, path: str | Path | None = None):
        """One panel per mode (the lowest twelve): its shape per coordinate; a matplotlib
        Figure (shown inline in a notebook), also written to ``path`` (PNG) when given."""
        from ..output.modes import mode_shape_figure, write_mode_plot

        if path is not None:
            write_mode_plot(self, path, protect=self._inputs())
        return mode_shape_figure(self)

    def animate(self, path: str | Path | None = None, *, mode: int | None = None, fps: int = 20,
                size: tuple[int, int] | str | None = None,
                view: tuple[float, float] | str | None = None):
        """The mechanism oscillating in mode ``mode`` (1 is the lowest, as printed), or the lowest
        six side by side: one period every 2 s at ``fps`` frames a second, ``size`` = (width,
        height) in pixels; written to ``path`` (.gif, .html player or .mp4) when given. In a
        notebook the animation shows itself as a player."""
        from ..errors import ModelError
        from ..output.media import check_animation_target, save_animation
        from ..output.mode_animation import mode_animation

        if self.model is None:
            raise ModelError("this analysis has no model to draw (use System.modes())",
                             field="animation")
        if path is not None:
            check_animation_target(path)
        animation = mode_animation(self, self.model, mode=mode, fps=fps, size=size, view=view)
        if path is not None:
            save_animation(animation, path, fps=fps, protect=self._inputs())
        return animation

    def _repr_png_(self) -> bytes | None:
        """Jupyter: the mode shapes as a PNG image."""
        from ..output.plots import figure_png

        return figure_png(self.plot()) if self.modes else None

    def _repr_mimebundle_(self, include=None, exclude=None) -> dict:
        """Jupyter: the table (LaTeX, rendered by MathJax), the mode shapes (PNG) and both in
        one piece of HTML, so whichever the front end prefers shows the figure."""
        bundle = {"text/plain": repr(self), "text/latex": self._repr_latex_()}
        png = self._repr_png_()
        if png is not None:
            bundle["image/png"] = png
            image = base64.b64encode(png).decode("ascii")
            bundle["text/html"] = (f"<div>{html.escape(self._repr_latex_(), quote=False)}</div>"
                                   f'<img alt="{html.escape(self.model_name, quote=True)} mode '
                                   f'shapes" src="data:image/png;base64,{image}">')
        return bundle

    def _inputs(self) -> tuple[Path, ...]:
        source = self.model.source if self.model is not None else None
        return (Path(source),) if source and not source.startswith("example:") else ()
