"""The report page: what each section shows (checked against closed forms), the sections that do
not apply saying so in one line, user text escaped by construction, nothing loaded from elsewhere,
and the file written only where we may."""

from __future__ import annotations

import importlib.util
import math
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.report.html import CONTENT_POLICY, FIRST_LINE
from report_models import HOSTILE_MODEL, HOSTILE_NAME


class Page(HTMLParser):
    """Every element (tag, attributes) and the text of each section."""

    def __init__(self, html: str):
        super().__init__(convert_charrefs=True)
        self.elements: list[tuple[str, dict]] = []
        self.text: dict[str, list[str]] = {}
        self._section = None
        self.feed(html)

    def handle_starttag(self, tag, attrs):
        attributes = dict(attrs)
        self.elements.append((tag, attributes))
        if tag == "section":
            self._section = attributes["id"]

    def handle_data(self, data):
        if self._section:
            self.text.setdefault(self._section, []).append(data)

    def section(self, key: str) -> str:
        return " ".join(" ".join(self.text.get(key, [])).split())

    def tags(self, tag: str) -> list[dict]:
        return [a for t, a in self.elements if t == tag]


@pytest.fixture(scope="module")
def double_pendulum():
    report = lagrangian.load("double_pendulum").report(t_end=3)
    return report, Page(report.html)


@pytest.fixture(scope="module")
def hostile(tmp_path_factory):
    path = tmp_path_factory.mktemp("hostile") / "hostile.toml"
    path.write_text(HOSTILE_MODEL, encoding="utf-8")
    report = lagrangian.load(path).report(t_end=1)
    return report, Page(report.html)


def _numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(r"-?\d+\.\d+(?:e[-+]?\d+)?", text)]


def test_double_pendulum_modes_are_the_closed_form(double_pendulum):
    report, page = double_pendulum
    # m = l = 1: omega^2 = g (2 -+ sqrt 2), shapes theta1/theta2 = +-1/sqrt 2
    expected = [math.sqrt(9.81 * (2 - math.sqrt(2))), math.sqrt(9.81 * (2 + math.sqrt(2)))]
    shown = _numbers(page.section("modes"))
    for omega in expected:
        assert any(abs(x - omega) < 1e-4 * omega for x in shown), (omega, shown[:12])
    assert any(abs(x + 1 / math.sqrt(2)) < 1e-3 for x in shown)
    statuses = {s.key: s.status for s in report.sections}
    assert statuses["modes"] == statuses["equations"] == statuses["simulation"] == "shown"


def test_each_mode_and_the_simulation_are_animated_gifs(double_pendulum):
    _, page = double_pendulum
    animations = [a for a in page.tags("img") if a.get("class") == "animation"]
    assert len(animations) == 3  # two modes and the simulation
    from base64 import b64decode
    from io import BytesIO

    from PIL import Image

    for attributes in animations:
        assert attributes["src"].startswith("data:image/gif;base64,")
        gif = Image.open(BytesIO(b64decode(attributes["src"].split(",", 1)[1])))
        assert gif.n_frames > 10 and gif.info.get("loop") == 0


def test_equilibria_of_the_double_pendulum(double_pendulum):
    _, page = double_pendulum
    text = page.section("equilibria")
    assert text.count("unstable") == 3 and text.count("stable") == 4  # hanging down only


def test_equations_are_mathml_with_dotted_rates(double_pendulum):
    report, page = double_pendulum
    maths = page.tags("math")
    assert len(maths) >= 8 and all(not a or a == {"display": "block"} for a in maths)
    equations = report.html[report.html.index('id="equations"'):report.html.index('id="equilibria"')]
    assert "\u00a8" in equations and "<mover" in equations  # theta double dot
    assert "_dot" not in equations and "_ddot" not in equations


def test_the_page_loads_nothing_from_elsewhere(double_pendulum):
    report, page = double_pendulum
    assert report.html.startswith(FIRST_LINE + "\n<!DOCTYPE html>")
    policy = [a for a in page.tags("meta") if a.get("http-equiv") == "Content-Security-Policy"]
    assert policy and policy[0]["content"] == CONTENT_POLICY
    assert not page.tags("script") and not page.tags("link")
    for tag, attributes in page.elements:
        for name in ("src", "href"):
            value = attributes.get(name)
            if value is not None:
                assert value.startswith(("data:", "#")), (tag, value[:60])
    assert "http://" not in report.html and "https://" not in report.html


def test_hostile_user_text_is_escaped_everywhere(hostile):
    report, page = hostile
    assert not page.tags("script")
    assert [a for a in page.tags("img") if a.get("src") == "x"] == []
    assert HOSTILE_NAME not in report.html
    assert "&lt;script&gt;alert(&quot;name&quot;)" in report.html
    assert "alert(&quot;file&quot;)" in report.html  # the file's text, shown as text
    heading = report.html[report.html.index("<h1>"):report.html.index("</h1>")]
    assert "&lt;/math&gt;" in heading
    # the load's name as text in its heading, never as markup
    assert "Load &lt;script&gt;push&lt;/script&gt;" in report.html
    iframe = report._repr_html_()
    assert iframe.count("<") == 2 and "&lt;script&gt;" in iframe  # only <iframe ...></iframe>


