"""Notebooks show themselves (issue 22): docs/notebooks/pendulum.ipynb run in a real Jupyter
kernel (nbconvert's ExecutePreprocessor), with no %matplotlib magic, holds in its output cells
the system as math (text/latex), the run and the modes as figures (image/png), and the
animations as a self-contained player (text/html)."""

from __future__ import annotations

import base64
import io
import os
from pathlib import Path

import pytest

import lagrangian

NOTEBOOK = Path(__file__).resolve().parents[2] / "docs" / "notebooks" / "pendulum.ipynb"


@pytest.fixture(scope="module")
def executed():
    nbformat = pytest.importorskip("nbformat")
    preprocessors = pytest.importorskip("nbconvert.preprocessors")
    pytest.importorskip("ipykernel")
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    assert not any("%matplotlib" in cell.source for cell in notebook.cells
                   if cell.cell_type == "code")
    # The kernel imports this checkout's lagrangian (the one under test), installed or not.
    source = str(Path(lagrangian.__file__).resolve().parents[1])
    old = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [source, old]))
    try:
        runner = preprocessors.ExecutePreprocessor(timeout=300, kernel_name="python3")
        runner.preprocess(notebook, {"metadata": {"path": str(NOTEBOOK.parent)}})
    finally:
        if old is None:
            os.environ.pop("PYTHONPATH")
        else:
            os.environ["PYTHONPATH"] = old
    return [cell for cell in notebook.cells if cell.cell_type == "code"]


def _result(cell) -> dict:
    """The data of the cell's last-line result (its execute_result output)."""
    results = [o for o in cell.outputs if o.output_type == "execute_result"]
    errors = [o for o in cell.outputs if o.output_type == "error"]
    assert not errors, errors
    assert len(results) == 1, cell.outputs
    return results[0]["data"]


def _png(data: dict):
    from PIL import Image

    image = Image.open(io.BytesIO(base64.b64decode(data["image/png"])))
    assert image.size[0] >= 300 and image.size[1] >= 200
    colours = image.convert("RGB").getcolors(maxcolors=1 << 16)
    assert colours is None or len(colours) > 20  # a drawing, not a blank image
    return image


def test_the_system_renders_as_math(executed):
    latex = _result(executed[0])["text/latex"]
    assert latex.startswith("$") and r"\theta" in latex and r"\cos" in latex


def test_a_run_shows_its_figure_not_its_repr(executed):
    data = _result(executed[1])
    _png(data)
    assert "<Figure size" not in data.get("text/plain", "")


def test_animations_show_as_a_player(executed):
    for cell in (executed[2], executed[4]):
        page = _result(cell)["text/html"]
        assert page.startswith('<div class="lagrangian-animation"')
        assert page.count("data:image/png;base64,") >= 10 and "<script" in page
        assert "http://" not in page and "https://" not in page  # offline: nothing fetched


def test_modes_show_the_table_as_math_and_the_shapes_as_a_figure(executed):
    data = _result(executed[3])
    _png(data)
    assert r"\omega" in data["text/latex"] and "4.429" in data["text/latex"]  # sqrt(g/L)
    assert "data:image/png;base64," in data["text/html"]


def test_one_equation_and_the_lagrangian_show_their_rates_dotted(executed):
    equation = _result(executed[5])["text/latex"]
    assert r"\ddot{\theta}" in equation and "_{dot}" not in equation and "_{ddot}" not in equation
    lagrangian_ = _result(executed[6])["text/latex"]
    assert r"\dot{\theta}^{2}" in lagrangian_ and "_{dot}" not in lagrangian_
