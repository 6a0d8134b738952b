"""Units of model quantities, through pint: validating unit strings and reading values like 30deg."""

from __future__ import annotations

import functools
import math
import re

from ..errors import ModelError

_ANGLE_UNITS = {"rad", "radian", "radians", "deg", "degree", "degrees", "rev", "revolution"}
_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-z_µ°][\w*/^ .µ°-]*)?\s*$")


@functools.cache
def registry():
    """The shared pint unit registry (imported lazily: pint is slow to import)."""
    import pint

    return pint.UnitRegistry(autoconvert_offset_to_baseunit=True)


def _unit(text: str):
    """The pint unit of ``text``, or None when pint cannot read it."""
    try:
        return registry().Unit(text.replace("^", "**").replace("·", "*"))
    except Exception:  # pint's parser raises many kinds (tokenize, syntax, lookup): all mean "not a unit"
        return None


def check_unit(text: str, field: str, source: str | None) -> str:
    """Validate a unit string (pint syntax, e.g. 'kg', 'N*m', 'm/s^2'); returns it unchanged."""
    if text in ("", "1"):
        return text
    if not re.fullmatch(r"[A-Za-z0-9_*/^ .()µ°·-]+", text) or _unit(text) is None:
        raise ModelError(f"unknown unit '{text}'", field=field, source=source)
    return text


def is_angle_unit(unit: str | None) -> bool:
    return unit is not None and unit.strip() in _ANGLE_UNITS


def to_si(value: float, unit: str | None, field: str, source: str | None = None) -> float:
    """Convert a number in ``unit`` to SI base units (angles to radians)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ModelError(f"expected a number, got {value!r}", field=field, source=source)
    if not math.isfinite(value):
        raise ModelError(f"the number {value!r} is not finite", field=field, source=source)
    if not unit or unit == "1":
        return float(value)
    parsed = _unit(unit)
    if parsed is None:
        raise ModelError(f"unknown unit '{unit}'", field=field, source=source)
    return float(registry().Quantity(value, parsed).to_base_units().magnitude)


def parse_quantity(text: str, expected_unit: str | None, field: str) -> float:
    """Read '30deg', '0.5 m' or '2' as an SI number, checking it matches ``expected_unit``.

    A bare number is taken as SI (radians for an angle).
    """
    match = _QUANTITY.match(text)
    if not match:
        raise ModelError(f"expected a number with an optional unit (like 30deg), got {text!r}",
                         field=field)
    number, unit = float(match.group(1)), (match.group(2) or "").strip()
    if not math.isfinite(number):
        raise ModelError(f"{text!r} is not a finite number", field=field)
    if not unit:
        return number
    parsed = _unit(unit)
    if parsed is None:
        raise ModelError(f"unknown unit '{unit}' in {text!r}", field=field)
    quantity = registry().Quantity(number, parsed)
    if expected_unit and expected_unit != "1":
        target = _unit(expected_unit)
        if target is not None and quantity.dimensionality != (1 * target).dimensionality:
            raise ModelError(
                f"{text!r} is not in units compatible with '{expected_unit}'", field=field
            )
    return float(quantity.to_base_units().magnitude)


def generalized_force_unit(coordinate_unit: str | None) -> str:
    """Unit of the generalized force paired with a coordinate: energy per unit of q."""
    if not coordinate_unit or coordinate_unit == "1" or is_angle_unit(coordinate_unit):
        return "N*m"
    parsed = _unit(coordinate_unit)
    if parsed is None:
        return f"J/({coordinate_unit})"
    dimensionality = (1 * parsed).to_base_units()
    if dimensionality.dimensionality == registry().meter.dimensionality:
        return "N" if dimensionality.magnitude == 1 else f"J/{coordinate_unit}"
    return f"J/({coordinate_unit})" if " " in coordinate_unit or "/" in coordinate_unit \
        else f"J/{coordinate_unit}"
