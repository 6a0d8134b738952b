"""Recursive rigid-body dynamics of a robot's kinematic tree (model/tree.py): one TreeDynamics,
the front that checks and shapes every input once, over a backend (backends.py: the engine, a
tree's unrolled module, or the numpy reference).

The unrolled module's text (engine/tree_module.py): instead of expanding the equations of motion
(whose size grows much faster than the number of bodies), the generated code keeps the
recursions over the tree, unrolled body by body with the joint axes, placements and inertias as
numbers (zeros and ones folded away, common terms shared):

- inverse dynamics by recursive Newton-Euler: tau = M(q) a + C(q, q_dot) q_dot + g(q);
- the mass matrix by the composite-rigid-body algorithm;
- forward dynamics by the articulated-body algorithm, O(n), or M = L L^T, whichever takes
  fewer operations (Cholesky only with mimic joints; a ball joint's or a free flyer's D = S^T IA S
  3 x 3 or 6 x 6);
- sin and cos of each joint angle once, by inline kernels (fdlibm's polynomials after a
  three-part reduction by pi/2, libm beyond |x| = 1e5): a libm call costs as much as the rest
  of the mass matrix of a 7-joint arm;
- kinetic energy 1/2 sum (m v.v + 2 v.(w x h) + w.J_O w), potential energy m g height.

A floating base (free_flyer.py) takes q of nq = n + 7 numbers and v, a, tau of nv = n + 6 (the
module's RT_NQ and LG_N), and a ball joint 4 in q and 3 in v (a free flyer below the root 7
and 6); every quaternion's norm is checked before the C call, the C uses its unit rotation.

Units SI. Gravity g (a runtime parameter) along the tree's direction; each coordinate's actuator
parameter tau_<joint> acts as a load, as in the symbolic equations (b = C q_dot + g - tau_p).
The same functions are written as standalone C99 (standalone.py) and, with the Python bindings
below and template.c, as a compiled module cached by compiled.py (a key of the tree's numbers,
taken before any code is generated).
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import partial

import numpy as np

from ..model.model import Model
from ..model.tree import KinematicTree
from ..model.values import resolve_parameters
from .algorithms.recursions import _positive_definite
from .backends import CompiledBackend, TreeBackend, compiled_backend
from .joint_space import Dynamics, reported_rows
from .recursive_numpy import NumpyBackend, floating_refusal
from .tree.applicable import TREE_PATH_BODIES, applicable_tree
from .tree.numbers import batch_shape
from .tree.spherical import check_tree_quaternions, quaternion_slices, refuse_spherical, unit_ball_quaternions
from .tree_terms import TreeTerms

BACKENDS = {"compact": "recursive", "unrolled": "recursive", "numpy": "recursive-numpy"}
# each recursion's axes of one state's output
_TAILS = {"mass_matrix": 2, "bias_forces": 1, "gravity": 1, "inverse_dynamics": 1,
          "forward_dynamics": 1, "kinetic_energy": 0, "potential_energy": 0}


class TreeDynamics(TreeTerms, Dynamics):
    """A tree's recursive dynamics over one backend, batched over leading axes (SI units).

    Every input is (..., n) (or (n,), broadcast against the others); outputs keep the batch
    shape. ``kernel``: "compact" (the engine: one compiled module for every tree), "unrolled"
    (the tree's own module, compiled once per tree) or "numpy" (the reference recursions).
    """

    _christoffel = True  # a tree's only velocity terms are M's (no dampers in the tree)

    def __init__(self, model: Model, tree: KinematicTree,
                 parameters: Mapping[str, float] | None = None, kernel: str = "compact"):
        values = resolve_parameters(model, parameters)
        self.model, self.tree = model, tree
        self.coordinates = tree.coordinates
        self.n = len(tree.coordinates)
        if tree.quaternion_joints:  # a ball joint: 4 numbers in q, 3 in v; a free flyer 7 and 6
            self.velocity_names = tree.velocity_coordinates
            self.n = len(tree.velocity_coordinates)
        if tree.floating_base:  # Pinocchio's layout: the base's numbers first (free_flyer.py)
            from .tree.free_flyer import BASE_CONFIGURATION, BASE_VELOCITY

            self.coordinates = BASE_CONFIGURATION + tree.coordinates
            self.velocity_names = BASE_VELOCITY + tree.velocity_coordinates
            self.n += 6
        self.parameters = {p.name: float(v)
                           for p, v in zip(model.parameters, values.values, strict=True)}
        names = tuple(p.name for p in model.parameters)
        self.recursions: TreeBackend = (
            NumpyBackend(tree, self.parameters, self.n) if kernel == "numpy"
            else compiled_backend(tree, self.parameters, names, kernel))
        self.kernel, self.backend = kernel, BACKENDS[kernel]
        b = self.recursions
        # the fast path: one call each into the backend, its tables bound here
        self._mass, self._bias, self._gravity = b.mass_matrix, b.bias_forces, b.gravity
        self._inverse, self._forward = b.inverse_dynamics, b.forward_dynamics
        self._kinetic, self._potential = b.kinetic_energy, b.potential_energy
        self._P = b.tables
        if isinstance(b, CompiledBackend) and type(self) is TreeDynamics:
            # each recursion's method the module's call itself, its tables bound: no Python
            # frame in front of the kernel; the class's method (checks, shapes) its fallback
            for name, tail in _TAILS.items():
                bound = b.bound(name, getattr(self, name), partial(reported_rows, tail=tail,
                                                                   stacklevel=3))
                if bound is not None:
                    setattr(self, name, bound)

    @property
    def module(self):
        """The compiled module (None on the numpy backend)."""
        return getattr(self.recursions, "module", None)

    @property
    def description(self):
        """The engine's description D of this tree (tree/description.py; kernel "compact")."""
        return getattr(self.recursions, "description", None)

    def regular(self) -> bool:
        """Whether M is positive definite at a few random states (a massless branch is not)."""
        rng = np.random.default_rng(0)
        q = rng.uniform(-np.pi, np.pi, (3, self.nq))
        if self.tree.floating_base:
            q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
        for _, _, iq, _ in quaternion_slices(self.tree):
            q[:, iq:iq + 4] /= np.linalg.norm(q[:, iq:iq + 4], axis=-1, keepdims=True)
        return all(_positive_definite(m) for m in self.mass_matrix(q))

    def numeric_system(self):
        """The NumericSystem over this backend (M, f = -b, energy, accelerations, rhs), as the
        symbolic path gives it; simulation uses it."""
        from ..compile.functions import NumericSystem

        if self.tree.floating_base:  # q and v differ in length: simulate_floating steps it
            raise floating_refusal()
        refuse_spherical(self.tree, "simulate and the equations' numeric functions (q_dot = v)")
        return NumericSystem(coordinates=self.coordinates, constraint_names=(),
                             constraint_kinds=(), parameters=dict(self.parameters),
                             _kernel=self.recursions.numeric_kernel(self.n))

    def __repr__(self) -> str:
        return f"TreeDynamics(kernel={self.kernel!r}, coordinates={list(self.coordinates)})"

    def _call(self, function, *arrays):
        """The checked path, where the backend answered NotImplemented: every input checked
        here, in front (numbers, widths named by coordinate, a floating base's quaternions,
        broadcast batch shapes), then the backend again."""
        third = "tau" if function is self._forward else "a"
        fields = ("q", "v", third)[:len(arrays)]
        arrays = [self._vector(x, field) for x, field in zip(arrays, fields, strict=True)]
        if self.tree.floating_base:
            arrays[0] = _unit_quaternions(arrays[0])
        if self.tree.quaternion_joints:  # each one's: refused in one line naming it, or unit
            Q = np.asarray(arrays[0], dtype=float)
            flat = Q.reshape(-1, Q.shape[-1])
            check_tree_quaternions(self.tree, flat)
            arrays[0] = unit_ball_quaternions(self.tree, flat).reshape(Q.shape)
        batch = batch_shape(arrays, fields)
        arrays = [np.ascontiguousarray(np.broadcast_to(x, batch + x.shape[-1:]), dtype=float)
                  for x in arrays]
        out = function(*arrays, self._P)
        if out is NotImplemented:  # the front's checks are the backend's: a defect here
            raise RuntimeError(f"the {self.kernel} backend refused inputs its front checked")
        return out

    def mass_matrix(self, q):
        """M(q), shape (..., n, n)."""
        out = self._mass(q, self._P)
        if out is NotImplemented:
            out = self._call(self._mass, q)
        return out if out.__class__ is not tuple else reported_rows(out, 2)

    def bias_forces(self, q, v):
        """C(q, q_dot) q_dot + g(q), shape (..., n)."""
        out = self._bias(q, v, self._P)
        if out is NotImplemented:
            out = self._call(self._bias, q, v)
        return out if out.__class__ is not tuple else reported_rows(out, 1)

    def gravity(self, q):
        """g(q), shape (..., n)."""
        out = self._gravity(q, self._P)
        if out is NotImplemented:
            out = self._call(self._gravity, q)
        return out if out.__class__ is not tuple else reported_rows(out, 1)

    def inverse_dynamics(self, q, v, a, f_ext=None):
        """tau = M a + C q_dot + g - sum J^T w, shape (..., n) (f_ext: wrenches.py)."""
        if f_ext is not None:  # wrenches at frames (wrenches.py)
            return self._with_wrenches(q, v, a, f_ext, forward=False)
        out = self._inverse(q, v, a, self._P)
        if out is NotImplemented:
            out = self._call(self._inverse, q, v, a)
        return out if out.__class__ is not tuple else reported_rows(out, 1)

    def forward_dynamics(self, q, v, tau, f_ext=None):
        """q_ddot = M^-1 (tau + sum J^T w - C q_dot - g), shape (..., n); NaN where M is not
        positive definite (f_ext: wrenches.py)."""
        if f_ext is not None:  # wrenches at frames (wrenches.py)
            return self._with_wrenches(q, v, tau, f_ext, forward=True)
        out = self._forward(q, v, tau, self._P)
        if out is NotImplemented:
            out = self._call(self._forward, q, v, tau)
        return out if out.__class__ is not tuple else reported_rows(out, 1)

    def kinetic_energy(self, q, v):
        """T in J, shape (...)."""
        out = self._kinetic(q, v, self._P)
        if out is NotImplemented:
            out = self._call(self._kinetic, q, v)
        return out if out.__class__ is not tuple else reported_rows(out, 0)

    def potential_energy(self, q):
        """V in J, shape (...)."""
        out = self._potential(q, self._P)
        if out is NotImplemented:
            out = self._call(self._potential, q)
        return out if out.__class__ is not tuple else reported_rows(out, 0)


def _unit_quaternions(q) -> np.ndarray:
    """q with its base quaternions refused in one line (free_flyer.check_quaternions: which
    state, what norm), else q itself, with only the quaternions the backend's own test would
    refuse (a norm within rounding of the tolerance) made unit: a unit one keeps its bits."""
    from .tree.free_flyer import QUATERNION_TOLERANCE, check_quaternions

    Q = np.asarray(q, dtype=float)
    flat = Q.reshape(-1, Q.shape[-1])
    check_quaternions(flat)
    with np.errstate(over="ignore", invalid="ignore"):  # a state beyond 1e154: its NaN row
        norms = np.sqrt((flat[:, 3:7] ** 2).sum(axis=-1))
    edge = np.isfinite(flat).all(axis=-1) & ~(np.abs(norms - 1.0) <= QUATERNION_TOLERANCE)
    if not edge.any():
        return Q
    flat = flat.copy()
    flat[edge, 3:7] /= norms[edge, None]
    return flat.reshape(Q.shape)


__all__ = ["BACKENDS", "TREE_PATH_BODIES", "TreeDynamics", "applicable_tree"]
