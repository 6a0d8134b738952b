"""Expressions to numpy functions: the one lambdify of the package, with one cse policy.

Every numeric function that is not generated C (compile/codegen.py) is made here: the numpy
kernel, the simulation's extra rows (power, velocity bias, stop condition), the static
functions of equilibria and linearization, and the geometry of the mechanism.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np
import sympy as sp

from ..model.expressions import as_expression
from ..model.model import Model
from .exact import machine_numbers

# Common-subexpression elimination pays for big expressions only: on a large sparse model
# (mostly short, independent entries) it costs more than it saves.
CSE_MIN_OPERATIONS = 2000

# numpy's namespace as modules="numpy" builds it (numpy's names, numpy.linalg's over them, the
# same printer and the same generated code), from the modules themselves: "numpy" runs
# `from numpy import *`, which imports numpy.f2py and numpy.testing, 0.3 s of a small command.
_NUMPY = [np.linalg, np]
# use_imps=False: no expression here carries an implemented_function, and looking for one walks
# the expression tree written out, node by node (20 of 34 s of a ten-body chain's lambdify)


def numpy_function(args: Sequence[sp.Symbol], exprs: sp.Expr | Sequence[sp.Expr]) -> Callable:
    """One numpy function of ``args`` returning ``exprs`` (a list, or one value for one
    expression); cse when the expressions are big enough to share work."""
    many = not isinstance(exprs, sp.Basic)
    items = [machine_numbers(as_expression(e)) for e in exprs] if many \
        else [machine_numbers(as_expression(exprs))]
    cse = operations_exceed(items, CSE_MIN_OPERATIONS)
    return sp.lambdify(list(args), items if many else items[0], modules=_NUMPY, cse=cse,
                       use_imps=False)


def operations_exceed(items: Sequence[sp.Expr], limit: int) -> bool:
    """sum(count_ops) > limit, without counting a large model's operations to the end (that
    took longer than the lambdify of the Whipple bicycle's linearization): a tree of more
    than 3 limit nodes has more than limit operations (each node with k arguments adds at
    least k - 1 of them and its leaves are at most about half the nodes)."""
    nodes = 0
    for e in items:
        for _ in sp.preorder_traversal(e):
            nodes += 1
            if nodes > 3 * limit:
                return True
    return sum(sp.count_ops(e) for e in items) > limit


def mpmath_function(args: Sequence[sp.Symbol], exprs: Sequence[sp.Expr]) -> Callable:
    """One mpmath function of ``args`` returning the list ``exprs``, evaluated at mpmath's
    working precision (the checks' random points); cse when the expressions are big."""
    items = [as_expression(e) for e in exprs]
    # Without cse a body in space's equations print and evaluate as a tree: the Whipple
    # bicycle's Newton-Euler rows took ~1.4 million mpmath sin/cos at 12 points and a minute
    # of printing; cse is exact (it only names repeated subexpressions).
    cse = operations_exceed(items, CSE_MIN_OPERATIONS)
    return sp.lambdify(list(args), items, modules="mpmath", cse=cse, use_imps=False)


class StateFunction:
    """Expressions in q, q_dot and t (parameter values put in) as one numpy function.

    Called with q, q_dot of shape (..., n) and t broadcastable to the batch shape; returns the
    values with shape (..., k), floats.
    """

    def __init__(self, model: Model, exprs: Sequence[sp.Expr],
                 parameters: Mapping[sp.Symbol, sp.Expr] | None = None):
        values = dict(parameters or {})
        self.size = len(exprs)
        self._function = numpy_function(
            [*model.q, *model.q_dot, model.time],
            [as_expression(e).xreplace(values) for e in exprs]) if exprs else None

    def __call__(self, q, q_dot, t) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        q_dot = np.asarray(q_dot, dtype=float)
        batch = np.broadcast_shapes(q.shape[:-1], q_dot.shape[:-1], np.shape(t))
        out = np.empty(batch + (self.size,))
        if self._function is None:
            return out
        rows = self._function(*np.moveaxis(q, -1, 0), *np.moveaxis(q_dot, -1, 0),
                              np.asarray(t, dtype=float))
        for i, row in enumerate(rows):
            out[..., i] = np.real(row)
        return out

    def at(self, q, q_dot, t: float) -> np.ndarray:
        """The values at one state, shape (k,): the per-step path, without broadcasting."""
        if self._function is None:
            return np.empty(0)
        return np.array([float(x) for x in self._function(*q, *q_dot, t)], dtype=float)
