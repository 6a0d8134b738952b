"""The statics section (docs/getting-started/engineers.md): its Python example runs and gives the
closed form, and its console lines are real output."""

import math
import re
import tomllib

import docs_blocks
from statics_models import SLIDER_CRANK as CRANK


def section() -> str:
    return docs_blocks.block("statics")


def test_python_example_runs_and_gives_the_closed_form(capsys):
    code = re.findall(r"```python\n(.*?)```", section(), re.S)[0]
    exec(compile(code, "statics", "exec"), {})
    out = capsys.readouterr().out
    theta = math.radians(40)
    closed = 12.0 / (0.1 * math.sin(theta) * (1 + 0.1 * math.cos(theta)
                                              / math.sqrt(0.09 - 0.01 * math.sin(theta) ** 2)))
    value = float(re.search(r"\{'P': ([0-9.e+-]+)\}", out).group(1))
    assert abs(value - closed) < 1e-9 * closed


def test_the_model_file_shown_is_the_tested_slider_crank():
    (model,) = re.findall(r"```toml\n# crank.toml\n(.*?)```", section(), re.S)
    assert tomllib.loads(model) == tomllib.loads(CRANK)


def test_console_lines_are_real_output(cli, tmp_path):
    path = tmp_path / "crank.toml"
    path.write_text(re.findall(r"```toml\n(# crank.toml\n.*?)```", section(), re.S)[0])
    out = cli("statics", str(path), "--at", "theta=40deg", "--solve-for", "P").out
    shown = re.findall(r"```console\n(.*?)```", section(), re.S)[0]
    lines = [line for line in shown.splitlines()[1:] if line and not line.startswith(("$", "..."))]
    assert lines and all(line in out.splitlines() for line in lines)
