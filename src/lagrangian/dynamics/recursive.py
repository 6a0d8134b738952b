"""Recursive rigid-body dynamics of a robot's kinematic tree (model/tree.py) as generated C.

Instead of expanding the equations of motion (whose size grows much faster than the number of
bodies), the generated code keeps the recursions over the tree, unrolled body by body with the
joint axes, placements and inertias as numbers (zeros and ones folded away, common terms
shared):

- inverse dynamics by recursive Newton-Euler: tau = M(q) a + C(q, q_dot) q_dot + g(q);
- the mass matrix by the composite-rigid-body algorithm;
- forward dynamics by the articulated-body algorithm, O(n), or M = L L^T, whichever takes
  fewer operations (Cholesky only with mimic joints);
- sin and cos of each joint angle once, by inline kernels (fdlibm's polynomials after a
  three-part reduction by pi/2, libm beyond |x| = 1e5): a libm call costs as much as the rest
  of the mass matrix of a 7-joint arm;
- kinetic energy 1/2 sum (m v.v + 2 v.(w x h) + w.J_O w), potential energy m g height.

A floating base (free_flyer.py) takes q of nq = n + 7 numbers and v, a, tau of nv = n + 6 (the
module's RT_NQ and LG_N); its quaternion's norm is checked before the C call, the C uses its
unit rotation.

Units SI. Gravity g (a runtime parameter) along the tree's direction; each coordinate's actuator
parameter tau_<joint> acts as a load, as in the symbolic equations (b = C q_dot + g - tau_p).
The same functions are written as standalone C99 (standalone.py) and, with the Python bindings
below and template.c, as a compiled module cached by compiled.py (a key of the tree's numbers,
taken before any code is generated).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..model.model import Model
from ..model.tree import KinematicTree
from .engine.compact_kernel import kernel_module
from .engine.tree_module import module_source, tree_key
from .joint_space import TreeDynamics, reported_rows
from .tree.applicable import TREE_PATH_BODIES, applicable_tree
from .tree.description import describe
from .tree.numbers import batch_shape


class RecursiveDynamics(TreeDynamics):
    """Compiled recursive dynamics of a tree, batched over leading axes (SI units).

    Every input is (..., n) (or (n,), broadcast against the others); outputs keep the batch
    shape. ``functions`` (lazy) is the NumericSystem over the same module (simulation).
    """

    backend = "recursive"
    kernel = "unrolled"  # the straight-line module of this tree (compact_kernel.py: "compact")

    def __init__(self, model: Model, tree: KinematicTree,
                 parameters: Mapping[str, float] | None = None):
        from ..compile import compiled

        names = tuple(p.name for p in model.parameters)
        self._take_tree(model, tree, parameters)
        self.parameter_values = np.array(list(self.parameters.values()), dtype=float)
        self.parameter_values.flags.writeable = False
        # exact: no fused multiply-adds, which the compiler places differently in the scalar
        # and the vector functions, so that a batch's row equals its state's single call bit
        # for bit (docs/robotics.md; with them Solo12's g differed in the last bit in 162 of
        # 400 states); 10-20% of an arm's ID and FD on one thread
        self.module = compiled.load_keyed(tree_key(tree, names),
                                          lambda: module_source(tree, names), native=True,
                                          exact=True)
        P = self.parameter_values
        m = self.module
        # The fast path: one C call each, the parameters bound here.
        self._mass, self._bias, self._gravity = m.mass_matrix, m.bias_forces, m.gravity
        self._inverse, self._forward = m.inverse_dynamics, m.forward_dynamics
        self._kinetic, self._potential = m.kinetic_energy, m.potential_energy
        self._P = P  # a floating base's quaternion: the module checks its norm (ValueError)

    def regular(self) -> bool:
        """Whether M is positive definite at a few random states (a massless branch is not)."""
        rng = np.random.default_rng(0)
        q = rng.uniform(-np.pi, np.pi, (3, self.nq))
        if self.tree.floating_base:
            q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
        try:
            np.linalg.cholesky(self.mass_matrix(q))
        except np.linalg.LinAlgError:
            return False
        return True

    def numeric_system(self):
        """The NumericSystem over this module (M, f = -b, energy, accelerations, rhs), as the
        symbolic path gives it; simulation uses it."""
        from ..compile.functions import CKernel, NumericSystem

        if self.tree.floating_base:
            from .recursive_numpy import floating_refusal

            raise floating_refusal()
        return NumericSystem(coordinates=self.coordinates, constraint_names=(),
                             constraint_kinds=(), parameters=dict(self.parameters),
                             _kernel=CKernel(self.module, self.parameter_values))

    def __repr__(self) -> str:
        return f"RecursiveDynamics(coordinates={list(self.coordinates)})"

    def _call(self, function, *arrays):
        """The slow path, after the module refused the fast one: every input checked here, in
        front (numbers, widths named by coordinate, a floating base's quaternions, broadcast
        batch shapes), then one C call; nothing read off the module's error text."""
        third = "tau" if function is self._forward else "a"
        fields = ("q", "v", third)[:len(arrays)]
        arrays = [self._vector(x, field) for x, field in zip(arrays, fields, strict=True)]
        if self.tree.floating_base:
            arrays[0] = _unit_quaternions(arrays[0])
        batch = batch_shape(arrays, fields)
        arrays = [np.ascontiguousarray(np.broadcast_to(x, batch + x.shape[-1:])) for x in arrays]
        return function(*arrays, self._P)

    def mass_matrix(self, q):
        """M(q), shape (..., n, n)."""
        try:
            out = self._mass(q, self._P)
        except (ValueError, TypeError):
            out = self._call(self._mass, q)
        return out if out.__class__ is not tuple else reported_rows(out, 2)

    def bias_forces(self, q, v):
        """C(q, q_dot) q_dot + g(q), shape (..., n)."""
        try:
            out = self._bias(q, v, self._P)
        except (ValueError, TypeError):
            out = self._call(self._bias, q, v)
        return out if out.__class__ is not tuple else reported_rows(out, 1)

    def gravity(self, q):
        """g(q), shape (..., n)."""
        try:
            out = self._gravity(q, self._P)
        except (ValueError, TypeError):
            out = self._call(self._gravity, q)
        return out if out.__class__ is not tuple else reported_rows(out, 1)

    def inverse_dynamics(self, q, v, a, f_ext=None):
        """tau = M a + C q_dot + g - sum J^T w, shape (..., n) (f_ext: wrenches.py)."""
        if f_ext is not None:  # wrenches at frames (wrenches.py)
            return self._with_wrenches(q, v, a, f_ext, forward=False)
        try:
            out = self._inverse(q, v, a, self._P)
        except (ValueError, TypeError):
            out = self._call(self._inverse, q, v, a)
        return out if out.__class__ is not tuple else reported_rows(out, 1)

    def forward_dynamics(self, q, v, tau, f_ext=None):
        """q_ddot = M^-1 (tau + sum J^T w - C q_dot - g), shape (..., n) (f_ext: wrenches.py)."""
        if f_ext is not None:  # wrenches at frames (wrenches.py)
            return self._with_wrenches(q, v, tau, f_ext, forward=True)
        try:
            out = self._forward(q, v, tau, self._P)
        except (ValueError, TypeError):
            out = self._call(self._forward, q, v, tau)
        return out if out.__class__ is not tuple else reported_rows(out, 1)

    def kinetic_energy(self, q, v):
        """T in J, shape (...)."""
        try:
            out = self._kinetic(q, v, self._P)
        except (ValueError, TypeError):
            out = self._call(self._kinetic, q, v)
        return out if out.__class__ is not tuple else reported_rows(out, 0)

    def potential_energy(self, q):
        """V in J, shape (...)."""
        try:
            out = self._potential(q, self._P)
        except (ValueError, TypeError):
            out = self._call(self._potential, q)
        return out if out.__class__ is not tuple else reported_rows(out, 0)


