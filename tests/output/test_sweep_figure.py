"""Sweep figures show what changed (issue 22): the quantities that vary each in a panel, the
model and the varied parameter in the title, and a quantity that does not vary drawn flat
rather than magnified to round-off on an offset axis ('1e-12 + 4.429446918')."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
from PIL import Image

import lagrangian
from lagrangian.output.sweep import study_figure


def _panels(figure) -> dict[str, object]:
    figure.canvas.draw()  # the offset text is decided when the ticks are drawn
    return {ax.get_ylabel(): ax for ax in figure.axes if ax.get_ylabel()}


def test_damping_sweep_draws_zeta_and_decay_beside_a_flat_frequency(client):
    """Damped oscillator (m = 1 kg, k = 4 N/m): omega_n = 2 rad/s whatever c, zeta = c/(2
    sqrt(k m)) = c/4 and growth rate -zeta omega_n = -c/2 (1/s)."""
    c = np.array([0.1, 0.4, 1.0, 2.0, 3.0])
    study = lagrangian.load("damped_oscillator").sweep({"c": c}, client=client)
    figure = study_figure(study)
    panels = _panels(figure)
    assert set(panels) == {"natural frequency (rad/s)", "damping ratio ζ", "growth rate (1/s)"}
    zeta = panels["damping ratio ζ"].lines[0]
    assert np.allclose(zeta.get_xdata(), c) and np.allclose(zeta.get_ydata(), c / 4, rtol=1e-9)
    growth = panels["growth rate (1/s)"].lines[0]
    assert np.allclose(growth.get_ydata(), -c / 2, rtol=1e-9)
    frequency = panels["natural frequency (rad/s)"]
    assert frequency.yaxis.get_offset_text().get_text() == ""
    assert frequency.get_ylim() == pytest.approx((1.9, 2.1))
    title = figure._suptitle.get_text()
    assert "Damped oscillator" in title and "against c" in title


def test_a_frequency_flat_to_round_off_has_no_offset_axis(client):
    """The pendulum's omega = sqrt(g/L) = 4.4294 rad/s does not depend on m: the frequencies
    of a sweep over m agree to round-off, and are drawn flat at that value."""
    study = lagrangian.load("pendulum").sweep({"m": [0.5, 1.0, 2.0, 4.0, 8.0]}, client=client)
    panels = _panels(study_figure(study))
    assert list(panels) == ["natural frequency (rad/s)"]  # undamped: nothing else varies
    ax = panels["natural frequency (rad/s)"]
    assert ax.yaxis.get_offset_text().get_text() == ""
    omega = math.sqrt(9.81 / 0.5)  # L = 0.5 m
    low, high = ax.get_ylim()
    assert low == pytest.approx(0.95 * omega) and high == pytest.approx(1.05 * omega)
    assert all("e-" not in t.get_text() for t in ax.get_yticklabels())


def test_a_sweep_shows_its_figure_in_a_notebook(client):
    study = lagrangian.load("two_mass").sweep({"k": [1.0, 4.0]}, client=client)
    bundle = study._repr_mimebundle_()
    with Image.open(io.BytesIO(bundle["image/png"])) as image:
        assert image.size[0] > 400
    assert bundle["text/html"].startswith('<img alt="study" src="data:image/png;base64,')
    assert "xr-wrap" in bundle["text/html"] or "xarray" in bundle["text/html"]
    # still an xarray Dataset: selections and xarray's own plotting keep working
    assert float(study["frequency"].sel(k=4.0, mode=1)) == pytest.approx(2.0)
    assert "text/html" in study.isel(k=0)._repr_mimebundle_()


def test_round_off_alone_is_not_magnified():
    """Values 4.429446918 apart by 1e-12 (a frequency that does not depend on the varied
    parameter, computed at each point): matplotlib alone draws them on a '1e-12 + 4.429446918'
    axis; flat_axis draws them flat at their value."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from lagrangian.output.sweep import flat_axis, varies

    values = 4.429446918 + 1e-12 * np.array([0.0, 1.0, 3.0, 2.0])
    assert not varies(values) and varies(np.array([1.0, 1.0 + 1e-6]))
    texts = []
    for flatten in (False, True):
        figure = Figure()
        FigureCanvasAgg(figure)
        ax = figure.add_subplot()
        ax.plot([1, 2, 3, 4], values)
        if flatten:
            flat_axis(ax, values)
        figure.canvas.draw()
        texts.append(ax.yaxis.get_offset_text().get_text())
    assert texts[0] != "" and texts[1] == ""
    assert ax.get_ylim() == pytest.approx((0.95 * 4.429446918, 1.05 * 4.429446918))
