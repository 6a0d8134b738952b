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


_ANSWER = "src/lagrangian/model/examples/course/worked_example_1/right.toml"

# What each small command must not load (issue 38: each answers in about a second): the
# libraries and stages it does not use. scipy is modes' (its generalized eigenproblem).
_NOT_LOADED = {
    ("derive", "pendulum"): ("scipy", "pint", "matplotlib", "pandas", "xarray",
                             "lagrangian.simulation", "lagrangian.dynamics",
                             "lagrangian.check.diagnose", "lagrangian.compile.compiled"),
    ("simulate", "pendulum", "--t-end", "2"): ("scipy", "pint", "matplotlib", "pandas", "xarray",
                                               "lagrangian.dynamics", "lagrangian.check.diagnose",
                                               "lagrangian.output.animation"),
    ("modes", "double_pendulum"): ("pint", "matplotlib", "pandas", "xarray",
                                   "lagrangian.dynamics", "lagrangian.simulation",
                                   "lagrangian.output.animation", "lagrangian.check.diagnose"),
    ("check", "pendulum", _ANSWER): ("scipy", "pint", "matplotlib", "pandas", "xarray",
                                     "lagrangian.dynamics", "lagrangian.simulation",
                                     "lagrangian.check.final_answers"),
}


@pytest.mark.parametrize("args", list(_NOT_LOADED), ids=lambda args: args[0])
def test_a_small_command_loads_only_what_it_uses(args):
    process = subprocess.run([sys.executable, "-c", _PROBE, json.dumps(list(args)),
                              json.dumps(["scipy", "pint", "matplotlib", "pandas", "xarray",
                                          "lagrangian"])],
                             capture_output=True, text=True, check=True)
    loaded = json.loads(process.stdout.splitlines()[-1])
    unwanted = [name for name in loaded
                if any(name == stem or name.startswith(stem + ".") for stem in _NOT_LOADED[args])]
    assert unwanted == []


def test_every_command_is_found_by_its_name():
    """The command line loads a named command's module alone (cli/__init__.py COMMAND_MODULES):
    every module's commands are listed there under their own module, and nothing else."""
    import pkgutil
    from importlib import import_module

    import lagrangian.cli as cli

    for found in pkgutil.iter_modules(cli.__path__):
        import_module(f"lagrangian.cli.{found.name}")
    registered = {cli.command_name(info): info.callback.__module__.rpartition(".")[2]
                  for info in cli.app.registered_commands}
    assert registered == cli.COMMAND_MODULES
