"""Hostile final-answer tables through `lagrangian check`: every file is checked (exit 0 or 1)
or refused in one line naming the file (exit 2), never a traceback."""

from __future__ import annotations

import contextlib
import io

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lagrangian.cli import main

VALUES = ['1', '-1', '0', '2.5', '1e308', '"1"', '"4.43 rad/s"', '"0.705 Hz"', '"1.42 s"', '"pi"',
          '"30deg"', '"43.3 N*m"', '"1 m"', '"1e999"', '"1e-999"', '"nan"', '"inf"', '"1/0"',
          '"k + k_c"', '"x1_ddot + x1"', '"theta_ddot + g/L*theta = 0"', '"a = b = c"', '""',
          'true', '[]', '{}', '[1]', '[[1]]', '[[1, 2], [3, 4]]', '[["k", 0], [0, "m"]]',
          '["0", "pi"]', '[1, "x"]', '{ theta = 0 }', '{ x1 = 0 }', '{ theta = "1 m" }',
          '{ x1 = "2 m" }', '[[0, 0], [0, 0]]', '[["sqrt(2)", 1], [1, -1]]', '"\\u0007"',
          '"__import__(\'os\')"', '"9^9^9^9"']
ORDERS = ['["x2", "x1"]', '["x1"]', "1", '["theta"]']
KEYS = {"matrices": ["M", "K", "C", "X"], "frequencies": ["omega", "f", "period", "zeta"],
        "mode_shapes": ["shapes", "vectors"], "linearized": ["about", "theta", "x1", "x2"],
        "equilibria": ["theta", "x1", "x2", "y"], "generalized_forces": ["at", "theta", "x1"]}


@st.composite
def final_answer_files(draw) -> str:
    lines = []
    if draw(st.booleans()):
        order = draw(st.sampled_from(ORDERS))
        lines.append(f"coordinates = {order}")
    for table in draw(st.sets(st.sampled_from(sorted(KEYS)), min_size=1, max_size=3)):
        lines.append(f"[{table}]")
        for key in draw(st.sets(st.sampled_from(KEYS[table]), min_size=1)):
            lines.append(f"{key} = {draw(st.sampled_from(VALUES))}")
    return "\n".join(lines) + "\n"


@settings(max_examples=80, deadline=None, database=None, derandomize=True,
          suppress_health_check=list(HealthCheck))
@given(final_answer_files(), st.sampled_from(["pendulum", "two_mass", "damped_oscillator"]))
def test_final_answer_tables_never_crash(tmp_path_factory, text, model):
    path = tmp_path_factory.mktemp("fuzz") / "a.toml"
    path.write_text(text, encoding="utf-8")
    err = io.StringIO()
    with pytest.raises(SystemExit) as exit_info:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
            main(["check", model, str(path), "--json"])
    code = exit_info.value.code
    assert code in (0, 1, 2), (code, text)
    if code == 2:
        message = err.getvalue()
        assert message.startswith("error: ") and message.count("\n") == 1, (text, message)
        assert "Traceback" not in message
