"""Units of model quantities, through pint: validating unit strings and reading values like 30deg."""

from __future__ import annotations

import functools
import math
import re

from ..errors import ModelError

_ANGLE_UNITS = {"rad", "radian", "radians", "deg", "degree", "degrees", "rev", "revolution"}
_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-z_µ°][\w*/^ .µ°-]*)?\s*$")
MAX_UNIT_LENGTH = 200
MAX_UNIT_EXPONENT = 100
_UNIT_TOKEN = re.compile(r"\s*(?:(?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)"
                         r"|(?P<name>[A-Za-z_µ°][A-Za-z0-9_µ°]*)|(?P<op>\*\*|[*/^()·.-]))")


# Units that are SI already (a factor of 1): checked and converted without pint, whose registry
# takes half a second to build, which was a third of `derive`'s start-up for every model file.
_SI_UNITS = frozenset({"m", "kg", "s", "rad", "N", "J", "W", "N*m", "m/s", "m/s^2", "rad/s",
                       "rad/s^2", "kg*m^2", "N/m", "N*s/m", "N*m/rad", "N*m*s/rad"})


# The dimensions (pint's names) of the units model files use most, exactly as pint gives them
# for a quantity in base units: the units check of every `derive` runs on these without pint.
_L, _M, _T = "[length]", "[mass]", "[time]"
_SI_DIMENSIONS = {
    "": {}, "1": {}, "rad": {}, "deg": {}, "m": {_L: 1}, "kg": {_M: 1}, "s": {_T: 1},
    "N": {_L: 1, _M: 1, _T: -2}, "J": {_L: 2, _M: 1, _T: -2}, "W": {_L: 2, _M: 1, _T: -3},
    "N*m": {_L: 2, _M: 1, _T: -2}, "m/s": {_L: 1, _T: -1}, "m/s^2": {_L: 1, _T: -2},
    "rad/s": {_T: -1}, "rad/s^2": {_T: -2}, "kg*m^2": {_L: 2, _M: 1}, "N/m": {_M: 1, _T: -2},
    "N*s/m": {_M: 1, _T: -1}, "N*m/rad": {_L: 2, _M: 1, _T: -2},
    "N*m*s/rad": {_L: 2, _M: 1, _T: -1},
}


class UnitOutsideTable(LookupError):
    """A unit the exact SI table does not hold: pint must judge it."""


class Dimension:
    """The dimension of a quantity in base units, as pint's ``dimensionality`` (exponents by
    pint's base names, zeros dropped), with the arithmetic the units check does on it: the same
    float operations in the same order as pint's, so every comparison comes out the same."""

    __slots__ = ("dimensionality",)

    def __init__(self, dimensionality: dict):
        self.dimensionality = dimensionality

    @property
    def dimensionless(self) -> bool:
        return not self.dimensionality

    def _combined(self, other: Dimension, sign: int) -> Dimension:
        result = dict(self.dimensionality)
        for name, exponent in other.dimensionality.items():
            total = result.get(name, 0) + exponent if sign > 0 else result.get(name, 0) - exponent
            if total == 0:
                result.pop(name, None)
            else:
                result[name] = total
        return Dimension(result)

    def __mul__(self, other: Dimension) -> Dimension:
        return self._combined(other, 1)

    def __truediv__(self, other: Dimension) -> Dimension:
        return self._combined(other, -1)

    def __pow__(self, power: float) -> Dimension:
        if power == 0:
            return Dimension({})
        return Dimension({name: exponent * power for name, exponent in self.dimensionality.items()})


def si_dimension(unit: str | None) -> Dimension | None:
    """The dimension of ``unit`` from the exact table (None: no unit, an unknown dimension);
    UnitOutsideTable for any other unit."""
    if unit is None:
        return None
    found = _SI_DIMENSIONS.get(unit)
    if found is None:
        raise UnitOutsideTable(unit)
    return Dimension(dict(found))


@functools.cache
def registry():
    """The shared pint unit registry (imported lazily: pint is slow to import).

    A model whose units are all in the exact SI table never reaches it (check/units.py); for
    the others pint is imported without dask (below). pint's on-disk cache of its parsed
    definitions is not used: it is pickles (code), and the model stage knows no trusted cache
    directory (that is the compile stage's).
    """
    pint = _import_pint()
    return pint.UnitRegistry(autoconvert_offset_to_baseunit=True)


