"""A URDF joint's lock value: a number in SI (rad for a revolute or continuous joint, m for a
prismatic one) or a text with its unit ("30deg", "0.02 m"), checked against the joint's kind
and its position limit as a coordinate's value is (beyond the limit: a ModelWarning)."""

from __future__ import annotations

import math
import re
import warnings

from ..errors import ModelError, ModelWarning
from .units import parse_quantity


def lock_value(joint, value: object) -> float:
    """The SI value ``joint`` is locked at: a text read in the joint's unit (an angle for a
    revolute joint, a length for a prismatic one; "1kg" refused), a number taken as SI; a value
    beyond the joint's position limit warned (field "lock")."""
    field = f"lock.{joint.name}"
    unit = "m" if joint.type == "prismatic" else "rad"
    if isinstance(value, str):
        number = parse_quantity(value.strip(), None, field)  # a number and a unit at all
        try:
            number = parse_quantity(value.strip(), unit, field)
        except ModelError:  # read, but in another dimension (1kg for an angle)
            what = "a length" if unit == "m" else "an angle"
            raise ModelError(f"{value.strip()[:40]!r} is not {what} (joint '{joint.name}' is "
                             f"{joint.type})", field=field) from None
    else:
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise ModelError(f"the value {value!r} is not a number", field=field) from None
    if not math.isfinite(number):
        raise ModelError(f"the value {value!r} is not finite", field=field)
    text = value.strip() if isinstance(value, str) else ""
    if unit == "rad" and _BARE_NUMBER.fullmatch(text) and abs(number) > 2 * math.pi:
        _warn(f"lock {joint.name}={text} is read as {text} rad ({math.degrees(number):.6g} deg); "
              f"write {text}deg for degrees")  # as --q's bare angle beyond a turn
    limit = joint.limit if joint.type != "continuous" else None
    lower, upper = (None, None) if limit is None else (limit.lower, limit.upper)
    if lower is not None and upper is not None and lower < upper \
            and not lower <= number <= upper:
        _warn(f"lock {joint.name}={number:.6g} {unit} is beyond the position limit "
              f"[{lower:.6g}, {upper:.6g}] {unit} of URDF joint '{joint.name}'")
    return number


_BARE_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


def _warn(line: str) -> None:
    warning = ModelWarning(line)
    warning.field = "lock"  # the CLI names its flag (--lock)
    warnings.warn(warning, stacklevel=3)
