"""Numeric functions compiled once from the symbolic equations (generated C, or numpy).

Every function takes q and q_dot of shape (..., n) and t broadcastable to the batch shape, and
returns arrays with that leading batch shape: one state or many at once.
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import partial

import numpy as np

from ..derivation.equations import EquationsOfMotion
from ..errors import DerivationError, ModelError
from ..kinds import Backend
from ..model.expressions import as_expression
from ..model.model import Model
from ..model.values import ParameterValues, resolve_parameters
from .lambdified import numpy_function


@dataclass(frozen=True)
class NumericSystem:
    """Mass matrix, forcing, constraint terms and energy as numeric callables (SI units).

    ``backend`` is "c" (generated C, compiled once and cached) or "numpy" (lambdify).
    """

    coordinates: tuple[str, ...]
    constraint_names: tuple[str, ...]
    constraint_kinds: tuple[str, ...]
    parameters: dict[str, float]
    _kernel: _NumpyKernel | CKernel

    @property
    def n(self) -> int:
        return len(self.coordinates)

    @property
    def m(self) -> int:
        return len(self.constraint_names)

    @property
    def backend(self) -> str:
        return self._kernel.backend

    def __repr__(self) -> str:
        constraints = f", constraints={list(self.constraint_names)}" if self.m else ""
        return (f"NumericSystem(coordinates={list(self.coordinates)}{constraints}, "
                f"backend={self.backend!r})")

    def _flat(self, q, q_dot, t):
        """(N, n), (N, n), (N,) float arrays for the kernel, and the batch shape."""
        n = self.n
        q, q_dot = np.asarray(q, dtype=float), np.asarray(q_dot, dtype=float)
        if q.shape == q_dot.shape and q.shape[-1:] == (n,) and np.ndim(t) == 0:
            # the common case (same shapes, one time): no broadcasting machinery
            batch = q.shape[:-1]
            Q, V = q.reshape(-1, n), q_dot.reshape(-1, n)
            return Q, V, np.full(len(Q), float(t)), batch
        q, q_dot, batch = _batch(q, q_dot, n)
        count = int(np.prod(batch, dtype=np.int64))
        t = np.broadcast_to(np.asarray(t, dtype=float), batch).reshape(count)
        return (np.ascontiguousarray(q.reshape(count, self.n)),
                np.ascontiguousarray(q_dot.reshape(count, self.n)),
                np.ascontiguousarray(t), batch)

    def _parts(self, q, q_dot, t):
        Q, V, T, batch = self._flat(q, q_dot, t)
        mass, forcing, jacobian, gamma = self._kernel.parts(Q, V, T)
        n, m = self.n, self.m
        return (mass.reshape(batch + (n, n)), forcing.reshape(batch + (n,)),
                jacobian.reshape(batch + (m, n)), gamma.reshape(batch + (m,)))

    def mass_matrix(self, q, q_dot, t=0.0) -> np.ndarray:
        """M(q, t), shape (..., n, n), in kg, kg m or kg m^2 per entry."""
        return self._parts(q, q_dot, t)[0]

    def forcing(self, q, q_dot, t=0.0) -> np.ndarray:
        """f(q, q_dot, t), shape (..., n)."""
        return self._parts(q, q_dot, t)[1]

    def constraint_jacobian(self, q, q_dot, t=0.0) -> np.ndarray:
        """Phi_q (or A for velocity constraints), shape (..., m, n)."""
        return self._parts(q, q_dot, t)[2]

    def acceleration_rhs(self, q, q_dot, t=0.0) -> np.ndarray:
        """gamma with Phi_q q_ddot = gamma, shape (..., m)."""
        return self._parts(q, q_dot, t)[3]

    def constraint_residual(self, q, q_dot, t=0.0) -> np.ndarray:
        """Phi(q, t) for holonomic constraints, A q_dot + b for velocity ones; shape (..., m)."""
        Q, V, T, batch = self._flat(q, q_dot, t)
        return self._kernel.residual(Q, V, T).reshape(batch + (self.m,))

    def energy(self, q, q_dot, t=0.0) -> np.ndarray:
        """Total mechanical energy T + V in J, shape (...)."""
        Q, V, T, batch = self._flat(q, q_dot, t)
        return self._kernel.energy(Q, V, T).reshape(batch)

    def accelerations_and_multipliers(self, q, q_dot, t=0.0) -> tuple[np.ndarray, np.ndarray]:
        """Solve `[[M, Phi_q^T], [Phi_q, 0]] [q_ddot; lambda] = [f; gamma]`: (q_ddot, lambda)."""
        Q, V, T, batch = self._flat(q, q_dot, t)
        q_ddot, multipliers = self._kernel.accelerations(Q, V, T)
        return q_ddot.reshape(batch + (self.n,)), multipliers.reshape(batch + (self.m,))

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """First-order right-hand side for y = [q, q_dot] (the one simulate integrates); always
        returns a fresh array."""
        return self._kernel.rhs(t, y)


class _NumpyKernel:
    """lambdify'd functions over flat batches; the fallback that needs no compiler."""

    backend = "numpy"

    def __init__(self, n: int, m: int, evaluate: Callable, energy: Callable, residual: Callable):
        self.n, self.m = n, m
        self._evaluate, self._energy, self._residual = evaluate, energy, residual

    def _columns(self, Q, V):
        return *Q.T, *V.T

    def parts(self, Q, V, T):
        count, n, m = len(T), self.n, self.m
        entries = self._evaluate(*self._columns(Q, V), T)
        flat = np.empty((count, len(entries)))
        for i, e in enumerate(entries):
            flat[:, i] = e
        return (flat[:, : n * n].reshape(count, n, n), flat[:, n * n: n * n + n],
                flat[:, n * n + n: n * n + n + m * n].reshape(count, m, n),
                flat[:, n * n + n + m * n:])

    def residual(self, Q, V, T):
        values = self._residual(*self._columns(Q, V), T)
        out = np.empty((len(T), self.m))
        for i, v in enumerate(values):
            out[:, i] = v
        return out

    def energy(self, Q, V, T):
        out = np.empty(len(T))
        out[:] = self._energy(*self._columns(Q, V), T)
        return out

    def accelerations(self, Q, V, T):
        mass, forcing, jacobian, gamma = self.parts(Q, V, T)
        n, m = self.n, self.m
        if not m:
            return np.linalg.solve(mass, forcing[..., None])[..., 0], forcing[..., :0]
        kkt = np.zeros((len(T), n + m, n + m))  # [[M, Phi_q^T], [Phi_q, 0]]
        kkt[:, :n, :n] = mass
        kkt[:, :n, n:] = np.swapaxes(jacobian, -1, -2)
        kkt[:, n:, :n] = jacobian
        rhs = np.concatenate([forcing, gamma], axis=-1)
        solution = np.linalg.solve(kkt, rhs[..., None])[..., 0]
        return solution[:, :n], solution[:, n:]

    def rhs(self, t, y):
        y = np.asarray(y, dtype=float)
        if y.shape != (2 * self.n,):
            raise ValueError(f"y must hold {2 * self.n} numbers [q, q_dot]")
        n, m = self.n, self.m
        # One state: scalar lambdify call and a small solve, no batch machinery.
        entries = np.array(self._evaluate(*y, float(t)), dtype=float)
        mass = entries[: n * n].reshape(n, n)
        forcing = entries[n * n: n * n + n]
        if m:
            jacobian = entries[n * n + n: n * n + n + m * n].reshape(m, n)
            mass = np.block([[mass, jacobian.T], [jacobian, np.zeros((m, m))]])
            forcing = np.concatenate([forcing, entries[n * n + n + m * n:]])
        return np.concatenate([y[n:], np.linalg.solve(mass, forcing)[:n]])


