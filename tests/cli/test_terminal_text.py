"""Issue 21, item 13: user text (a model's name, a load's, a value on the command line) never
reaches a terminal with the control characters that would clear the screen, move the cursor or
reorder the line; in HTML and SVG it is escaped; in a plot it is drawn as written (never parsed
as mathtext)."""

from __future__ import annotations

import io
import json

import pytest

from lagrangian.cli.common import TerminalText, terminal_text

HOSTILE_NAME = ("evil\x1b[2J\x1b[1;1Herror: fake\x07 <script>alert(1)</script> "
                "\u202egnp.exe\u2066 \x9b31m $\\frac$ \r\x7fend")
CONTROLS = [chr(c) for c in [*range(0x00, 0x09), *range(0x0B, 0x20), 0x7F, *range(0x80, 0xA0),
                             *range(0x202A, 0x202F), *range(0x2066, 0x206A)]]


def _model(tmp_path, body: bool = False):
    name = json.dumps(HOSTILE_NAME)  # a JSON string is a TOML basic string
    text = f"""name = {name}
[coordinates]
theta = {{ unit = "rad", initial = 0.3 }}
[parameters]
m = 1.0
L = 0.5
g = 9.81
"""
    if body:
        text += """[gravity]
g = "g"
direction = [0, -1]
[[particles]]
name = "bob"
mass = "m"
position = ["L*sin(theta)", "-L*cos(theta)"]
"""
    else:
        text += '[energy]\nT = "1/2*m*L^2*theta_dot^2"\nV = "-m*g*L*cos(theta)"\n'
    path = tmp_path / "evil.toml"
    path.write_text(text, encoding="utf-8")
    return str(path)


def _clean(text: str) -> None:
    found = sorted({c for c in text if c in CONTROLS})
    assert not found, f"control characters reach the terminal: {found!r}"


def test_terminal_text_strips_every_control_but_newline_and_tab():
    text = "".join(CONTROLS) + "a\tb\nc é ∑ 𝜃"
    assert terminal_text(text) == "a\tb\nc é ∑ 𝜃"


def test_terminal_stream_filters_writes_and_keeps_the_stream():
    inner = io.StringIO()
    stream = TerminalText(inner)
    stream.write("x\x1b[2Jy\n")
    stream.writelines(["\u202eab", "c\x9b"])
    assert inner.getvalue() == "x[2Jy\nabc"
    assert stream.rich_proxied_file is inner  # rich's progress bars keep their own codes
    assert not stream.isatty()
    with pytest.raises(TypeError):
        stream.write(b"")  # a text stream: click then writes text, not to the buffer
    with pytest.raises(AttributeError):
        stream.buffer  # noqa: B018  (no way around the filter)


@pytest.mark.parametrize("args", [
    ["derive"], ["derive", "--format", "latex"], ["modes"], ["equilibria"], ["forces"],
    ["dynamics"], ["units"], ["simulate", "--t-end", "0.1", "--samples", "5"],
])
def test_hostile_model_name_is_stripped_on_the_terminal(cli, tmp_path, args):
    code, out, err = cli(args[0], _model(tmp_path), *args[1:])
    assert code == 0, err
    _clean(out + err)
    assert "evil" in out + err or args[0] in ("forces", "dynamics", "units")


def test_hostile_model_name_in_json_is_escaped_not_lost(cli, tmp_path):
    code, out, err = cli("derive", _model(tmp_path), "--json")
    assert code == 0, err
    _clean(out)
    assert json.loads(out)["name"] == HOSTILE_NAME  # JSON escapes, the reader gets it back


def test_hostile_text_in_an_error_is_one_clean_line(cli, tmp_path):
    code, out, err = cli("derive", _model(tmp_path), "--set", "m=1\x1b[2J\u202e")
    assert code == 2 and out == ""
    _clean(err)
    assert len(err.strip().splitlines()) == 1 and err.startswith("error: ")
    code, out, err = cli("derive", "no\x1b]0;title\x07such\u202e.toml")
    assert code == 2
    _clean(err)
    assert len(err.strip().splitlines()) == 1


def test_hostile_model_name_in_the_html_player_is_escaped(cli, tmp_path):
    page = tmp_path / "run.html"
    code, out, err = cli("simulate", _model(tmp_path, body=True), "--t-end", "0.2",
                         "--animate", str(page))
    assert code == 0, err
    _clean(out + err)
    html = page.read_text(encoding="utf-8")
    assert "<script>alert" not in html and "&lt;script&gt;alert(1)&lt;/script&gt;" in html
    assert html.count("<script>") == 1  # the player's own


@pytest.mark.parametrize("suffix", [".svg", ".png"])
def test_hostile_model_name_in_plots_is_drawn_as_written(cli, tmp_path, suffix):
    plot = tmp_path / f"run{suffix}"
    code, out, err = cli("simulate", _model(tmp_path), "--t-end", "0.1", "--plot", str(plot))
    assert code == 0, err  # '$\\frac$' was parsed as mathtext: ParseSyntaxException
    _clean(out + err)
    if suffix == ".svg":
        svg = plot.read_text(encoding="utf-8")
        assert "<script>alert" not in svg
    code, out, err = cli("modes", _model(tmp_path), "--plot", str(tmp_path / "modes.png"))
    assert code == 0, err
    _clean(out + err)
