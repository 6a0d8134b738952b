"""Shared pieces of the command line: loading a model, reading NAME=VALUE options, printing."""

from __future__ import annotations

import json
import re
import sys
import warnings
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

import typer

from ..errors import InputError, LagrangianError, ModelError, ModelWarning, one_line

if TYPE_CHECKING:
    from .. import EquationsOfMotion, System

# sympy, scipy and pint are imported inside the functions that need them, so that
# `lagrangian --help` and `lagrangian examples` start in a fraction of a second.

# The CLI's name for each Python field the library names in its errors (ModelError.field):
# the one place where the library's words meet the command line's flags.
FLAG_OF_FIELD = {
    "parameters": "--set",
    "configuration": "--at",
    "about": "--about",
    "steady": "--steady",
    "solve_for": "--solve-for",
    "initial": "--initial",
    "t_end": "--t-end",
    "stop_when": "--stop-when",
    "guess": "--guess",
    "max_impacts": "--max-impacts",
    "method": "--method",
    "rtol": "--rtol",
    "atol": "--atol",
    "samples": "--samples",
    "table": "--out",
    "plot": "--plot",
    "animation": "--animate",
    "view": "--view",
    "size": "--size",
    "fps": "--fps",
    "mode": "--mode",
    "lock": "--lock",
    "floating_base": "--floating-base",
    "q": "--q",
    "keep": "--keep",
    "speed": "--speed",
    "out": "--out",
    "csv": "--csv",
    "frame": "--frame",
    "reference": "--reference",
    "f_ext": "--wrench",
    "armature": "--armature",
    "controller": "--control",
    "linear_model": "--control",
    "inputs": "--inputs",
    "independent": "--independent",
    "Q": "--Q",
    "R": "--R",
    "Kp": "--kp",
    "Kd": "--kd",
    "q_des": "--about",
}

SET_HELP = "Override a parameter: NAME=VALUE; repeat, or join with commas (m=2,L=0.5)."
# What an animation's option is called where it is given without --animate.
ONLY_WITH_ANIMATE = {"size": "a frame size is", "fps": "frames a second are",
                     "mode": "a mode number is", "view": "a viewpoint is"}
SIZE_HELP = "Frame size of the animation in pixels, WIDTHxHEIGHT (default 400x400 a drawing)."
FPS_HELP = "Frames a second of the animation (1 to 120)."
LOCK_HELP = ("URDF: freeze a joint at a value, NAME=VALUE (30deg, 0.02m); repeat, or join with "
             "commas (a=0,b=0).")
PAYLOAD_HELP = ("URDF: a point mass fixed to a link, LINK=MASS[@X,Y,Z] (kg; m in the link's "
                "frame, default its origin); repeatable.")
FLOATING_HELP = ("URDF: a free-flyer joint under the root link (a robot that walks or flies): q is "
                 "the base's x,y,z and quaternion qx,qy,qz,qw, then the joints; v the base's "
                 "twist vx..wz in its own axes, then the joint rates. MJCF: the free joint as "
                 "that base (without the flag, MuJoCo's own qpos and qvel).")
GRAVITY_HELP = ("Gravity as a vector in world axes, GX,GY,GZ in m/s^2 (default: the model's; "
                "a URDF's is 0,0,-9.81).")


def in_flags(error: LagrangianError) -> LagrangianError:
    """The library's error with its Python field (``parameters.m``) named by the flag that gave
    it (``--set m``); errors in a file (with a source) keep the file's own field names."""
    if not isinstance(error, ModelError) or error.source or not error.field:
        return error
    head, _, rest = error.field.partition(".")
    if head not in FLAG_OF_FIELD:
        return error
    return ModelError(error.message, field=f"{FLAG_OF_FIELD[head]} {rest}".strip())


def in_flags_text(warning: Warning) -> str:
    """A library warning's line with the Python field it starts with (``lock elbow=...``, its
    ``field``) named by the flag (``--lock elbow=...``)."""
    text, field = str(warning), getattr(warning, "field", None)
    if field in FLAG_OF_FIELD and text.startswith(f"{field} "):
        return FLAG_OF_FIELD[field] + text[len(field):]
    return text


