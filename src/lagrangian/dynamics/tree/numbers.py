"""A user's q, v, a or tau as float64 numbers, or one line naming the argument: text, a
mapping or ragged lists are refused as InputError, never a numpy ValueError or TypeError
escaping from deep inside a dynamics function (None reads as NaN: that state's row is NaN)."""

from __future__ import annotations

import warnings

import numpy as np

from ...errors import DynamicsWarning, InputError


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


def warn_undefined(count: int, total: int, stacklevel: int = 4) -> None:
    """One DynamicsWarning for ``count`` of ``total`` states with NaN rows (at the user's call)."""
    warnings.warn(DynamicsWarning(
        f"{count} of {total} states have no dynamics (an input not finite, or a mass matrix "
        "that is not positive definite): their rows are NaN", count, total),
        stacklevel=stacklevel)


def over_finite_rows(compute, flat, tail: tuple[int, ...], forward: bool = False):
    """compute(*flat inputs (N, width)) -> (N, *tail) over the states whose inputs are all
    finite, NaN rows for the others (and, ``forward``, for rows without a finite answer):
    (outputs, the rows' mask of defined answers)."""
    total = len(flat[0])
    good = np.ones(total, dtype=bool)
    for x in flat:
        good &= np.isfinite(x).all(axis=-1)
    # a finite state beyond 1e154 overflows to inf as the compiled engine's does, without
    # numpy's RuntimeWarning (forward dynamics then counts its row)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        if good.all():
            out = np.asarray(compute(*flat), dtype=float).reshape((total,) + tail)
        else:
            out = np.full((total,) + tail, np.nan)
            if good.any():
                out[good] = np.asarray(compute(*(x[good] for x in flat)),
                                       dtype=float).reshape((-1,) + tail)
    if forward:
        good &= np.isfinite(out.reshape(total, -1)).all(axis=-1)
        out[~good] = np.nan
    return out, good


def solve_positive(mass: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """M^-1 rhs for a flat batch (N, n, n), (N, n) by Cholesky, NaN in the rows whose M is not
    positive definite (each row as if alone)."""
    try:
        L = np.linalg.cholesky(mass)
    except np.linalg.LinAlgError:
        out = np.full(rhs.shape, np.nan)
        for k in range(len(mass)):  # only on this path: find the rows without a factor
            try:
                L = np.linalg.cholesky(mass[k:k + 1])
            except np.linalg.LinAlgError:
                continue
            y = np.linalg.solve(L, rhs[k:k + 1, :, None])
            out[k] = np.linalg.solve(np.swapaxes(L, -1, -2), y)[0, :, 0]
        return out
    y = np.linalg.solve(L, rhs[..., None])
    return np.linalg.solve(np.swapaxes(L, -1, -2), y)[..., 0]


__all__ = ["batch_shape", "float_array", "over_finite_rows", "solve_positive",
           "warn_undefined"]