class CompactDynamics(RecursiveDynamics):
    """A tree's recursive dynamics on the compact kernel, batched over leading axes (SI units);
    the functions of recursive.RecursiveDynamics, the tree ``description`` their last argument."""

    kernel = "compact"

    def __init__(self, model: Model, tree: KinematicTree,
                 parameters: Mapping[str, float] | None = None):
        self._take_tree(model, tree, parameters)
        self.module = kernel_module()
        self.description = describe(tree, self.parameters)
        m, D = self.module, self.description
        self._mass, self._bias, self._gravity = m.mass_matrix, m.bias_forces, m.gravity
        self._inverse, self._forward = m.inverse_dynamics, m.forward_dynamics
        self._kinetic, self._potential = m.kinetic_energy, m.potential_energy
        self._P = D

    def __repr__(self) -> str:
        return f"CompactDynamics(coordinates={list(self.coordinates)})"

    def numeric_system(self):
        """The NumericSystem over this kernel (M, f = -b, energy, accelerations, rhs)."""
        from ..compile.functions import NumericSystem

        if self.tree.floating_base:  # q and v differ in length: simulate_floating steps it
            from .recursive_numpy import floating_refusal

            raise floating_refusal()
        return NumericSystem(coordinates=self.coordinates, constraint_names=(),
                             constraint_kinds=(), parameters=dict(self.parameters),
                             _kernel=_CompactKernel(self))


