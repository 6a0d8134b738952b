"""Start-up: `lagrangian --help`, `lagrangian examples` and `import lagrangian` load none of the
heavy libraries (sympy, scipy, matplotlib, pandas), which cost about a second of CPU before."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

HEAVY = ("sympy", "scipy", "matplotlib", "pandas", "numpy", "pint")

_PROBE = """
import json, sys
from contextlib import redirect_stdout
import io
args = json.loads(sys.argv[1])
if args is None:
    import lagrangian
else:
    from lagrangian.cli import main
    with redirect_stdout(io.StringIO()):
        try:
            main(args)
        except SystemExit:
            pass
print(json.dumps(sorted(m for m in sys.modules if m.split('.')[0] in json.loads(sys.argv[2]))))
"""


def _loaded(args):
    process = subprocess.run([sys.executable, "-c", _PROBE, json.dumps(args), json.dumps(HEAVY)],
                             capture_output=True, text=True, check=True)
    return {name.split(".")[0] for name in json.loads(process.stdout.splitlines()[-1])}


@pytest.mark.parametrize("args", [["--help"], ["examples"], ["examples", "--json"],
                                  ["simulate", "--help"], ["derive", "--help"]])
def test_help_and_examples_import_no_heavy_library(args):
    assert _loaded(args) == set()


def test_import_lagrangian_is_lean_and_loads_names_on_use():
    assert _loaded(None) == set()
    import lagrangian

    # every public name still resolves (the lazy attributes), sympy's functions included
    assert lagrangian.load("pendulum").model.coordinates
    assert lagrangian.sin(0) == 0
    assert "System" in dir(lagrangian)
    with pytest.raises(AttributeError):
        lagrangian.no_such_name  # noqa: B018


def test_a_command_still_does_its_work():
    """The command bodies import what they need: derive still derives."""
    process = subprocess.run([sys.executable, "-m", "lagrangian", "derive", "pendulum", "--format",
                              "json"], capture_output=True, text=True)
    assert process.returncode == 0, process.stderr
    assert "g*sin(theta)" in json.dumps(json.loads(process.stdout))  # m L² θ̈ + m g L sin θ = 0
