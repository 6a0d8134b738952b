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