def test_sections_that_do_not_apply_say_so_in_one_line():
    statuses = {}
    models = [("pendulum", 1), ("atwood", 0.5), ("two_mass", 1)]
    if importlib.util.find_spec("yourdfpy") is not None:  # URDF support may be an extra
        models.append(("two_link_arm", 0.5))
    for name, t_end in models:
        report = lagrangian.load(name).report(t_end=t_end)
        statuses[name] = {s.key: s.status for s in report.sections}
        page = Page(report.html)
        for section in report.sections:
            if section.status != "shown":
                notes = re.findall(r'<p class="note">', report.html.split(
                    f'id="{section.key}"')[1].split("</section>")[0])
                assert len(notes) == 1, (name, section.key)
        if name == "two_mass":  # given by its energies: each mode's coordinates on tracks
            assert "given by its energies only" in page.section("modes")
            gifs = [a for a in page.tags("img") if a.get("class") == "animation"]
            assert len(gifs) == 2 and "Nothing to draw" in page.section("model")
    assert statuses["pendulum"]["forces"] == "not applicable: no loads"
    assert statuses["pendulum"]["check"] == "not applicable: no answer"
    assert statuses["atwood"]["equilibria"] == "not applicable: none found"
    assert statuses["atwood"]["modes"].startswith("not available: no equilibrium")
    if "two_link_arm" in statuses:
        assert statuses["two_link_arm"]["equations"] == "not applicable: URDF"
        assert statuses["two_link_arm"]["simulation"] == "shown"


def test_the_forces_section_gives_each_load_its_virtual_work(hostile):
    _, page = hostile
    text = page.section("forces")
    # a horizontal force m g / 10 at the bob: Q_theta = (m g / 10) L cos(theta)
    assert "<script>push</script>" in text and "cos" in text


def test_the_check_of_a_hand_derivation_is_shown():
    answer = Path(__file__).resolve().parents[1] / "check" / "answers" / \
        "pendulum_wrong_potential.toml"
    report = lagrangian.load("pendulum").report(answer=answer, t_end=0.5)
    text = Page(report.html).section("check")
    assert "incorrect" in text and "wrong" in text
    assert {s.key: s.status for s in report.sections}["check"] == "shown"


def test_bad_input_is_refused_before_any_work(tmp_path):
    pendulum = lagrangian.load("pendulum")
    with pytest.raises(ModelError, match="positive number of seconds"):
        pendulum.report(t_end=-1)
    with pytest.raises(ModelError):
        pendulum.report(answer=tmp_path / "missing.toml")
    for bad, field in (({"size": "huge"}, "size"), ({"size": (10, 10)}, "size"),
                       ({"fps": 0}, "fps"), ({"fps": "fast"}, "fps")):
        with pytest.raises(ModelError) as error:
            pendulum.report(**bad)
        assert error.value.field == field


def test_save_writes_atomically_and_only_where_we_may(double_pendulum, tmp_path):
    report, _ = double_pendulum
    target = tmp_path / "report.html"
    report.save(target)
    assert target.read_text(encoding="utf-8") == report.html
    report.save(target)  # our own page may be replaced
    foreign = tmp_path / "notes.html"
    foreign.write_text("<p>my notes</p>")
    with pytest.raises(ModelError, match="not generated by lagrangian"):
        report.save(foreign)
    assert foreign.read_text() == "<p>my notes</p>"
    with pytest.raises(ModelError, match=r"\*\.html"):
        report.save(tmp_path / "report.txt")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.html", "report.html"]


def test_a_formula_too_long_to_typeset_is_one_line(monkeypatch):
    """The benchmark bicycle's M has 32000 nodes: past the limit a formula is named, not set."""
    from lagrangian.report import page as module

    monkeypatch.setattr(module, "TYPESET_LIMIT", 12)
    report = lagrangian.load("cart_pendulum").report(t_end=0.2)
    page = Page(report.html)
    energy = page.section("energy")
    assert "Kinetic energy T: more than 12 terms and factors, too long to typeset" in energy
    assert "Potential energy (J)" in energy  # V = -m g l cos(theta): 9 nodes, still set
    assert "The mass matrix: more than 12" in page.section("equations")


def test_parameters_without_a_value_leave_the_numbers_out(tmp_path):
    model = tmp_path / "symbolic.toml"
    model.write_text("""name = "Symbolic pendulum"
[coordinates]
theta = { unit = "rad", initial = 0.3 }
[parameters]
m = { unit = "kg" }
L = { unit = "m" }
g = { value = 9.81, unit = "m/s^2" }
[gravity]
g = "g"
direction = [0, -1]
[[particles]]
name = "bob"
mass = "m"
position = ["L*sin(theta)", "-L*cos(theta)"]
""", encoding="utf-8")
    report = lagrangian.load(model).report(t_end=0.2)
    statuses = {s.key: s.status for s in report.sections}
    assert statuses["energy"] == statuses["equations"] == "shown"  # symbols need no values
    for key in ("equilibria", "modes", "simulation"):
        assert statuses[key].startswith("not available:") and "'m'" in statuses[key]
    assert "No drawing: parameters: no value for m, L" in Page(report.html).section("model")
