"""A user's q, v, a or tau as float64 numbers, or one line naming the argument: text, a
mapping or ragged lists are refused as InputError, never a numpy ValueError or TypeError
escaping from deep inside a dynamics function (None reads as NaN: that state's row is NaN)."""

from __future__ import annotations

import numpy as np

from ..errors import InputError


def float_array(value, field: str) -> np.ndarray:
    """``value`` as an array of float64 (no copy where it already is one)."""
    if value.__class__ is np.ndarray and value.dtype == np.float64:
        return value
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        reason = "rows of different lengths" if "inhomogeneous" in str(exc) else str(exc)
        raise InputError(f"expected numbers, got a {type(value).__name__} that cannot be read "
                         f"as them ({reason})", field=field) from None


def batch_shape(arrays, fields) -> tuple[int, ...]:
    """The batch the inputs' leading axes broadcast to (each array's last axis is one state's
    numbers), else one line naming them."""
    shapes = [np.shape(x)[:-1] for x in arrays]
    try:
        return np.broadcast_shapes(*shapes)
    except ValueError:
        listed = ", ".join(f"{f} {s}" for f, s in zip(fields, shapes, strict=True))
        raise InputError(f"the batches of states do not broadcast together ({listed})",
                         field=fields[0] if len(set(fields)) == 1 else "/".join(fields)) from None


__all__ = ["batch_shape", "float_array"]
