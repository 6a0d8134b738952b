"""The HTML player's own script, run in node with a stand-in page: it shows the embedded
frames, steps, wraps, plays on a timer and stops at the end without loop; two players on one
page (a notebook) keep apart."""

from __future__ import annotations

import json
import re
import shutil
import subprocess

import numpy as np
import pytest

from lagrangian.output.animation import player_html

node = shutil.which("node")
pytestmark = pytest.mark.skipif(node is None, reason="node is not installed")

PAGE = """
var elements = {};
var document = { getElementById: function (id) {
  if (!(id in elements)) elements[id] = { id: id, checked: true, innerHTML: "", value: 0 };
  return elements[id];
} };
var timers = [];
function setInterval(f, ms) { timers.push([f, ms]); return timers.length; }
function clearInterval(t) { if (t) timers[t - 1] = null; }
"""


def run_player(script: str, actions: str) -> dict:
    out = subprocess.run([node, "-e", PAGE + script + actions], capture_output=True, text=True,
                         timeout=30, check=True).stdout
    return json.loads(out)


def test_the_player_steps_wraps_plays_and_stops():
    frames = [np.full((4, 4, 3), 40 * k, dtype=np.uint8) for k in range(3)]
    page = player_html(frames, fps=20, times=np.array([0.0, 0.05, 0.1]), title="three")
    script = re.search(r"<script>(.*)</script>", page, re.S).group(1)
    prefix = re.search(r'id="(lagrangian-[0-9a-f]+)"', page).group(1)
    actions = f"""
    var p = "{prefix}-", log = [];
    function state() {{ return [elements[p + "frame"].src.length, elements[p + "clock"].textContent,
                                elements[p + "slider"].value]; }}
    log.push(state());
    elements[p + "next"].onclick(); log.push(state());
    elements[p + "back"].onclick(); elements[p + "back"].onclick(); log.push(state());
    document.getElementById(p + "loop").checked = false;
    elements[p + "play"].onclick();
    var timer = timers[timers.length - 1];
    log.push([timer[1], elements[p + "play"].innerHTML]);
    timer[0](); log.push([elements[p + "clock"].textContent, timers[timers.length - 1] === null]);
    console.log(JSON.stringify(log));
    """
    log = run_player(script, actions)
    assert log[0][1:] == ["t = 0.00 s", 0] and log[0][0] > 20  # a data: image is shown
    assert log[1][1:] == ["t = 0.05 s", 1]
    assert log[2][1:] == ["t = 0.10 s", 2]  # back from the first frame wraps to the last
    assert log[3] == [50, "&#10074;&#10074;"]  # 20 frames a second: a 50 ms timer, pause sign
    # at the last frame without loop, the next tick stops instead of wrapping
    assert log[4] == ["t = 0.10 s", True]


def test_two_players_on_one_page_have_their_own_ids():
    frames = [np.zeros((4, 4, 3), dtype=np.uint8)] * 2
    a = player_html(frames, fps=10, times=np.array([0.0, 0.1]))
    b = player_html(frames, fps=10, times=np.array([0.0, 0.1]))
    ids = [set(re.findall(r'id="([^"]+)"', page)) for page in (a, b)]
    assert ids[0] and not ids[0] & ids[1]
