"""docs/teaching.md, "Showing the working": its Python example runs and prints what its comments
say, and its console lines are real output."""

import re
from pathlib import Path

TEACHING = Path(__file__).resolve().parents[1] / "docs" / "teaching.md"


def section() -> str:
    text = TEACHING.read_text(encoding="utf-8")
    return text[text.index("<!-- BEGIN steps -->"):text.index("<!-- END steps -->")]


def test_python_example_runs_and_prints_its_comments(capsys):
    code = re.findall(r"```python\n(.*?)```", section(), re.S)[0]
    exec(compile(code, "docs/teaching.md", "exec"), {})
    printed = capsys.readouterr().out.splitlines()
    promised = [line.split("#", 1)[1].strip() for line in code.splitlines()
                if line.startswith("print(") and "#" in line]
    assert printed == promised


def test_console_lines_are_real_output(cli):
    blocks = re.findall(r"```console\n(.*?)```", section(), re.S)
    assert len(blocks) == 2
    runs = []
    for block in blocks:
        for line in block.splitlines():
            if line.startswith("$ "):
                runs.append((line[2:].split("#")[0].split()[1:], []))
            elif line and line != "...":
                runs[-1][1].append(line)
    assert len(runs) == 3
    for command, shown in runs:
        result = cli(*command)
        assert result.code == 0, command
        out = result.out.splitlines()
        assert all(line in out for line in shown), (command, [s for s in shown if s not in out])


def _keys(value, skip=()) -> set[str]:
    """Every key of a JSON document, but not the names of coordinates, bodies or loads."""
    found: set[str] = set()
    if isinstance(value, dict):
        for key, inner in value.items():
            if key not in skip:
                found.add(key)
            found |= _keys(inner, skip)
    elif isinstance(value, list):
        for inner in value:
            found |= _keys(inner, skip)
    return found


def test_every_steps_key_is_documented(cli):
    import json

    text = section()
    names = {"x", "y", "theta", "link", "F", "rod"}  # coordinates, bodies, loads of the models
    derive = json.loads(cli("derive", "cartesian_pendulum", "--steps", "--json").out)["steps"]
    link = json.loads(cli("derive", "virtual_work_link", "--steps", "--json").out)["steps"]
    cross = json.loads(cli("crosscheck", "virtual_work_link", "--steps", "--json").out)["steps"]
    for document in (derive, link, cross):
        for key in _keys(document, names):
            assert any(f"`{key}{end}" in text for end in ("`", ".", "[]")), key
