"""The two checks every value given by name passes (values.py's states and parameters,
Model.with_parameter_values): the model has that name, and the value is a finite SI number.
Apart from values.py, so that model.py checks its own replacements without importing it."""

from __future__ import annotations

import math
from collections.abc import Iterable

from ..errors import ModelError, did_you_mean_or_list


def unknown_name(name: str, known: Iterable[str], what: str, field: str | None) -> ModelError:
    """"'x' is not a <what> of this model; did you mean 'y'?" (the hint when one is close, else
    the valid names)."""
    return ModelError(f"'{name}' is not a {what} of this model"
                      f"{did_you_mean_or_list(name, known)}", field=field)


def si_number(name: str, value: object, field: str) -> float:
    """``value`` as a finite float, or a ModelError naming ``name`` and ``field``."""
    number = None
    if not isinstance(value, str | bytes):  # text is read with its unit by the caller, not here
        try:
            number = float(value)  # numbers, numpy or sympy numbers (sympy.pi)
        except (TypeError, ValueError):
            pass
    if number is None:
        raise ModelError(f"the value of '{name}' must be a number in SI units (radians for "
                         f"angles, e.g. math.pi), got {value!r}", field=field)
    if not math.isfinite(number):
        raise ModelError(f"the value of '{name}' must be a finite number, got {value!r}",
                         field=field)
    return number