def load_system(model: str, settings: Iterable[str] = (), lock: Iterable[str] = (),
                gravity: str | None = None, payload: Iterable[str] = (),
                floating_base: bool = False) -> System:
    """The system of a model file or built-in example, with --set overrides applied (and a
    URDF's joints frozen by --lock NAME=VALUE, its gravity turned by --gravity GX,GY,GZ; a
    later --set g=... rescales that vector's magnitude)."""
    from .. import load, parse_quantity

    # --lock a=0,b=0 as --lock a=0 --lock b=0, as --set reads a comma list; each text read by
    # the library in its joint's unit (an angle, a length) and checked against its limit
    locked = dict(assignments(comma_separated(lock), "--lock"))
    carried = payloads(payload)
    freed = {"floating_base": True} if floating_base else {}
    with warnings.catch_warnings(record=True) as seen:  # what the reader left out, one line each
        warnings.simplefilter("always", ModelWarning)
        system = load(model, lock=locked, payload=carried, **freed) \
            if locked or carried or freed else load(model)
    for warning in seen:
        if issubclass(warning.category, ModelWarning):
            warn(in_flags_text(warning.message))
        else:
            warnings.warn_explicit(warning.message, warning.category, warning.filename,
                                   warning.lineno)
    if gravity is not None:
        parts = [part.strip() for part in gravity.split(",")]
        if len(parts) != 3:
            raise InputError(f"expected 3 comma-separated components g_x,g_y,g_z (m/s^2), got "
                             f"{len(parts)}", field="--gravity")
        system = system.with_gravity([parse_quantity(p, "m/s^2", "--gravity") for p in parts])
    values = parameter_values(system, settings)
    system = system.with_parameters(**values) if values else system
    for line in system.warnings(set_parameters=values):
        warn(line)
    return system


# Warnings of this command (one line each on stderr, and `warnings` in its JSON document).
_WARNINGS: list[str] = []


def reset_warnings() -> None:
    _WARNINGS.clear()


def warn(line: str) -> None:
    """A line `warning: ...` for stderr (printed when the command ends, so that a refusal stays
    one `error:` line), kept for the command's JSON document."""
    if line not in _WARNINGS:
        _WARNINGS.append(line)


def flush_warnings() -> None:
    """Print the command's warnings on stderr, one line each (main() calls it on success)."""
    for line in _WARNINGS:  # a warning may quote a model's names: escaped as errors are
        typer.echo(f"warning: {one_line(line)}", err=True)
    _WARNINGS.clear()


def parameter_values(system: System, settings: Iterable[str]) -> dict[str, float | str]:
    """Read --set NAME=VALUE[unit] options in SI units (names are judged by the library)."""
    units = {p.name: p.unit for p in system.model.parameters}
    pairs = assignments(comma_separated(settings), "--set")
    values = quantities(pairs, units, "--set")
    warn_bare_angles("--set", pairs, units, values)  # an incline angle of 30
    return values


def state_assignments(system: System, settings: Iterable[str], option: str
                      ) -> dict[str, float | str]:
    """Read NAME=VALUE[unit] options for coordinates (e.g. 30deg), velocities and t, in SI
    units (names are judged by the library)."""
    from .. import state_units

    pairs = assignments(comma_separated(settings), option)
    units = state_units(system.model)
    values = quantities(pairs, units, option)
    warn_bare_angles(option, pairs, units, values)
    return values


def warn_bare_angles(option: str, pairs: Iterable[tuple[str, str]],
                     units: Mapping[str, str | None], values: Mapping[str, object]) -> None:
    """A warning for each angle written as a bare number beyond a turn (the library judges)."""
    from .. import bare_angle_warnings

    for line in bare_angle_warnings(option, pairs, units, values):
        warn(line)


def quantities(pairs: Iterable[tuple[str, str]], units: Mapping[str, str | None], option: str
               ) -> dict[str, float | str]:
    """Each value in SI units by the unit of its name. A name without a unit here is passed on
    as written: the library refuses it by name (with a suggestion), so the CLI need not judge."""
    from .. import parse_quantity

    return {name: parse_quantity(text, units[name], f"{option} {name}") if name in units else text
            for name, text in pairs}


