"""What `System.sweep` returns: the study's xarray Dataset, which also shows its figure in a
notebook (the quantities that vary against the varied names) above xarray's own table.
xarray is imported here, on the sweep path only."""

from __future__ import annotations

import base64
from pathlib import Path

import xarray as xr


class Sweep(xr.Dataset):
    """An xarray Dataset of a study (one dimension per varied name; see System.sweep), with
    ``figure()`` drawing it and a notebook display of that figure (image/png) and the table."""

    __slots__ = ()  # xarray's subclassing rule: a Dataset holds no attributes of its own

    @classmethod
    def of(cls, dataset: xr.Dataset) -> Sweep:
        """The same Dataset (not copied), as a Sweep."""
        dataset.__class__ = cls
        return dataset

    def figure(self, path: str | Path | None = None):
        """The study drawn (output/sweep.py's study_figure): a matplotlib Figure, shown inline
        in a notebook, also written to ``path`` (PNG) when given."""
        from ..output.sweep import study_figure, write_study_plot

        if path is not None:
            write_study_plot(self, path)
        return study_figure(self)

    def _repr_png_(self) -> bytes:
        from ..output.plots import figure_png

        return figure_png(self.figure())

    def _repr_mimebundle_(self, include=None, exclude=None) -> dict:
        """Jupyter: the figure (PNG) and, as HTML, the figure above xarray's table; a part of a
        study that cannot be drawn (a selection without its status) shows the table alone."""
        try:
            png = self._repr_png_()
        except Exception:  # noqa: BLE001 - a display never fails: the table is still shown
            return {"text/plain": repr(self), "text/html": self._repr_html_()}
        image = base64.b64encode(png).decode("ascii")
        return {"text/plain": repr(self), "image/png": png,
                "text/html": f'<img alt="study" src="data:image/png;base64,{image}">'
                             + self._repr_html_()}
