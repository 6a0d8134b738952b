"""Recursive rigid-body dynamics of a robot's kinematic tree (model/tree.py) in numpy: the
fallback of recursive.py's generated C where no C compiler works, or backend "numpy".

The same algorithms over the same tree, each body's quantities an array over a flat batch of
states (N, 3) or (N, 3, 3), the bodies visited in Python:

- inverse dynamics by recursive Newton-Euler: tau = M(q) a + C(q, q_dot) q_dot + g(q);
- the mass matrix by the composite-rigid-body algorithm;
- forward dynamics by M = L L^T (Cholesky, also with mimic joints): q_ddot = M^-1 (tau - b);
- kinetic energy 1/2 sum (m v.v + 2 v.(w x h) + w.J_O w), potential energy m g height.

A floating base (a free flyer at the root, free_flyer.py) takes q of nq = n + 7 numbers and v, a,
tau of nv = n + 6: its body moves by its own twist, and its share of tau is the wrench on it.

Unlike the fully expanded equations (whose lambdified expression trees grow too deep for a
7-joint arm), the cost grows with the number of bodies (CRBA: with bodies x depth). Units SI;
gravity g and the actuator parameters tau_<joint> as in recursive.py (b = C q_dot + g - tau_p).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..errors import ModelError
from ..model.model import Model
from ..model.tree import KinematicTree
from .algorithms.recursions import TreeRecursions, _Joint, _positive_definite, _TreeKernel
from .joint_space import TreeDynamics, solve_positive
from .tree.description import describe, joints_of


class RecursiveNumpyDynamics(TreeRecursions, TreeDynamics):
    """Recursive dynamics of a tree in numpy, batched over leading axes (SI units).

    Every input is (..., n) (or (n,), broadcast against the others); outputs keep the batch
    shape. Same interface as recursive.RecursiveDynamics.
    """

    backend = "recursive-numpy"

    def __init__(self, model: Model, tree: KinematicTree,
                 parameters: Mapping[str, float] | None = None):
        self._take_tree(model, tree, parameters)
        missing = [name for name in (tree.gravity_parameter, *tree.actuators)
                   if name is not None and name not in self.parameters]
        if missing:
            raise ModelError(f"the tree's parameters {missing} are not the model's")
        self._g = self.parameters.get(tree.gravity_parameter, 0.0)  # None: no gravity
        self._actuators = np.array([0.0] * tree.base_nv  # no actuator drives a floating base
                                   + [self.parameters.get(a, 0.0) for a in tree.actuators],
                                   dtype=float)
        # the ground accelerates up by g: every body feels gravity (Newton-Euler's trick)
        self._up = -self._g * np.array(tree.gravity_direction, dtype=float)
        # the bodies as the compact C kernel reads them (compact_kernel.describe): one
        # description; a floating base (a joint that kernel does not take) from the tree itself
        joints = tree.joints if tree.floating_base else joints_of(describe(tree, self.parameters))
        self._joints = [_Joint(j, tree) for j in joints]

    def __repr__(self) -> str:
        return f"RecursiveNumpyDynamics(coordinates={list(self.coordinates)})"

    # -- the public functions --------------------------------------------------------------------

    def regular(self) -> bool:
        """Whether M is positive definite at a few random states (a massless branch is not)."""
        rng = np.random.default_rng(0)
        q = rng.uniform(-np.pi, np.pi, (3, self.nq))
        if self.tree.floating_base:
            q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
        return all(_positive_definite(m) for m in self.mass_matrix(q))

    def mass_matrix(self, q):
        """M(q), shape (..., n, n)."""
        return self._guarded(self._composite_rigid_body, (q,), ("q",), (self.n, self.n))

    def bias_forces(self, q, v):
        """C(q, q_dot) q_dot + g(q), shape (..., n)."""
        return self._guarded(lambda Q, V: self._newton_euler(Q, V, None), (q, v), ("q", "v"),
                             (self.n,))

    def gravity(self, q):
        """g(q), shape (..., n)."""
        return self._guarded(lambda Q: self._newton_euler(Q, None, None), (q,), ("q",),
                             (self.n,))

    def inverse_dynamics(self, q, v, a, f_ext=None):
        """tau = M a + C q_dot + g - sum J^T w, shape (..., n) (f_ext: wrenches.py)."""
        if f_ext is not None:  # wrenches at frames (wrenches.py)
            return self._with_wrenches(q, v, a, f_ext, forward=False)
        return self._guarded(self._newton_euler, (q, v, a), ("q", "v", "a"), (self.n,))

    def forward_dynamics(self, q, v, tau, f_ext=None):
        """q_ddot = M^-1 (tau + sum J^T w - C q_dot - g), shape (..., n); NaN where M is not
        positive definite (f_ext: wrenches.py)."""
        if f_ext is not None:  # wrenches at frames (wrenches.py)
            return self._with_wrenches(q, v, tau, f_ext, forward=True)
        return self._guarded(lambda Q, V, TAU: solve_positive(
            self._composite_rigid_body(Q), TAU - self._newton_euler(Q, V, None)),
            (q, v, tau), ("q", "v", "tau"), (self.n,), forward=True)

    def kinetic_energy(self, q, v):
        """T in J, shape (...)."""
        return self._guarded(self._kinetic, (q, v), ("q", "v"), ())

    def potential_energy(self, q):
        """V in J, shape (...)."""
        return self._guarded(self._potential, (q,), ("q",), ())

    def numeric_system(self):
        """The NumericSystem over these functions (M, f = -b, energy, accelerations, rhs), as
        the symbolic path gives it; simulation uses it."""
        from ..compile.functions import NumericSystem

        if self.tree.floating_base:
            raise floating_refusal()
        return NumericSystem(coordinates=self.coordinates, constraint_names=(),
                             constraint_kinds=(), parameters=dict(self.parameters),
                             _kernel=_TreeKernel(self))


def floating_refusal() -> ModelError:
    """Why a floating base has no NumericSystem (simulate)."""
    return ModelError("simulate and the equations' numeric functions integrate q_dot = v; a "
                      "floating base's configuration holds a quaternion (nq = n + 7, nv = n + 6): "
                      "use dynamics() and its integrate(q, v, dt)")


__all__ = ["RecursiveNumpyDynamics"]
