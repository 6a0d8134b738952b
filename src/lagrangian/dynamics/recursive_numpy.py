"""Recursive rigid-body dynamics of a robot's kinematic tree (model/tree.py) in numpy: the
reference recursions as a backend (backends.py) of recursive.TreeDynamics, where no C compiler
works, or backend "numpy".

The same algorithms over the same tree, each body's quantities an array over a flat batch of
states (N, 3) or (N, 3, 3), the bodies visited in Python:

- inverse dynamics by recursive Newton-Euler: tau = M(q) a + C(q, q_dot) q_dot + g(q);
- the mass matrix by the composite-rigid-body algorithm;
- forward dynamics by M = L L^T (Cholesky, also with mimic joints): q_ddot = M^-1 (tau - b);
- kinetic energy 1/2 sum (m v.v + 2 v.(w x h) + w.J_O w), potential energy m g height.

A floating base (a free flyer at the root, free_flyer.py) takes q of nq = n + 7 numbers and v, a,
tau of nv = n + 6: its body moves by its own twist, and its share of tau is the wrench on it. A
ball joint (tree/spherical.py) has 4 numbers in q (w x y z) and 3 in v (its body's angular
velocity in its own axes): its share of tau is the moment on its body. A free flyer below the
root (a URDF floating joint between two links) has 7 numbers in q (x y z in its parent's joint
frame, qx qy qz qw) and 6 in v (its body's twist relative to its parent, linear then angular, in
its own axes), as Pinocchio's JointModelFreeFlyer: its share of tau is the wrench on its body.

Unlike the fully expanded equations (whose lambdified expression trees grow too deep for a
7-joint arm), the cost grows with the number of bodies (CRBA: with bodies x depth). Units SI;
gravity g and the actuator parameters tau_<joint> as in recursive.py (b = C q_dot + g - tau_p).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..errors import ModelError
from ..model.quaternions import QUATERNION_TOLERANCE
from ..model.tree import KinematicTree
from .algorithms.recursions import TreeRecursions, _Joint, _TreeKernel
from .tree.description import describe, joints_of
from .tree.numbers import over_finite_rows, solve_positive
from .tree.spherical import ball_quaternions_unit


class NumpyBackend(TreeRecursions):
    """The tree's recursions in numpy over flat batches (backends.py's contract, SI units)."""

    kernel = "numpy"
    tables = None

    def __init__(self, tree: KinematicTree, parameters: Mapping[str, float], nv: int,
                 own_frames: bool = False):
        self.tree, self.n = tree, nv
        missing = [name for name in (tree.gravity_parameter, *tree.actuators)
                   if name is not None and name not in parameters]
        if missing:
            raise ModelError(f"the tree's parameters {missing} are not the model's")
        self._g = parameters.get(tree.gravity_parameter, 0.0)  # None: no gravity
        self._actuators = np.array([0.0] * tree.base_nv  # no actuator drives a floating base
                                   + [parameters.get(a, 0.0) for a in tree.actuators],
                                   dtype=float)
        # the ground accelerates up by g: every body feels gravity (Newton-Euler's trick)
        self._up = -self._g * np.array(tree.gravity_direction, dtype=float)
        # the bodies as the engine reads them (tree/description.py): one description; a
        # floating base (a joint that description does not turn) and a free flyer below the
        # root (one the engine does not take: selection.py) from the tree itself
        # own_frames: each body in its joint's own frame (the regressor's parameters are
        # about it), not the description's canonical axes
        joints = (tree.joints if own_frames or tree.floating_base or tree.free_joints
                  else joints_of(describe(tree, parameters)))
        self._joints = [_Joint(j, tree) for j in joints]
        self._widths = (tree.nq, nv, nv)

    def _rows(self, compute, arrays, tail: tuple[int, ...], forward: bool = False):
        """compute(*flat (N, width)) over the finite states, NaN rows for the rest (and for
        forward dynamics, for rows without a finite answer): the outputs, or (outputs, count);
        NotImplemented for inputs the front has not handed on."""
        flat = self._handed_on(arrays)
        if flat is None:
            return NotImplemented
        batch, flat = flat
        out, good = over_finite_rows(compute, flat, tail, forward)
        bad = len(good) - int(good.sum())
        out = out.reshape(batch + tail)
        return (out, bad) if bad else out

    def _handed_on(self, arrays):
        """(batch shape, flat inputs) for float64 C-ordered inputs of the tree's widths, one
        batch shape (a single state broadcast) and unit base quaternions; else None."""
        shape = None
        for x, width in zip(arrays, self._widths, strict=False):
            if x.__class__ is not np.ndarray or x.dtype != np.float64 or x.ndim == 0 \
                    or not x.flags.c_contiguous or x.shape[-1] != width:
                return None
            if x.ndim > 1 or len(arrays) == 1:
                if shape is not None and x.shape[:-1] != shape:
                    return None
                shape = x.shape[:-1]
        shape = () if shape is None else shape
        total = int(np.prod(shape, dtype=np.int64))
        flat = [np.broadcast_to(x, shape + x.shape[-1:]).reshape(total, x.shape[-1])
                for x in arrays]
        if self.tree.floating_base:
            Q = flat[0]
            norms = np.sqrt((Q[:, 3:7] ** 2).sum(axis=-1))
            if (np.isfinite(Q).all(axis=-1) & ~(np.abs(norms - 1.0) <= QUATERNION_TOLERANCE)).any():
                return None
        if self.tree.quaternion_joints and not ball_quaternions_unit(self.tree, flat[0]):
            return None
        return shape, flat

    def mass_matrix(self, q, tables=None):
        return self._rows(self._composite_rigid_body, (q,), (self.n, self.n))

    def bias_forces(self, q, v, tables=None):
        return self._rows(lambda Q, V: self._newton_euler(Q, V, None), (q, v), (self.n,))

    def gravity(self, q, tables=None):
        return self._rows(lambda Q: self._newton_euler(Q, None, None), (q,), (self.n,))

    def inverse_dynamics(self, q, v, a, tables=None):
        return self._rows(self._newton_euler, (q, v, a), (self.n,))

    def forward_dynamics(self, q, v, tau, tables=None):
        return self._rows(lambda Q, V, TAU: solve_positive(
            self._composite_rigid_body(Q), TAU - self._newton_euler(Q, V, None)),
            (q, v, tau), (self.n,), forward=True)

    def kinetic_energy(self, q, v, tables=None):
        return self._rows(self._kinetic, (q, v), ())

    def potential_energy(self, q, tables=None):
        return self._rows(self._potential, (q,), ())

    def numeric_kernel(self, n: int):
        """NumericSystem's kernel over these recursions (simulation)."""
        return _TreeKernel(self)


def floating_refusal() -> ModelError:
    """Why a floating base has no NumericSystem (simulate)."""
    return ModelError("simulate and the equations' numeric functions integrate q_dot = v; a "
                      "floating base's configuration holds a quaternion (nq = n + 7, nv = n + 6): "
                      "use dynamics() and its integrate(q, v, dt)")


__all__ = ["NumpyBackend", "floating_refusal"]
