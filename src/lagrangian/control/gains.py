"""Weight and gain matrices as a user writes them: a number (times I), a diagonal, or a matrix."""

from __future__ import annotations

import warnings

import numpy as np

from ..errors import InputError

LARGEST_ENTRY = 1e100  # a weight's or gain's entry; its square stays far inside double range


def square_matrix(value, size: int, field: str, *, definite: bool = False) -> np.ndarray:
    """A size x size symmetric matrix from a number, a diagonal of ``size`` numbers or a
    matrix; positive semidefinite (``definite``: positive definite), finite."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a complex entry: numpy's ComplexWarning refused
            array = np.asarray(value, dtype=float)
    except (TypeError, ValueError, Warning):  # text, a ragged list, a mapping, 1j
        raise InputError(f"expected a number, {size} diagonal entries or a {size} x {size} "
                         f"matrix of real numbers, got {type(value).__name__}",
                         field=field) from None
    if not np.all(np.isfinite(array)):  # before inf * I makes NaN (and numpy's warning)
        raise InputError("entries must be finite numbers", field=field)
    if array.ndim == 0:
        array = array * np.eye(size)
    elif array.ndim == 1 and array.shape == (size,):
        array = np.diag(array)
    if array.shape != (size, size):
        raise InputError(f"expected a number, {size} diagonal entries or a {size} x {size} "
                         f"matrix, got shape {np.shape(value)}", field=field)
    if not np.all(np.isfinite(array)):
        raise InputError("entries must be finite numbers", field=field)
    if np.abs(array).max(initial=0.0) > LARGEST_ENTRY:
        # the Riccati and eigenvalue solvers square and multiply the weights: 1e308 overflowed
        # into eigenvalues that did not converge; only the ratio of Q to R matters
        raise InputError(f"an entry of {float(np.abs(array).max()):.3g} is too large (at most "
                         f"{LARGEST_ENTRY:g}; scale the weights together, only their ratio "
                         "matters)", field=field)
    scale = max(float(np.abs(array).max()), 1e-300)
    if not np.allclose(array, array.T, rtol=0, atol=1e-12 * scale):
        raise InputError("the matrix must be symmetric", field=field)
    smallest = float(np.linalg.eigvalsh((array + array.T) / 2).min()) if size else 1.0
    if smallest < -1e-12 * scale or (definite and smallest <= 1e-12 * scale):
        kind = "positive definite" if definite else "positive semidefinite"
        raise InputError(f"the matrix must be {kind} (its smallest eigenvalue is "
                         f"{smallest:.3g})", field=field)
    if definite and smallest < 1 / LARGEST_ENTRY:  # R^-1 of a subnormal R overflows K
        raise InputError(f"its smallest eigenvalue {smallest:.3g} is too small (at least "
                         f"{1 / LARGEST_ENTRY:g}; scale the weights together, only their ratio "
                         "matters)", field=field)
    return (array + array.T) / 2
