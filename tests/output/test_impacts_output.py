"""Impacts shown: the text and JSON of a run's impacts, the cycle's words, the impacts marked
on the time histories and named on the animation's frames (output/impacts.py, output/plots.py,
output/animation.py)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import lagrangian
from lagrangian.output.impacts import cycle_document, cycle_text, impacts_document, impacts_text
from lagrangian.output.plots import time_history_figure


@pytest.fixture(scope="module")
def run():
    return lagrangian.load("bouncing_ball").simulate(2.0, samples=41)


def test_the_text_lists_the_first_impacts(run):
    text = impacts_text(run)
    assert text.startswith(f"  {len(run.impacts)} impacts:")
    assert f"t = {run.impacts[0].time:.12g} s  floor" in text


def test_the_document_is_json(run):
    document = json.loads(json.dumps(impacts_document(run), allow_nan=False))
    assert document["count"] == len(run.impacts) == len(document["list"])
    assert document["accumulation_time"] is None  # 2 s: before the accumulation at 4.06 s


def test_the_time_histories_mark_each_impact(run):
    figure = time_history_figure(run)
    marks = [line for line in figure.axes[0].lines if line.get_linestyle() == ":"]
    assert [line.get_xdata()[0] for line in marks] == pytest.approx(
        [r.time for r in run.impacts])


def test_the_cycle_in_words():
    cycle = lagrangian.load("rimless_wheel").limit_cycle()
    text = cycle_text(cycle, "Rimless wheel")
    assert "a stable limit cycle through 'spoke'" in text and "0.5 (|0.5|)" in text
    document = cycle_document(cycle)
    assert document["multipliers"] == [[pytest.approx(0.5, abs=1e-8), 0.0]]


def test_the_animation_names_each_impact_on_the_frames_after_it(run):
    from lagrangian.output.animation import IMPACT_SHOWN_S, mechanism_animation

    animation = mechanism_animation(run, fps=20)
    label, times = animation.impact_label, animation.times
    for record in run.impacts:
        k = int(np.searchsorted(times, record.time))  # the first frame at or after it
        animation.draw(k)
        assert label.get_text() == "impact: floor"
        later = int(np.searchsorted(times, record.time + IMPACT_SHOWN_S + 0.06))
        if later < len(times) and all(not record.time < r.time <= times[later]
                                      for r in run.impacts):
            animation.draw(later)
            assert label.get_text() == ""
    animation.draw(0)  # falling from 1 m: the floor first struck at sqrt(2/g) = 0.45 s
    assert label.get_text() == ""
    before = lagrangian.load("bouncing_ball").simulate(0.3, samples=5)  # no impact yet
    assert mechanism_animation(before, fps=10).impact_label is None
