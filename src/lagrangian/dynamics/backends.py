"""The one seam between a tree's dynamics (recursive.TreeDynamics, the front that checks and
shapes every input) and what computes them: a TreeBackend.

Every backend holds the same seven recursions, each ``f(*inputs, tables)`` (SI units):

- on inputs as the front hands them on (float64 C-ordered arrays of the tree's widths, one
  batch shape, unit base quaternions) it returns the outputs, or ``(outputs, count)`` with NaN
  rows for the states without a defined answer (inputs not finite, M not positive definite);
- on anything else it returns ``NotImplemented``, and the front checks and shapes the inputs
  and calls again: no error text is read, no exception chooses a path.

Two kinds: CompiledBackend (the engine, one compiled module over the tree's tables for every
tree, kernel "compact"; or the tree's own unrolled module, kernel "unrolled") and
recursive_numpy.NumpyBackend (the reference recursions in numpy, where no compiler works or
when asked for). The backend is chosen once, up front (selection.py).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Protocol

import numpy as np

from ..model.tree import KinematicTree

RECURSIONS = ("mass_matrix", "bias_forces", "gravity", "inverse_dynamics", "forward_dynamics",
              "kinetic_energy", "potential_energy")


class TreeBackend(Protocol):
    """A tree's recursions over its tables (module docstring: the contract)."""

    kernel: str  # "compact", "unrolled" or "numpy"
    tables: object  # the last argument of every recursion

    def mass_matrix(self, q, tables): ...
    def bias_forces(self, q, v, tables): ...
    def gravity(self, q, tables): ...
    def inverse_dynamics(self, q, v, a, tables): ...
    def forward_dynamics(self, q, v, tau, tables): ...
    def kinetic_energy(self, q, v, tables): ...
    def potential_energy(self, q, tables): ...
    def numeric_kernel(self, n: int): ...


class CompiledBackend:
    """The recursions in compiled C: the engine's module with the tree's description D,
    prepared once (checked and copied: ``module.prepare(D)``), as its tables (kernel
    "compact"), or a tree's unrolled module with its parameter values ("unrolled")."""

    def __init__(self, kernel: str, module, tables, description: np.ndarray | None = None):
        self.kernel, self.module, self.tables = kernel, module, tables
        self.description = description
        for name in RECURSIONS:  # the module's own functions: no Python between
            setattr(self, name, getattr(module, name))

    def bound(self, name: str, fallback, report):
        """The module's recursion ``name`` bound to the tables: called with the inputs alone,
        fallback(*inputs) where it answers NotImplemented, report((out, count)) where it has
        NaN rows (bound_call.c); None where the module has no such binding."""
        make = getattr(self.module, "bound", None)
        return None if make is None else make(getattr(self.module, name), self.tables,
                                               fallback, report)

    def numeric_kernel(self, n: int):
        """NumericSystem's kernel over this module (simulation)."""
        if self.kernel == "unrolled":
            from ..compile.functions import CKernel

            return CKernel(self.module, self.tables)
        return _CompactKernel(self.module, self.tables, n)


def compiled_backend(tree: KinematicTree, parameters: Mapping[str, float], names: tuple[str, ...],
                     kernel: str) -> CompiledBackend:
    """The engine over this tree's description (kernel "compact"), or the tree's unrolled
    module, built once per tree (kernel "unrolled"); BackendUnavailable without a compiler."""
    if kernel == "compact":
        from .engine.compact_kernel import kernel_module
        from .tree.description import describe

        module, D = kernel_module(), describe(tree, parameters)
        return CompiledBackend("compact", module, module.prepare(D), D)
    from ..compile import compiled
    from .engine.tree_module import module_source, tree_key

    values = np.array([parameters[name] for name in names], dtype=float)
    values.flags.writeable = False
    # exact: no fused multiply-adds, which the compiler places differently in the scalar and
    # the vector functions, so that a batch's row equals its state's single call bit for bit
    # (docs/robotics.md; with them Solo12's g differed in the last bit in 162 of 400 states)
    module = compiled.load_keyed(tree_key(tree, names), lambda: module_source(tree, names),
                                 native=True, exact=True)
    return CompiledBackend("unrolled", module, values)


class _CompactKernel:
    """NumericSystem's kernel over the engine (no constraints: m = 0)."""

    backend = "compact"  # not "c": the module has no DOP853 loop of its own (scipy steps)

    def __init__(self, module, tree, n: int):
        self.m, self.D, self.n = module, tree, n  # the prepared tree

    def _plain(self, out):
        return out[0] if out.__class__ is tuple else out

    def parts(self, Q, V, T):
        Q, V = np.ascontiguousarray(Q, dtype=float), np.ascontiguousarray(V, dtype=float)
        count = len(Q)
        return (self._plain(self.m.mass_matrix(Q, self.D)),
                -self._plain(self.m.bias_forces(Q, V, self.D)),
                np.zeros((count, 0, self.n)), np.zeros((count, 0)))

    def residual(self, Q, V, T):
        return np.zeros((len(Q), 0))

    def energy(self, Q, V, T):
        Q, V = np.ascontiguousarray(Q, dtype=float), np.ascontiguousarray(V, dtype=float)
        return (self._plain(self.m.kinetic_energy(Q, V, self.D))
                + self._plain(self.m.potential_energy(Q, self.D)))

    def accelerations(self, Q, V, T):
        Q, V = np.ascontiguousarray(Q, dtype=float), np.ascontiguousarray(V, dtype=float)
        qdd = self._plain(self.m.forward_dynamics(Q, V, np.zeros_like(Q), self.D))
        return qdd, np.zeros((len(Q), 0))

    def rhs(self, t, y):
        y = np.ascontiguousarray(y, dtype=float)
        n = self.n
        if y.shape != (2 * n,):
            raise ValueError(f"y must hold {2 * n} numbers [q, q_dot]")
        qdd = self._plain(self.m.forward_dynamics(y[:n], y[n:], np.zeros(n), self.D))
        return np.concatenate([y[n:], qdd])


__all__ = ["RECURSIONS", "CompiledBackend", "TreeBackend", "compiled_backend"]