def _import_pint():
    """pint, imported with dask hidden when dask is not loaded yet: pint.compat imports
    dask.base (0.13 s, with psutil and jinja2) only to let quantities wrap dask arrays, which
    nothing here makes. A process that has imported dask already (xarray's sweeps) keeps it."""
    import sys

    if "pint" in sys.modules or "dask" in sys.modules:
        import pint

        return pint
    sys.modules["dask"] = None  # find_spec and import both read None as "not installed"
    try:
        import pint
    finally:
        if sys.modules.get("dask", "") is None:
            del sys.modules["dask"]
    return pint


def unit_syntax_problem(text: str) -> str | None:
    """Why ``text`` cannot be a unit before the unit library reads it (pint evaluates powers
    and numbers in a unit string: 'kg*9^9^9' would take minutes), or None.

    Powers must be plain numbers of at most MAX_UNIT_EXPONENT in size (m^2, s^-1, m^(1/2)),
    never towers; numbers stay below 1e300.
    """
    if len(text) > MAX_UNIT_LENGTH:
        return f"a unit is at most {MAX_UNIT_LENGTH} characters long"
    tokens = []
    position = 0
    stripped = _pint_text(text).rstrip()
    while position < len(stripped):
        match = _UNIT_TOKEN.match(stripped, position)
        if match is None or match.end() == position:
            return f"{stripped[position:].lstrip()[:1]!r} cannot appear in a unit"
        tokens.append((match.lastgroup, match.group(match.lastgroup)))
        position = match.end()
    powered = [False]  # per open parenthesis: does the group hold a power already?
    index = 0
    while index < len(tokens):
        kind, value = tokens[index]
        if kind == "op" and value == "(":
            powered.append(False)
            if len(powered) > 20:
                return "the unit is nested too deeply"
        elif kind == "op" and value == ")" and len(powered) > 1:
            inner = powered.pop()
            powered[-1] = powered[-1] or inner
            if inner and tokens[index + 1:index + 2] == [("op", "**")]:
                return "powers of powers are not allowed in a unit"
        elif kind == "number" and not float(value) < 1e300:
            return f"the number {value} is too large"
        elif kind == "op" and value == "**":
            index, problem = _unit_exponent(tokens, index + 1)
            if problem:
                return problem
            powered[-1] = True
            continue
        index += 1
    return None


def _pint_text(text: str) -> str:
    """A unit string as the unit library reads it ('·' multiplies, '^' raises)."""
    return text.replace("^", "**").replace("·", "*")


def _unit_exponent(tokens, index):
    """Read the exponent after '^': [sign] number or '(' [sign] number [/ number] ')'."""
    values = []
    closing = index < len(tokens) and tokens[index] == ("op", "(")
    if closing:
        index += 1
    if index < len(tokens) and tokens[index] in (("op", "-"),):
        index += 1
    while index < len(tokens) and tokens[index][0] == "number":
        values.append(float(tokens[index][1]))
        index += 1
        if closing and index < len(tokens) and tokens[index] == ("op", "/"):
            index += 1
            continue
        break
    if not values:
        return index, "a power in a unit must be a plain number (like m^2 or s^-1)"
    if closing:
        if index >= len(tokens) or tokens[index] != ("op", ")"):
            return index, "a power in a unit must be a plain number (like m^2 or m^(1/2))"
        index += 1
    if any(abs(v) > MAX_UNIT_EXPONENT for v in values):
        return index, f"the power is too large (at most {MAX_UNIT_EXPONENT})"
    if index < len(tokens) and tokens[index] == ("op", "**"):
        return index, "powers of powers are not allowed in a unit"
    return index, None


def _unit(text: str):
    """The pint unit of ``text``, or None when pint cannot read it."""
    if unit_syntax_problem(text):
        return None
    try:
        return registry().Unit(_pint_text(text))
    except Exception:  # pint's parser raises many kinds (tokenize, syntax, lookup): all mean "not a unit"
        return None


def check_unit(text: str, field: str, source: str | None) -> str:
    """Validate a unit string (pint syntax, e.g. 'kg', 'N*m', 'm/s^2'); returns it unchanged."""
    if text in ("", "1") or text in _SI_UNITS:
        return text
    if re.fullmatch(r"[A-Za-z0-9_*/^ .()µ°·-]+", text):
        problem = unit_syntax_problem(text)
        if problem:
            raise ModelError(f"unit {_short(text)}: {problem}", field=field, source=source)
    if not re.fullmatch(r"[A-Za-z0-9_*/^ .()µ°·-]+", text) or _unit(text) is None:
        raise ModelError(f"unknown unit {_short(text)}", field=field, source=source)
    return text


def _short(text: str) -> str:
    """A unit string for a one-line message (cut when long, control characters escaped)."""
    return repr(text) if len(text) <= 60 else repr(f"{text[:28]}...{text[-28:]}")


