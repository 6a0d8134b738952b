"""Warnings where a user is probably wrong: one line each, for the CLI's stderr and the
`warnings` of its JSON, and for the Python user (System.warnings).

Not errors: the model is well formed and the results are right for what was written, but what
was written is likely not what was meant (a declared g with no gravity, a parameter that no
equation contains given a value, a dimensionally inconsistent term).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping

from ..derivation.equations import EquationsOfMotion
from ..errors import LagrangianError
from ..model.model import Model
from ..model.units import is_angle_unit
from .units import check_model_units

# More unit issues than this are summed up in one line (the `units` command lists them all).
MOST_UNIT_LINES = 3


def model_warnings(model: Model, eom: EquationsOfMotion | None = None) -> list[str]:
    """A declared g with no gravity; the units check's inconsistent terms (a g in m/s)."""
    lines = []
    names = {p.name for p in model.parameters}
    if "g" in names and model.gravity is None and model.kinematic_tree is None and \
            (eom is None or "g" not in eom.parameters_used):
        lines.append("parameter 'g' is declared but the model has no [gravity]: the potential "
                     "holds no weight (add a [gravity] table, or remove g)")
    lines += fixed_root_warnings(model)
    if model.kinematic_tree is None:  # a URDF robot's numbers are SI by the format
        try:
            report = check_model_units(model)
        except (LagrangianError, ArithmeticError, ValueError, TypeError):
            report = None
        issues = list(report.issues) if report is not None else []
        # A model whose parameters all carry units was written with units in mind: all its
        # inconsistencies are news. Elsewhere (numbers, bare symbols) only gravity's is.
        united = bool(model.parameters) and all(p.unit for p in model.parameters)
        issues = [i for i in issues if united or i.item.startswith("gravity")]
        for issue in issues[:MOST_UNIT_LINES]:
            lines.append(f"units: {issue.item}: {issue.message} (see `units`)")
        if len(issues) > MOST_UNIT_LINES:
            lines.append(f"units: {len(issues) - MOST_UNIT_LINES} more inconsistent terms "
                         "(see `units`)")
    return lines


def fixed_root_warnings(model: Model) -> list[str]:
    """A URDF robot loaded with a fixed base whose root link carries mass that no joint of the
    file fixes (a root named 'world' is the file's own word for the ground): a legged robot's
    trunk, probably meant to float."""
    tree = model.kinematic_tree
    if tree is None or tree.floating_base or tree.root_mass <= 0 or tree.root_link == "world":
        return []
    return [f"the root link '{tree.root_link}' (with the links welded to it) carries "
            f"{tree.root_mass:.6g} kg and no joint of the URDF fixes it: loaded with a fixed "
            "base, bolted to the world (a robot that walks or flies: dynamics, kinematics or "
            "codegen --floating-base, load(path, floating_base=True))"]


def setting_warnings(eom: EquationsOfMotion, names: Iterable[str]) -> list[str]:
    """A parameter given a value that no equation contains: its value changes nothing."""
    steady = eom.model.steady_motion
    speed = steady.speed if steady is not None else None
    # a gain of the [control] laws counts: it changes every run with controller="model"
    controlled = {str(s) for _, law in eom.model.control for s in law.free_symbols}
    # ... and a parameter of an impact (its restitution, guard, point, normal or relabelling)
    for impact in eom.model.impacts:
        parts = (impact.guard, impact.restitution, *impact.point, *impact.normal,
                 *(e for _, e in impact.relabel))
        controlled |= {str(s) for part in parts for s in part.free_symbols}
    return [f"'{name}' is set but appears in no equation of motion: its value changes nothing"
            + (f" here ('{name}' is the speed of the [steady] motion: `speeds`, `modes`)"
               if name == speed else "")
            for name in names if name not in eom.parameters_used and name not in controlled]


def bare_angle_warnings(option: str, written: Iterable[tuple[str, str]],
                        units: Mapping[str, str | None], values: Mapping[str, object]) -> list[str]:
    """An angle written as a bare number beyond a turn (2 pi rad): read as radians, and 30 was
    probably meant in degrees. ``written``: (name, text as typed); ``values``: SI values."""
    lines = []
    for name, text in written:
        value = values.get(name)
        if is_angle_unit(units.get(name)) and _BARE_NUMBER.fullmatch(text) and \
                isinstance(value, float) and abs(value) > 2 * math.pi:
            lines.append(f"{option} {name}={text} is read as {text} rad "
                         f"({math.degrees(value):.6g} deg); write {text}deg for degrees")
    return lines


def joint_limits(model: Model) -> dict[str, tuple[float, float]]:
    """A robot read from URDF: coordinate name -> its joint's position limit (lower, upper) in
    rad or m, for the joints that have one (a continuous joint has none)."""
    coordinates = {c.name: c for c in model.coordinates}
    return {name: coordinates[name].range for name, _ in model.source_names
            if name in coordinates and coordinates[name].range is not None}


def limit_warnings(model: Model, values: Mapping[str, float], option: str = "--q") -> list[str]:
    """One line for each coordinate of ``values`` (SI) beyond its URDF joint's position limit,
    naming the file's joint and the limit."""
    limits, joints = joint_limits(model), dict(model.source_names)
    units = {c.name: c.unit for c in model.coordinates}
    lines = []
    for name, value in values.items():
        if name not in limits or not math.isfinite(value):
            continue
        lower, upper = limits[name]
        if lower <= value <= upper:
            continue
        lines.append(f"{option} {name}={value:.6g} {units[name]} is beyond the position limit "
                     f"[{lower:.6g}, {upper:.6g}] {units[name]} of URDF joint '{joints[name]}'")
    return lines


_BARE_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


__all__ = ["bare_angle_warnings", "joint_limits", "limit_warnings", "model_warnings",
           "setting_warnings"]
