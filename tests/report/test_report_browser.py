"""The report page in a real browser: headless Chromium (Debian's package, installed by
.ci/install-chromium where missing) opens it, and the test measures what it drew: the math laid
out as math (a fraction's numerator above its denominator, a dot above its letter) and not
blank in a screenshot, the animations moving between two screenshots, no console error, and
nothing asked of any network. Driven over the DevTools protocol on a pipe (tests/headless_chromium.py):
the standard library only. Skipped, with the reason, only where Chromium cannot be had.
"""

from __future__ import annotations

import io
import time
from pathlib import Path

import pytest

import lagrangian
from headless_chromium import Browser, find_chromium
from report_models import HOSTILE_MODEL

CHROMIUM = find_chromium()
pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="Chromium is not installed and .ci/install-chromium could not "
    "install it here (needs apt-get as root and Debian's package lists)")


def _image(png: bytes):
    from PIL import Image

    return Image.open(io.BytesIO(png)).convert("RGB")


def _ink(png: bytes) -> float:
    """The fraction of pixels that are not (near) white."""
    import numpy as np

    pixels = np.asarray(_image(png), dtype=int)
    return float(np.mean(pixels.min(axis=2) < 200))


def _difference(a: bytes, b: bytes) -> float:
    import numpy as np

    first, second = np.asarray(_image(a), dtype=int), np.asarray(_image(b), dtype=int)
    assert first.shape == second.shape
    return float(np.mean(np.any(first != second, axis=2)))


@pytest.fixture(scope="module")
def browser():
    with Browser(CHROMIUM) as opened:
        yield opened


@pytest.fixture(scope="module")
def page(browser, tmp_path_factory):
    path = tmp_path_factory.mktemp("report") / "double_pendulum.html"
    lagrangian.load("double_pendulum").report(t_end=4).save(path)
    browser.open(path)
    browser.settle(1.0)
    return browser


_LAYOUT = """(() => {
  const box = e => { const r = e.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; };
  const maths = Array.from(document.querySelectorAll('math'));
  const fractions = Array.from(document.querySelectorAll('mfrac')).map(
      f => [box(f.children[0]), box(f.children[1])]);
  const accents = Array.from(document.querySelectorAll('mover')).map(
      o => [box(o.children[0]), box(o.children[1])]);
  const rows = Array.from(document.querySelectorAll('mtable')).map(t => t.rows ? 0 :
      Array.from(t.children).map(r => box(r)));
  return {maths: maths.map(m => box(m.firstElementChild || m)), fractions, accents, rows,
          scripts: document.scripts.length, title: document.title};
})()"""


def test_the_math_is_laid_out_as_math(page):
    layout = page.evaluate(_LAYOUT)
    assert len(layout["maths"]) >= 8
    for left, top, right, bottom in layout["maths"]:
        assert right - left > 0 and bottom - top > 0
    # MathML rendered: each fraction's numerator sits above its denominator (as plain inline
    # text they would share a line), each dot above its letter.
    assert layout["fractions"]
    for numerator, denominator in layout["fractions"]:
        assert numerator[3] <= denominator[1] + 1
    assert layout["accents"]
    for base, accent in layout["accents"]:
        assert accent[3] <= (base[1] + base[3]) / 2
    # matrix rows stacked: each row below the one before
    for rows in layout["rows"]:
        if rows:
            assert all(b[1] >= a[3] - 1 for a, b in zip(rows, rows[1:], strict=False))


def test_the_equations_are_drawn(page):
    left, top, right, bottom = page.evaluate(
        "(() => { const f = document.querySelector('#equations .formula math');"
        " f.scrollIntoView(); const r = f.getBoundingClientRect();"
        " return [r.left + scrollX, r.top + scrollY, r.right + scrollX, r.bottom + scrollY]; })()")
    shot = page.screenshot({"x": left, "y": top, "width": right - left, "height": bottom - top})
    assert _ink(shot) > 0.02  # glyphs, not a blank box


def test_the_animations_play(page):
    count = page.evaluate("document.querySelectorAll('img.animation').length")
    assert count == 3  # two modes and the simulation
    for k in range(count):
        clip = page.evaluate(
            f"(() => {{ const e = document.querySelectorAll('img.animation')[{k}];"
            " e.scrollIntoView(); const r = e.getBoundingClientRect();"
            " return {x: r.left + scrollX, y: r.top + scrollY, width: r.width,"
            " height: r.height}; })()")
        assert clip["width"] > 100 and clip["height"] > 100
        page.settle(0.3)
        shots = []
        for _ in range(3):  # a still image gives the same pixels every time
            shots.append(page.screenshot(clip))
            time.sleep(0.45)
        assert _ink(shots[0]) > 0.01
        moved = max(_difference(a, b) for a, b in zip(shots, shots[1:], strict=False))
        assert moved > 0.001, f"animation {k} did not move"


def test_no_console_errors_and_nothing_from_the_network(page, tmp_path):
    assert page.console_errors() == []
    requests = page.requests()
    assert requests and all(url.startswith(("file://", "data:")) for url in requests), \
        [u[:80] for u in requests if not u.startswith(("file://", "data:"))]
    shot = page.screenshot()
    (tmp_path / "viewport.png").write_bytes(shot)
    assert _ink(shot) > 0.01


def test_a_hostile_model_runs_no_script(browser, tmp_path):
    model = tmp_path / "hostile.toml"
    model.write_text(HOSTILE_MODEL, encoding="utf-8")
    path = tmp_path / "hostile.html"
    lagrangian.load(model).report(t_end=0.5).save(path)
    before = len(browser.events)
    browser.open(path)
    browser.settle(0.5)
    layout = browser.evaluate(_LAYOUT)
    assert layout["scripts"] == 0
    assert layout["title"].startswith('<script>alert("name")</script></math>')
    heading = browser.evaluate("document.querySelector('h1').textContent")
    assert heading.startswith("<script>")  # shown as text
    assert browser.evaluate("document.querySelectorAll('img[src=\"x\"]').length") == 0
    assert browser.console_errors(since=before) == []
    assert Path(path).read_text(encoding="utf-8").count("<script") == 0


def test_the_checks_see_what_they_look_for(browser, tmp_path):
    """A page that logs an error and asks the network for an image is caught by both checks."""
    path = tmp_path / "noisy.html"
    path.write_text('<!DOCTYPE html><img src="http://lagrangian.invalid/x.png">'
                    '<script>console.error("boom")</script>', encoding="utf-8")
    before, asked = len(browser.events), len(browser.requests())
    browser.open(path)
    browser.settle(0.5)
    assert any("boom" in line for line in browser.console_errors(since=before))
    assert any(url.startswith("http://") for url in browser.requests()[asked:])
