"""Make docs/images/report.png, the README's picture of the report page, the way the browser test
sees it: the double pendulum's page in headless Chromium, its equations and its modes moving.

    PYTHONPATH=src python tests/make_report_screenshot.py
"""

from __future__ import annotations

import io
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import lagrangian  # noqa: E402
from headless_chromium import Browser, find_chromium  # noqa: E402

TARGET = Path(__file__).resolve().parents[1] / "docs" / "images" / "report.png"
WIDTH = 1000


def _clip(browser: Browser, start: str, end: str) -> dict:
    """The page's region from the top of ``start`` to the bottom of ``end`` (CSS selectors)."""
    return browser.evaluate(
        f"(() => {{ const a = document.querySelector('{start}').getBoundingClientRect();"
        f" const b = document.querySelector('{end}').getBoundingClientRect();"
        " return {x: 0, y: a.top + scrollY - 8, width: document.documentElement.clientWidth,"
        " height: b.bottom - a.top + 6}; })()")


def main() -> None:
    from PIL import Image

    chromium = find_chromium()
    if chromium is None:
        raise SystemExit("chromium is not installed (run .ci/install-chromium)")
    with tempfile.TemporaryDirectory() as folder:
        page = Path(folder) / "double_pendulum.html"
        lagrangian.load("double_pendulum").report(t_end=10).save(page)
        with Browser(chromium, width=WIDTH, height=900) as browser:
            browser.open(page)
            browser.settle(1.0)
            parts = []
            for start, end in (("#energy h2", "#equations .formula:nth-of-type(2)"),
                               ("#modes .gallery", "#modes .gallery")):
                browser.evaluate(f"document.querySelector('{start}').scrollIntoView()")
                time.sleep(0.5)  # the modes caught mid-swing, not at their first frame
                parts.append(Image.open(io.BytesIO(browser.screenshot(
                    _clip(browser, start, end)))).convert("RGB"))
    height = sum(p.height for p in parts) + 2 * (len(parts) - 1)
    picture = Image.new("RGB", (max(p.width for p in parts), height), (200, 200, 200))
    top = 0
    for part in parts:
        picture.paste(part, (0, top))
        top += part.height + 2
    picture = picture.quantize(colors=128, method=Image.Quantize.MEDIANCUT)
    picture.save(TARGET, optimize=True)
    print(f"wrote {TARGET} ({picture.width}x{picture.height})")


if __name__ == "__main__":
    main()
