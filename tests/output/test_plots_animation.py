"""Mechanism animations: real frames of the moving mechanism, as GIF and HTML."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from PIL import Image

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.output.animation import animation_frames, spring_end_points

RED = np.array([214, 39, 40])  # matplotlib tab:red, the particles


def red_centroid(frame: Image.Image) -> np.ndarray:
    pixels = np.asarray(frame.convert("RGB"), dtype=int)
    mask = np.sum(np.abs(pixels - RED), axis=-1) < 60
    assert mask.sum() > 20, "no particle drawn"
    rows, cols = np.nonzero(mask)
    return np.array([rows.mean(), cols.mean()])


def test_gif_holds_distinct_frames_of_the_moving_mechanism(tmp_path):
    run = lagrangian.load("double_pendulum").simulate(1.0, samples=201)
    run.animate(tmp_path / "run.gif", fps=10)
    with Image.open(tmp_path / "run.gif") as gif:
        assert gif.n_frames == 11  # 1 s at 10 frames a second, both ends included
        gif.seek(0)
        first = np.asarray(gif.convert("RGB")).copy()
        start = red_centroid(gif)
        gif.seek(gif.n_frames - 1)
        last = np.asarray(gif.convert("RGB")).copy()
        end = red_centroid(gif)
    assert np.mean(np.any(first != last, axis=-1)) > 0.002
    # the bobs fall: their centroid moves by several pixels between first and last frame
    assert np.linalg.norm(end - start) > 5


def test_html_animation_has_a_player_and_one_image_per_frame(tmp_path):
    run = lagrangian.load("slider_crank").simulate(0.4, samples=41)
    run.animate(tmp_path / "run.html", fps=10)
    html = (tmp_path / "run.html").read_text()
    assert "<script" in html and "animation" in html.lower()
    assert html.count("frames[") >= 5 == len(animation_frames(run.result, fps=10))


def test_springs_are_drawn_between_recovered_end_points():
    model = lagrangian.load("slider_crank").model
    ends = spring_end_points(model, {p.symbol: p.value for p in model.parameters})
    assert list(ends) == ["spring"]
    a, b = ends["spring"]
    assert tuple(a) == (0, 0, 0) and sp.Symbol("x") in sp.sympify(b[0]).free_symbols

    builder = lagrangian.SystemBuilder("anchored")
    x = builder.coordinate("x")
    y = builder.coordinate("y")
    builder.add_particle("mass", 1.0, (x, y))
    builder.add_spring("wall", 10.0, 0.2, between=((1.0, 0.5), "mass"))
    anchored = builder.build().model
    (anchor, point), = spring_end_points(anchored, {}).values()
    assert [float(c) for c in anchor] == pytest.approx([1.0, 0.5, 0.0], abs=1e-9)
    assert tuple(point) == anchored.particles[0].position


def test_a_model_without_particles_or_bodies_cannot_be_animated(tmp_path):
    run = lagrangian.load("pendulum").simulate(0.2, samples=5)  # given by T and V only
    with pytest.raises(ModelError, match="nothing to animate"):
        run.animate(tmp_path / "run.gif")
    with pytest.raises(ModelError, match="use a .gif or .html file name"):
        lagrangian.load("double_pendulum").simulate(0.1, samples=3).animate(tmp_path / "x.mp4")
    assert not (tmp_path / "run.gif").exists()