class CKernel:
    """Generated C (see codegen.py / template.c): batch loops and the linear solve run in C."""

    backend = "c"

    def __init__(self, module, parameter_values: np.ndarray):
        self.module = module
        self.parameter_values = np.ascontiguousarray(parameter_values, dtype=float)
        self.parameter_values.flags.writeable = False
        # partial is a C callable: rhs(t, y) costs one C call plus the work.
        self.rhs = partial(module.rhs, self.parameter_values)

    def parts(self, Q, V, T):
        return self.module.parts(Q, V, T, self.parameter_values)

    def residual(self, Q, V, T):
        return self.module.residual(Q, V, T, self.parameter_values)

    def energy(self, Q, V, T):
        return self.module.energy(Q, V, T, self.parameter_values)

    def accelerations(self, Q, V, T):
        return self.module.accelerations(Q, V, T, self.parameter_values)


def _batch(q, q_dot, n: int):
    q = np.asarray(q, dtype=float)
    q_dot = np.asarray(q_dot, dtype=float)
    if q.shape[-1:] != (n,) or q_dot.shape[-1:] != (n,):
        raise ValueError(f"q and q_dot must have a last axis of length {n}")
    batch = np.broadcast_shapes(q.shape[:-1], q_dot.shape[:-1])
    return np.broadcast_to(q, batch + (n,)), np.broadcast_to(q_dot, batch + (n,)), batch


