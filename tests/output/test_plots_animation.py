"""Mechanism animations: real frames of the moving mechanism, as GIF and HTML."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from PIL import Image

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.output.animation import _dashpot, _zigzag, animation_frames
from lagrangian.output.geometry import mechanism, spring_end_points

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
    # the shared palette keeps the white background white (not a near-white neighbour)
    assert tuple(first[2, 2]) == tuple(last[2, 2]) == (255, 255, 255)
    # the bobs fall: their centroid moves by several pixels between first and last frame
    assert np.linalg.norm(end - start) > 5


def test_html_animation_has_a_player_and_one_image_per_frame(tmp_path):
    run = lagrangian.load("slider_crank").simulate(0.4, samples=41)
    run.animate(tmp_path / "run.html", fps=10)
    html = (tmp_path / "run.html").read_text()
    assert "<script" in html and "animation" in html.lower()
    assert html.count("frames[") >= 5 == len(animation_frames(run, fps=10))


def test_springs_given_by_length_only_are_drawn_between_guessed_end_points():
    model = lagrangian.load("slider_crank").model  # its spring has `length = "x"`, no ends
    assert model.springs[0].ends is None
    ends = spring_end_points(model, {p.symbol: p.value for p in model.parameters})
    assert list(ends) == ["spring"]
    a, b = ends["spring"]
    assert tuple(a) == (0, 0, 0) and sp.Symbol("x") in sp.sympify(b[0]).free_symbols

    # A length-only spring to a fixed anchor (1, 0.5): the anchor is found by least squares.
    builder = lagrangian.SystemBuilder("anchored")
    x = builder.coordinate("x")
    y = builder.coordinate("y")
    builder.add_particle("mass", 1.0, (x, y))
    builder.add_spring("wall", 10.0, 0.2, length=sp.sqrt((x - 1.0)**2 + (y - 0.5)**2))
    anchored = builder.build().model
    (anchor, point), = spring_end_points(anchored, {}).values()
    assert [float(c) for c in anchor] == pytest.approx([1.0, 0.5, 0.0], abs=1e-9)
    assert tuple(point) == anchored.particles[0].position


def rod_and_hanging_mass():
    """A rod pivoted at the origin; a mass hangs from its tip (a body point) by a spring and is
    tied to the ground point (0, -2) by a second spring and a damper."""
    b = lagrangian.SystemBuilder("Rod and hanging mass")
    th, x, y = b.coordinate("theta", unit="rad"), b.coordinate("x"), b.coordinate("y")
    L = b.parameter("L", 0.8, "m")
    b.set_gravity(9.81, (0, -1))
    b.add_body("rod", 2.0, 2.0 * L**2 / 12, (L / 2 * sp.sin(th), -L / 2 * sp.cos(th)),
               th - sp.pi / 2)
    b.add_particle("mass", 0.5, (x, y))
    b.add_spring("upper", 40.0, 0.3, between=[{"body": "rod", "offset": [L / 2, 0.1]}, "mass"])
    b.add_spring("lower", 25.0, 0.2, between=["mass", (0, -2)])
    b.add_damper("dashpot", 0.7, between=["mass", (0, -2)])
    return b.build()


def test_springs_and_dampers_with_ends_are_drawn_between_their_exact_ends():
    system = rod_and_hanging_mass()
    model = system.model
    geometry = mechanism(model, system.parameters)
    assert geometry.spring_names == ("upper", "lower")
    assert geometry.damper_names == ("dashpot",)
    states = np.array([[0.3, 0.2, -1.2], [-1.1, -0.4, -0.7], [2.5, 0.9, -1.6]])
    rates = np.array([[0.5, -0.1, 0.2], [0.0, 0.3, -0.6], [-1.0, 0.0, 0.4]])
    times = np.array([0.0, 0.5, 1.0])
    frame = geometry.frame(states, rates, times)
    assert frame.springs.shape == (3, 2, 2, 2) and frame.dampers.shape == (3, 1, 2, 2)
    for k, (theta, x, y) in enumerate(states):
        # The rod's tip point at offset (L/2, 0.1) in its frame, whose x axis is along the rod
        # (angle theta - pi/2): L (sin, -cos) + 0.1 (cos, sin).
        L = 0.8
        tip = [L * np.sin(theta) + 0.1 * np.cos(theta), -L * np.cos(theta) + 0.1 * np.sin(theta)]
        assert frame.springs[k, 0] == pytest.approx(np.array([tip, [x, y]]), abs=1e-12)
        assert frame.springs[k, 1] == pytest.approx(np.array([[x, y], [0, -2]]), abs=1e-12)
        assert frame.dampers[k, 0] == pytest.approx(np.array([[x, y], [0, -2]]), abs=1e-12)
        # ... and they are the model's own attachment points evaluated there.
        values = {sp.Symbol("theta"): theta, sp.Symbol("x"): x, sp.Symbol("y"): y,
                  sp.Symbol("L"): L}
        for spring, drawn in zip(model.springs, frame.springs[k], strict=True):
            exact = [[float(sp.sympify(c).xreplace(values)) for c in end.point[:2]]
                     for end in spring.ends]
            assert drawn == pytest.approx(np.array(exact), abs=1e-12)
    # No sampling: the kept ends themselves.
    ends = spring_end_points(model, {})
    assert ends["upper"] == (model.springs[0].ends[0].point, model.springs[0].ends[1].point)


def test_a_damper_is_drawn_as_a_dashpot_not_a_zigzag():
    a, b = np.array([0.0, 0.0]), np.array([0.0, -1.0])
    pot, zig = _dashpot(a, b), _zigzag(a, b)
    assert pot[0] == pytest.approx(a) and pot[-1] == pytest.approx(b)
    assert np.isnan(pot).any() and not np.isnan(zig).any()  # separate pieces: rod, cup, piston
    drawn = pot[~np.isnan(pot).any(axis=1)]
    # The cylinder's walls stand off the line by the same width on both sides.
    assert drawn[:, 0].max() == pytest.approx(-drawn[:, 0].min()) and drawn[:, 0].max() > 0


def test_an_animation_with_springs_and_a_damper_renders(tmp_path):
    system = rod_and_hanging_mass()
    run = system.simulate(0.2, samples=21, initial={"theta": 0.4, "y": -1.2})
    run.animate(tmp_path / "run.gif", fps=10)
    with Image.open(tmp_path / "run.gif") as gif:
        assert gif.n_frames == 3
        pixels = np.asarray(gif.convert("RGB"), dtype=int)
    purple = np.array([148, 103, 189])  # matplotlib tab:purple, the dashpot
    assert (np.sum(np.abs(pixels - purple), axis=-1) < 60).sum() > 10


def test_a_model_without_particles_or_bodies_cannot_be_animated(tmp_path):
    run = lagrangian.load("pendulum").simulate(0.2, samples=5)  # given by T and V only
    with pytest.raises(ModelError, match="nothing to animate"):
        run.animate(tmp_path / "run.gif")
    with pytest.raises(ModelError, match="use a .gif, .html or .mp4 file name"):
        lagrangian.load("double_pendulum").simulate(0.1, samples=3).animate(tmp_path / "x.avi")
    assert not (tmp_path / "run.gif").exists()


def test_writing_a_gif_reports_each_frame_for_a_progress_bar(tmp_path):
    """1 s at 10 frames a second: 11 frames, reported 0..10 of 11, in order."""
    run = lagrangian.load("ladder_pendulum").simulate(1.0, samples=101)
    seen = []
    run.animate(tmp_path / "run.gif", fps=10, progress=lambda frame, frames: seen.append(
        (frame, frames)))
    with Image.open(tmp_path / "run.gif") as gif:
        assert gif.n_frames == 11
    assert seen == [(k, 11) for k in range(11)]


def test_a_long_run_capped_in_frames_still_plays_in_real_time(tmp_path):
    """3 s at 20 frames a second would be 61 frames; capped at 16, the frames are 3/15 s apart
    and the GIF shows each that long; uncapped, each shows 1/fps."""
    run = lagrangian.load("ladder_spring_mass").simulate(3.0, samples=61)
    run.animate(tmp_path / "run.gif", max_frames=16)
    with Image.open(tmp_path / "run.gif") as gif:
        assert gif.n_frames == 16 and gif.info["duration"] == 200
    run.animate(tmp_path / "short.gif", fps=10)
    with Image.open(tmp_path / "short.gif") as gif:
        assert gif.n_frames == 31 and gif.info["duration"] == 100