def is_angle_unit(unit: str | None) -> bool:
    return unit is not None and unit.strip() in _ANGLE_UNITS


def to_si(value: float, unit: str | None, field: str, source: str | None = None) -> float:
    """Convert a number in ``unit`` to SI base units (angles to radians)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ModelError(f"expected a number, got {value!r}", field=field, source=source)
    try:
        finite = math.isfinite(value)
    except OverflowError:  # an integer beyond 1.8e308
        raise ModelError("the number is too large for a floating-point number", field=field,
                         source=source) from None
    if not finite:
        raise ModelError(f"the number {value!r} is not finite", field=field, source=source)
    if not unit or unit == "1" or unit in _SI_UNITS:
        return float(value)
    parsed = _unit(unit)
    if parsed is None:
        raise ModelError(f"unknown unit {_short(unit)}", field=field, source=source)
    return _finite_si(registry().Quantity(value, parsed), f"{value!r} {unit}", field, source)


def _finite_si(quantity, text: str, field: str, source: str | None = None) -> float:
    """The SI magnitude of ``quantity``, refused when the conversion overflows (1e308 pi)."""
    try:
        value = float(quantity.to_base_units().magnitude)
    except (OverflowError, ZeroDivisionError, ValueError):
        value = math.inf
    if not math.isfinite(value):
        raise ModelError(f"{_short(text)} is not a finite number in SI units", field=field,
                         source=source)
    return value


def parse_quantity(text: str, expected_unit: str | None, field: str) -> float:
    """Read '30deg', '0.5 m', '2', 'pi/2' or '3*pi/4 rad' as an SI number, checking it matches
    ``expected_unit``.

    A bare number is taken as SI (radians for an angle); the number may be a constant
    expression of the model grammar (numbers and pi), bounded like any expression.
    """
    match = _QUANTITY.match(text)
    if match:
        number, unit = float(match.group(1)), (match.group(2) or "").strip()
        if not math.isfinite(number):
            raise ModelError(f"{_short(text)} is not a finite number", field=field)
        if number == 0 and any(d in "123456789" for d in match.group(1).lower().partition("e")[0]):
            raise ModelError(f"{_short(text)} is too small for a floating-point number (it would "
                             f"be read as 0)", field=field)
    else:
        number, unit = _constant_quantity(text, field)
    if not unit:
        return number
    problem = unit_syntax_problem(unit)
    if problem:
        raise ModelError(f"unit {_short(unit)}: {problem}", field=field)
    parsed = _unit(unit)
    if parsed is None:
        raise ModelError(f"unknown unit {_short(unit)} in {_short(text)}", field=field)
    quantity = registry().Quantity(number, parsed)
    if expected_unit and expected_unit != "1":
        target = _unit(expected_unit)
        if target is not None and quantity.dimensionality != (1 * target).dimensionality:
            raise ModelError(
                f"{_short(text)} is not in units compatible with '{expected_unit}'", field=field
            )
    return _finite_si(quantity, text, field)


_UNIT_TAIL = re.compile(r"^(.*?\S)\s+([A-Za-z_µ°][\w*/^.µ°-]*)\s*$", re.DOTALL)


def _constant_quantity(text: str, field: str) -> tuple[float, str]:
    """'pi/2' or '3*pi/4 rad': a constant expression and an optional unit after a space."""
    from .expressions import parse_expression
    from .tokens import plain_names

    head, unit = text.strip(), ""
    split = _UNIT_TAIL.match(head)
    if split and split.group(2) != "pi" and _unit(split.group(2)) is not None:
        head, unit = split.group(1), split.group(2)
    if not head or set(plain_names(head)) - {"pi"}:
        raise ModelError(f"expected a number with an optional unit (like 30deg), got "
                         f"{_short(text)}", field=field)
    value = parse_expression(head, {}, field=field)
    return float(value.evalf()), unit


def generalized_force_unit(coordinate_unit: str | None) -> str:
    """Unit of the generalized force paired with a coordinate: energy per unit of q."""
    if not coordinate_unit or coordinate_unit == "1" or is_angle_unit(coordinate_unit):
        return "N*m"
    if coordinate_unit == "m":
        return "N"
    parsed = _unit(coordinate_unit)
    if parsed is None:
        return f"J/({coordinate_unit})"
    dimensionality = (1 * parsed).to_base_units()
    if dimensionality.dimensionality == registry().meter.dimensionality:
        return "N" if dimensionality.magnitude == 1 else f"J/{coordinate_unit}"
    return f"J/({coordinate_unit})" if " " in coordinate_unit or "/" in coordinate_unit \
        else f"J/{coordinate_unit}"