BACKENDS = tuple(Backend)  # "auto", "c", "numpy"

# Generated C per equations object: cse + printing is the slow part of a C build.
_SOURCES: dict[int, tuple[EquationsOfMotion, object]] = {}


def _generated(eom: EquationsOfMotion):
    from .codegen import generate

    hit = _SOURCES.get(id(eom))
    if hit is not None and hit[0] is eom:
        return hit[1]
    source = generate(eom)
    if len(_SOURCES) >= 16:
        _SOURCES.pop(next(iter(_SOURCES)))
    _SOURCES[id(eom)] = (eom, source)
    return source


def equations_key(eom: EquationsOfMotion) -> str:
    """What the generated C is a function of, as text: the names in their order and the
    expressions' trees (no printing, no cse: 40x quicker than srepr at n = 10), so a cached
    module is found without generating its source."""
    model = eom.model
    names = [model.name, *map(str, model.q), *map(str, model.q_dot), str(model.time),
             *(p.name for p in model.parameters), str(len(model.constraints))]
    expressions = [*eom.mass_matrix, *eom.forcing, *eom.constraint_jacobian,
                   *eom.acceleration_rhs, eom.kinetic_energy + eom.potential_energy,
                   *(c.expression for c in model.constraints)]
    memo: dict = {}
    return "\n".join([repr(names), *(_tree_text(as_expression(e), memo) for e in expressions)])


def _tree_text(expression, memo: dict) -> str:
    """The expression's tree as exact text: each node's type and arguments, Floats by their
    binary value (two Floats printing alike but differing in the last bit are two keys)."""
    hit = memo.get(expression)
    if hit is not None:
        return hit
    if expression.is_Atom:
        exact = getattr(expression, "_mpf_", None)
        text = f"Float{exact!r}" if exact is not None else \
            f"{type(expression).__name__}:{expression}"
    else:
        text = (f"{type(expression).__name__}("
                + ",".join(_tree_text(a, memo) for a in expression.args) + ")")
    memo[expression] = text
    return text


def _c_kernel(eom: EquationsOfMotion, values: dict) -> CKernel:
    from . import compiled

    def source():  # only for a module not yet built: a cached one needs no C printer
        from .codegen import CodegenError

        try:
            return _generated(eom)
        except CodegenError as exc:
            raise compiled.BackendUnavailable(f"the equations cannot be written in C: {exc}"
                                              ) from None

    module = compiled.load_keyed(equations_key(eom), source)
    return CKernel(module, np.array([float(values[p.symbol]) for p in eom.model.parameters]))


_TOLD: set[str] = set()


def tell_once(line: str) -> None:
    """One plain line on stderr, once per process (not a Python warning: this is advice)."""
    if line not in _TOLD:
        _TOLD.add(line)
        print(line, file=sys.stderr)


def _numpy_kernel(eom: EquationsOfMotion, values: dict) -> _NumpyKernel:
    model = eom.model
    args = [*model.q, *model.q_dot, model.time]

    def numeric_list(exprs):
        return [as_expression(e).xreplace(values) for e in exprs]

    entries = numeric_list([*eom.mass_matrix, *eom.forcing, *eom.constraint_jacobian,
                            *eom.acceleration_rhs])
    residuals = numeric_list([c.expression for c in model.constraints])
    energy = (eom.kinetic_energy + eom.potential_energy).xreplace(values)
    return _NumpyKernel(len(model.q), len(model.constraints), numpy_function(args, entries),
                        numpy_function(args, energy), numpy_function(args, residuals))