class _CompactKernel:
    """NumericSystem's kernel over the compact module (no constraints: m = 0)."""

    backend = "compact"  # not "c": the module has no DOP853 loop of its own (scipy steps)

    def __init__(self, dynamics: CompactDynamics):
        self.m, self.D, self.n = dynamics.module, dynamics.description, dynamics.n

    def _plain(self, out):
        return out[0] if out.__class__ is tuple else out

    def parts(self, Q, V, T):
        count = len(Q)
        return (self._plain(self.m.mass_matrix(Q, self.D)),
                -self._plain(self.m.bias_forces(Q, V, self.D)),
                np.zeros((count, 0, self.n)), np.zeros((count, 0)))

    def residual(self, Q, V, T):
        return np.zeros((len(Q), 0))

    def energy(self, Q, V, T):
        return (self._plain(self.m.kinetic_energy(Q, V, self.D))
                + self._plain(self.m.potential_energy(Q, self.D)))

    def accelerations(self, Q, V, T):
        qdd = self._plain(self.m.forward_dynamics(Q, V, np.zeros_like(Q), self.D))
        return qdd, np.zeros((len(Q), 0))

    def rhs(self, t, y):
        y = np.asarray(y, dtype=float)
        n = self.n
        if y.shape != (2 * n,):
            raise ValueError(f"y must hold {2 * n} numbers [q, q_dot]")
        qdd = self._plain(self.m.forward_dynamics(y[:n], y[n:], np.zeros(n), self.D))
        return np.concatenate([y[n:], qdd])


def _unit_quaternions(q) -> np.ndarray:
    """q with its base quaternions refused in one line (free_flyer.check_quaternions: which
    state, what norm), else q itself, with only the quaternions the module's own test would
    refuse (a norm within rounding of the tolerance) made unit: a unit one keeps its bits."""
    from .tree.free_flyer import QUATERNION_TOLERANCE, check_quaternions

    Q = np.asarray(q, dtype=float)
    flat = Q.reshape(-1, Q.shape[-1])
    check_quaternions(flat)
    norms = np.sqrt((flat[:, 3:7] ** 2).sum(axis=-1))
    edge = np.isfinite(flat).all(axis=-1) & ~(np.abs(norms - 1.0) <= QUATERNION_TOLERANCE)
    if not edge.any():
        return Q
    flat = flat.copy()
    flat[edge, 3:7] /= norms[edge, None]
    return flat.reshape(Q.shape)


__all__ = ["applicable_tree", "CompactDynamics", "RecursiveDynamics", "TREE_PATH_BODIES"]
