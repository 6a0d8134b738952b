"""Shared pieces of the command line: loading a model, reading NAME=VALUE options, printing."""

from __future__ import annotations

import json
import sys
from collections.abc import Iterable
from typing import Any

from ..api.system import System, load
from ..errors import ModelError
from ..model.units import parse_quantity
from ..model.values import state_units, unknown_name


def load_system(model: str, settings: Iterable[str] = ()) -> System:
    """The system of a model file or built-in example, with --set overrides applied."""
    system = load(model)
    values = parameter_values(system, settings)
    return system.with_parameters(**values) if values else system


def parameter_values(system: System, settings: Iterable[str]) -> dict[str, float]:
    """Read --set NAME=VALUE[unit] options against the model's parameters."""
    parameters = {p.name: p for p in system.model.parameters}
    values = {}
    for name, text in assignments(settings, "--set"):
        if name not in parameters:
            raise _unknown(name, list(parameters), "--set", "parameter")
        values[name] = parse_quantity(text, parameters[name].unit, f"--set {name}")
    return values


def state_assignments(system: System, settings: Iterable[str], option: str) -> dict[str, float]:
    """Read NAME=VALUE[unit] options for coordinates (e.g. 30deg), velocities and t."""
    units = state_units(system.model)
    values = {}
    for name, text in assignments(settings, option):
        if name not in units:
            raise unknown_name(name, units, "coordinate, velocity or t", option)
        values[name] = parse_quantity(text, units[name], f"{option} {name}")
    return values


def assignments(settings: Iterable[str], option: str) -> list[tuple[str, str]]:
    pairs = []
    for setting in settings:
        name, sep, value = setting.partition("=")
        if not sep or not name.strip() or not value.strip():
            raise ModelError(f"expected NAME=VALUE, got {setting!r}", field=option)
        pairs.append((name.strip(), value.strip()))
    return pairs


def _unknown(name: str, known: list[str], option: str, what: str) -> ModelError:
    import difflib

    close = difflib.get_close_matches(name, known, n=1)
    hint = f"; did you mean '{close[0]}'?" if close else ""
    return ModelError(f"'{name}' is not a {what} of this model{hint}", field=option)


def print_json(document: Any) -> None:
    json.dump(document, sys.stdout, indent=2, allow_nan=False)
    sys.stdout.write("\n")
