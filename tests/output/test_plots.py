"""Time-history plots and result tables written from a simulation."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import ModelError


@pytest.fixture(scope="module")
def slider():
    return lagrangian.load("slider_crank").simulate(0.5, samples=101)


def test_plot_is_a_png_with_one_panel_per_unit_energy_and_multipliers(slider, tmp_path):
    figure = slider.plot(tmp_path / "run.png")
    data = (tmp_path / "run.png").read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
    labels = [ax.get_ylabel() for ax in figure.axes]
    assert labels == ["coordinate (rad)", "coordinate (m)", "E - E0 (J)", "multiplier"]
    # the plotted lines are the simulated coordinates
    theta_line = figure.axes[0].get_lines()[0]
    np.testing.assert_array_equal(theta_line.get_ydata(), slider["theta"])


def test_plot_of_a_dissipative_run_shows_the_energy_itself(tmp_path):
    run = lagrangian.load("damped_oscillator").simulate(2, samples=51)
    figure = run.plot()
    assert figure.axes[1].get_ylabel() == "energy T + V (J)"
    np.testing.assert_array_equal(figure.axes[1].get_lines()[0].get_ydata(), run["energy"])


def test_plot_rejects_an_unknown_format(slider, tmp_path):
    with pytest.raises(ModelError, match="use a .png, .svg or .pdf file name"):
        slider.plot(tmp_path / "run.bmp")
    assert not (tmp_path / "run.bmp").exists()


def test_csv_has_the_documented_columns_and_full_precision(slider, tmp_path):
    slider.save(tmp_path / "run.csv")
    lines = (tmp_path / "run.csv").read_text().splitlines()
    assert lines[0] == ("t,theta,phi,x,theta_dot,phi_dot,x_dot,energy,lambda_loop_y,"
                        "lambda_loop_x,residual_loop_y,residual_loop_x,power")
    assert len(lines) == 1 + len(slider.t)
    row = [float(v) for v in lines[-1].split(",")]
    assert row[1] == slider.q[-1, 0]  # repr round-trips the double exactly


def test_parquet_round_trips_through_pandas(slider, tmp_path):
    import pandas as pd

    slider.save(tmp_path / "run.parquet")
    frame = pd.read_parquet(tmp_path / "run.parquet")
    pd.testing.assert_frame_equal(frame, slider.to_pandas())
    assert list(frame.columns)[:4] == ["t", "theta", "phi", "x"]


def test_outputs_never_overwrite_the_model_file(tmp_path):
    """A model file that happens to be named like an output is still an input: refused."""
    source = Path(lagrangian.model.examples.example_path("pendulum")).read_text()
    model = tmp_path / "pendulum.csv"
    model.write_text(source)
    run = lagrangian.load(model).simulate(0.1, samples=3)
    with pytest.raises(FileExistsError, match="refusing to overwrite an input file"):
        run.save(model)
    png = tmp_path / "pendulum.png"
    png.write_text(source)
    run_png = lagrangian.load(png).simulate(0.1, samples=3)
    with pytest.raises(FileExistsError, match="refusing to overwrite an input file"):
        run_png.plot(png)
    assert model.read_text() == source and png.read_text() == source
    with pytest.raises(ModelError, match="use a .csv or .parquet file name"):
        run.save(tmp_path / "run.xlsx")


@pytest.mark.parametrize("name", ["slider_crank", "double_pendulum"])
def test_legends_sit_outside_the_panels_and_hide_no_curve(name, tmp_path):
    run = lagrangian.load(name).simulate(0.5, samples=51)
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    figure = run.plot(tmp_path / "run.png")
    canvas = FigureCanvasAgg(figure)
    canvas.draw()  # the layout is final
    renderer = canvas.get_renderer()
    legends = [ax.get_legend() for ax in figure.axes if ax.get_legend() is not None]
    assert legends
    for legend in legends:
        box = legend.get_window_extent(renderer)
        assert box.width > 0 and box.x1 <= figure.bbox.x1 + 1  # on the page
        for ax in figure.axes:  # over no panel's plotting area
            assert not box.overlaps(ax.get_window_extent(renderer))
