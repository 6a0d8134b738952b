"""The documentation site (issue 22): `mkdocs build --strict` builds docs/ with no broken link,
anchor or reference; the README is a front page; the gallery is what `lagrangian examples`
lists; every relative link of the README and the docs reaches a file (checked here without
mkdocs too, so a checkout without the docs extra still catches a dead link)."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from make_gallery import PICTURES, examples, gallery_markdown

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = ROOT / "docs"
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")


def _missing(*modules: str) -> list[str]:
    def absent(module: str) -> bool:
        try:
            return importlib.util.find_spec(module) is None
        except ModuleNotFoundError:   # its parent package is not there either
            return True

    return [m for m in modules if absent(m)]


def test_the_site_builds_in_strict_mode(tmp_path):
    missing = _missing("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers.python")
    if missing:
        pytest.skip(f"the docs site needs {', '.join(missing)}: pip install \".[docs]\"")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    run = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir",
                          str(tmp_path / "site")], cwd=ROOT, env=env, capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    site = tmp_path / "site"
    home = (site / "index.html").read_text(encoding="utf-8")
    shown = re.sub(r"<[^>]+>", "", home)                                  # highlighted code
    assert "pip install . &amp;&amp; lagrangian derive pendulum" in shown  # the README is home
    assert 'href="getting-started/students-and-teachers/"' in home          # links rewritten
    api = (site / "api" / "index.html").read_text(encoding="utf-8")
    assert "equations_of_motion" in api and "SystemBuilder" in api         # from docstrings
    for page in ("getting-started/engineers", "getting-started/robotics",
                 "getting-started/studies", "model-file", "gallery", "analysis", "dependencies"):
        assert (site / page / "index.html").is_file(), page


def test_the_configuration_fails_on_broken_links_and_pages_left_out_of_the_nav():
    text = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    assert re.search(r"^strict: true$", text, re.M)
    for check in ("not_found", "anchors", "omitted_files", "unrecognized_links"):
        assert re.search(rf"^    {check}: warn$", text, re.M), check


def _relative_links(page: Path) -> list[str]:
    text = re.sub(r"```.*?```", "", page.read_text(encoding="utf-8"), flags=re.S)
    return [target for target in LINK.findall(text)
            if not re.match(r"[a-z]+:", target) and not target.startswith("#")]


@pytest.mark.parametrize("page", [README, *sorted(DOCS.rglob("*.md"))],
                         ids=lambda page: str(page.relative_to(ROOT)))
def test_every_relative_link_reaches_a_file(page):
    for target in _relative_links(page):
        path = (page.parent / target.split("#")[0]).resolve()
        assert path.exists(), f"{page.relative_to(ROOT)} links to {target}, which is not there"
        if page != README:   # the site's pages may link only inside docs/
            assert DOCS in path.parents, f"{page.relative_to(ROOT)} links outside docs/: {target}"


def test_the_readme_is_a_front_page():
    text = README.read_text(encoding="utf-8")
    assert len(text.encode()) < 15_000
    # .ci/run and the Quick start are the same two commands.
    command = 'pip install ".[test]" && python -m pytest -q -n auto'
    assert f"pip install . && lagrangian derive pendulum\n{command}\n" in text
    ci = (ROOT / ".ci/run").read_text(encoding="utf-8")
    assert 'python3 -m pip install -q ".[test]" && python3 -m pytest -q -n auto' in ci
    assert len(re.findall(r"!\[", text)) == 1 and "docs/images/report.png" in text
    assert "## Contents" in text
    # The students' entry point is above the Quick start.
    assert text.index("docs/getting-started/students-and-teachers.md") < text.index("## Quick start")
    linked = {target.split("#")[0] for target in _relative_links(README)}
    for page in ("students-and-teachers", "engineers", "robotics", "studies"):
        assert f"docs/getting-started/{page}.md" in linked
    assert {"docs/model-file.md", "docs/api.md", "docs/gallery.md"} <= linked


def test_the_gallery_lists_every_example_with_its_drawing():
    listed = examples()
    pictures = {path.name for path in PICTURES.glob("*.png")}
    assert (DOCS / "gallery.md").read_text(encoding="utf-8") == gallery_markdown(listed, pictures), (
        "docs/gallery.md is stale: run PYTHONPATH=src python tests/make_gallery.py")
    names = {example["name"] for example in listed}
    assert {name.removesuffix(".png") for name in pictures} <= names   # no picture of a lost one
    # A model made of particles or bodies is drawn; one given by its energies alone is not.
    assert {"double_pendulum.png", "slider_crank.png", "whipple_bicycle.png"} <= pictures
    assert "pendulum.png" not in pictures and "two_mass.png" not in pictures