def numeric(
    eom: EquationsOfMotion, parameters: Mapping[str, float] | ParameterValues | None = None,
    backend: str = "auto",
) -> NumericSystem:
    """Compile the equations once (common-subexpression elimination) into numeric functions.

    backend: "c" (generated C; raises BackendUnavailable without a working compiler), "numpy"
    (lambdify, needs no compiler) or "auto" (C when a compiler works, else numpy).
    """
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {', '.join(BACKENDS)}, not {backend!r}")
    model = eom.model
    refuse_large_chain(model)
    values = resolve_parameters(model, parameters).symbol_values(model)
    kernel = None
    if backend in ("auto", "c"):
        from .compiled import BackendUnavailable

        try:
            kernel = _c_kernel(eom, values)
        except BackendUnavailable as exc:
            if backend == "c":
                raise
            tell_numpy_fallback(exc, "the equations run as numpy functions, 50-100x slower "
                                "than compiled C")
    if kernel is None:
        try:
            kernel = _numpy_kernel(eom, values)
        except NotImplementedError as exc:  # sympy's printers: e.g. a leftover Derivative
            raise DerivationError("the equations cannot be evaluated numerically: "
                                  + str(exc).splitlines()[0]) from None
    return NumericSystem(
        coordinates=tuple(c.name for c in model.coordinates),
        constraint_names=tuple(c.name for c in model.constraints),
        constraint_kinds=tuple(c.kind for c in model.constraints),
        parameters={str(k): float(v) for k, v in values.items()},
        _kernel=kernel,
    )


# The deepest chain of rotating bodies whose derived equations are compiled: measured with
# benchmarks/bench_spatial_chain.py, 10 bodies build in 5 s, 14 in 43 s and 2.8 GB, 20 passed
# 24 GB; the number of terms grows like the Fibonacci numbers down the chain.
MAX_COMPILED_ROTATIONS = 12


def refuse_large_chain(model: Model) -> None:
    """Refuse, before any work, to compile the equations of a chain of bodies too deep for them
    (one line naming the body and its depth); a bare tree of bodies on joints runs the
    recursive algorithms instead (dynamics/recursive.py) and never comes here."""
    deep = next((b for b in model.rigid_bodies if b.depth > MAX_COMPILED_ROTATIONS), None)
    if deep is not None:
        raise ModelError(
            f"body '{deep.name}' is {deep.depth} elementary rotations from the ground: its "
            f"equations are too large to compile (at most {MAX_COMPILED_ROTATIONS}; 14 took 43 s "
            "and 2.8 GB); a tree of rigid bodies on revolute and prismatic joints with only "
            "gravity and generalized forces runs the recursive algorithms instead",
            field=f"body '{deep.name}'.joint", source=model.source)


def tell_numpy_fallback(exc: Exception, what_happens: str) -> None:
    """Say once, in one plain line, that C gave way to numpy for want of a compiler (and how to
    get the fast path); a compiler that is there but failed is a warning."""
    from .compiled import CompilerMissing

    if isinstance(exc, CompilerMissing):
        tell_once(f"note: {str(exc).split(' (')[0]}, so {what_happens}; for the fast path "
                   + ("unset CC or point it at gcc or clang" if "CC=" in str(exc)
                      else "install gcc or clang (or set CC)"))
    elif compiled_was_expected():
        from ..errors import BackendWarning

        # the compiler's own words after the first line, joined: one line in the CLI
        first, *rest = [line.strip() for line in str(exc).splitlines() if line.strip()] or [""]
        warnings.warn(f"C backend unavailable, using numpy: {first} {'; '.join(rest)}".rstrip(),
                      BackendWarning, stacklevel=3)


def compiled_was_expected() -> bool:
    """A compiler is present, so a failure to use it is worth a warning."""
    from . import compiled

    return compiled.available()