def comma_separated(settings: Iterable[str]) -> list[str]:
    """`--at x=0.1,x_dot=2` as `--at x=0.1 --at x_dot=2`: split at each comma that a NAME=
    follows (a comma inside a value, as in 1,5, stays where it is and is refused as a number)."""
    return [part for setting in settings for part in _NEXT_ASSIGNMENT.split(setting)]


_NEXT_ASSIGNMENT = re.compile(r",(?=\s*[A-Za-z_][A-Za-z0-9_.\-]*\s*=)")  # link.mass= too


def payloads(settings: Iterable[str]) -> dict[str, tuple[float, tuple[float, ...]]]:
    """--payload LINK=MASS[@X,Y,Z] options as {link: (kg, (x, y, z) in m)}."""
    from .. import parse_quantity

    out = {}
    for link, text in assignments(settings, "--payload"):
        mass, _, point = text.partition("@")
        field = f"--payload {link}"
        parts = [p.strip() for p in point.split(",")] if point.strip() else ["0", "0", "0"]
        if len(parts) != 3:
            raise InputError(f"expected MASS@X,Y,Z, got {len(parts)} coordinates", field=field)
        out[link] = (parse_quantity(mass.strip(), "kg", field),
                     tuple(parse_quantity(p, "m", field) for p in parts))
    return out


def assignments(settings: Iterable[str], option: str) -> list[tuple[str, str]]:
    """NAME=VALUE options as (name, value text) pairs; a name given twice is refused (one of
    the two would be dropped without a word)."""
    pairs: dict[str, str] = {}
    for setting in settings:
        name, sep, value = setting.partition("=")
        name, value = name.strip(), value.strip()
        if not sep or not name or not value:
            raise InputError(f"expected NAME=VALUE, got {setting!r}", field=option)
        if name in pairs:
            raise InputError(f"{name!r} is given twice ({pairs[name]!r}, then {value!r}): give "
                             f"it once", field=option)
        pairs[name] = value
    return list(pairs.items())


def warn_if_unphysical(eom: EquationsOfMotion) -> None:
    """One line `warning: ...` on stderr for each thing that makes a well-formed model
    physically meaningless (a negative mass, a kinetic energy that is not positive)."""
    from .. import physical_warnings

    for warning in physical_warnings(eom.model, eom.mass_matrix):
        warn(warning)


# Characters that a terminal acts on rather than prints: C0 controls but newline and tab, DEL,
# C1 controls, and the bidirectional overrides and isolates (and marks) that reorder a line.
# A model's name or any other text from a file (a body, a coordinate, a load) could otherwise
# clear the screen, move the cursor or print fake text (issue 21, item 13).
_TERMINAL_CONTROLS = dict.fromkeys(
    [*range(0x00, 0x09), *range(0x0B, 0x20), 0x7F, *range(0x80, 0xA0),
     *range(0x202A, 0x202F), *range(0x2066, 0x206A), 0x200E, 0x200F, 0x061C])


def terminal_text(text: str) -> str:
    """``text`` with every character a terminal would act on removed (newline and tab kept)."""
    return text.translate(_TERMINAL_CONTROLS)


class TerminalText:
    """A text stream that strips terminal controls from everything written to it: the one place
    where the command line's output (stdout, stderr) meets the terminal. Everything else is the
    wrapped stream's; rich's progress bars (our own text, their own escape codes) write to the
    wrapped stream directly (``rich_proxied_file``)."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text: str) -> int:
        if not isinstance(text, str):  # as a text stream: click probes with b""
            raise TypeError(f"write() argument must be str, not {type(text).__name__}")
        self._stream.write(terminal_text(text))
        return len(text)

    def writelines(self, lines: Iterable[str]) -> None:
        for line in lines:
            self.write(line)

    @property
    def rich_proxied_file(self):
        return self._stream

    @property
    def buffer(self):  # no way around the filter (click writes bytes to a stream's buffer)
        raise AttributeError("buffer")

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


def print_json(document: Any) -> None:
    """The command's JSON document, with this command's warnings under `warnings`."""
    if isinstance(document, dict) and _WARNINGS:
        known = list(document.get("warnings") or [])
        document = {**document, "warnings": known + [w for w in _WARNINGS if w not in known]}
    json.dump(document, sys.stdout, indent=2, allow_nan=False)
    sys.stdout.write("\n")
