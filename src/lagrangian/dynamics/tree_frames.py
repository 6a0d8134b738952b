"""A URDF tree's side of Dynamics' frames and configuration space: its quaternions' checks, its
frames (frames.py) and their compiled kernel (reach_c.py), wrenches at frames, q (+) v on its
quaternions and its C(q, q_dot) factorization (coriolis_tree.py); mixed in first by
recursive.TreeDynamics and actuators.ActuatedDynamics, so that joint_space.Dynamics knows no
tree. Without a tree each step is the base class's (a model file's)."""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from functools import partial
from typing import TYPE_CHECKING

import numpy as np

from ..errors import DynamicsWarning
from .algorithms.frames import TreeKinematics, tree_kinematics
from .joint_space import Dynamics, reported_rows, undefined_rows

if TYPE_CHECKING:
    from .model_frames import ModelKinematics


class TreeFrames:
    """The tree's frames, quaternions and C (a mixin ahead of joint_space.Dynamics; SI units)."""

    def _check_quaternions(self, flat) -> None:
        """A floating base's quaternion, and the ball joints' (tree/spherical.py), each of norm 1
        in every row of flat (N, nq), else refused in one line."""
        tree = getattr(self, "tree", None)
        if tree is not None and tree.quaternion_joints:  # and the ball joints' (tree/spherical.py)
            from .tree.spherical import check_tree_quaternions

            check_tree_quaternions(tree, flat)
        else:
            from .tree.free_flyer import check_quaternions

            check_quaternions(flat)

    # -- frames, Jacobians and the centre of mass (a URDF robot's tree: frames.py) --------------

    @property
    def kinematics(self) -> TreeKinematics | ModelKinematics:
        """Placements, frame Jacobians and the centre of mass of the robot's kinematic tree
        (refused in one line for a model without one)."""
        return super().kinematics

    def _frames_source(self):
        """A URDF tree's frames (frames.py), else a model file's points and bodies from its own
        expressions (model_frames.py), at this object's parameter values."""
        tree = getattr(self, "tree", None)
        if tree is not None and tree.frames:
            return tree_kinematics(tree)
        return super()._frames_source()

    def placement(self, q, frame: str) -> np.ndarray:
        """The frame's 4 x 4 placement in the world (rotation and origin in m), (..., 4, 4)."""
        fast = self._reach
        if fast is None:
            fast = self._reach_kernel()
        if fast:  # NotImplemented: numpy below names the fault in one line
            out = fast.placement(q, frame)
            if out is not NotImplemented:
                return out if out.__class__ is not tuple else reported_rows(out, 2)
        return undefined_rows(self.kinematics.placement, (q, frame), (q,), 2)

    def jacobian(self, q, frame: str, reference: str = "local_world_aligned") -> np.ndarray:
        """The frame's 6 x n Jacobian, linear rows first, (..., 6, n); ``reference`` "world",
        "local" or "local_world_aligned" as Pinocchio's ReferenceFrame."""
        fast = self._reach
        if fast is None:
            fast = self._reach_kernel()
        if fast:  # NotImplemented: numpy below names the fault in one line
            out = fast.jacobian(q, frame, reference)
            if out is not NotImplemented:
                return out if out.__class__ is not tuple else reported_rows(out, 2)
        return undefined_rows(self.kinematics.jacobian, (q, frame, reference), (q,), 2)

    def center_of_mass(self, q) -> np.ndarray:
        """The moving bodies' centre of mass in the world (m), (..., 3)."""
        fast = self._reach if self._reach is not None else self._reach_kernel()
        if fast and fast.center_of_mass is not None:  # None: no moving mass (numpy refuses)
            out = fast.center_of_mass(q)
            if out is not NotImplemented:
                return out if out.__class__ is not tuple else reported_rows(out, 1)
        return undefined_rows(self.kinematics.center_of_mass, (q,), (q,), 1)

    def center_of_mass_jacobian(self, q) -> np.ndarray:
        """J_c with c_dot = J_c q_dot, (..., 3, n)."""
        fast = self._reach if self._reach is not None else self._reach_kernel()
        if fast and fast.center_of_mass_jacobian is not None:
            out = fast.center_of_mass_jacobian(q)
            if out is not NotImplemented:
                return out if out.__class__ is not tuple else reported_rows(out, 2)
        return undefined_rows(self.kinematics.center_of_mass_jacobian, (q,), (q,), 2)

    def jacobian_dot_times_v(self, q, v, frame: str,
                             reference: str = "local_world_aligned") -> np.ndarray:
        """J_dot q_dot: the frame's classical acceleration at q_ddot = 0 (m/s^2, rad/s^2),
        (..., 6), as Pinocchio's getFrameClassicalAcceleration with a = 0."""
        fast = self._reach if self._reach is not None else self._reach_kernel()
        if fast:  # NotImplemented: numpy below broadcasts, or names the fault in one line
            out = fast.drift(q, v, frame, reference)
            if out is not NotImplemented:
                return out if out.__class__ is not tuple else reported_rows(out, 1)
        return undefined_rows(self.kinematics.jacobian_dot_times_v, (q, v, frame, reference),
                              (q, v), 1)

    def centroidal_momentum_matrix(self, q) -> np.ndarray:
        """A_g with h_g = A_g q_dot (linear, then angular momentum about the centre of mass,
        world axes), (..., 6, n), as Pinocchio's ccrba."""
        fast = self._reach
        if fast is None:
            fast = self._reach_kernel()
        if fast and fast.centroidal is not None:  # None: no moving mass (numpy refuses)
            out = fast.centroidal(q)
            if out is not NotImplemented:
                return out if out.__class__ is not tuple else reported_rows(out, 2)
        return undefined_rows(self.kinematics.centroidal_momentum_matrix, (q,), (q,), 2)

    # the compiled kernel of the functions above (reach_c.py): None until asked, then
    # the kernel, or False (not the C backend, or no compiler)
    _reach = None

    def _reach_kernel(self):
        self._reach = False
        if getattr(self, "backend", None) in ("recursive", "compact"):  # compiled C backends
            from .engine.reach_c import ReachKernel, reach_module

            module = reach_module(self.tree)
            if module is not None:
                self._reach = ReachKernel(module, self.tree, self.kinematics.mass() > 0)
        return self._reach

    def _with_wrenches(self, q, v, x, f_ext, forward: bool) -> np.ndarray:
        """Inverse or forward dynamics with wrenches at frames: tau_ext = sum J^T w
        (wrenches.py) taken from tau, or added to it; in compiled C where it can be."""
        fast = self._reach if self._reach is not None else self._reach_kernel()
        # the compiled way where it takes the inputs (NotImplemented: the numpy way below
        # broadcasts, or names the fault in one line)
        if fast and isinstance(f_ext, Mapping):
            if forward:  # a state not finite leaves NaN in tau, and forward dynamics warns
                if x.__class__ is np.ndarray and x.dtype.kind in "fiu":
                    tau = np.array(x, dtype=float)  # our own copy, added to in place
                    if fast.add_wrenches(q, f_ext, tau, 1.0) is not NotImplemented:
                        return self.forward_dynamics(q, v, tau)
            else:
                one_pass = fast.inverse if fast.inverse is not None else fast.fused_inverse(self)
                # one Newton-Euler pass (reach_inverse.c, on vector lanes over a batch) for a
                # floating base or a few states; over many states of a fixed base the tree
                # module's unrolled ID and then J^T w are the faster (measured: benchmarks.md)
                if one_pass and (self.velocity_names is not None or q.__class__ is not np.ndarray
                                 or q.ndim < 2 or len(q) <= 64):
                    out = one_pass(q, v, x, f_ext)
                    if out is not NotImplemented:
                        return out if out.__class__ is not tuple else reported_rows(out, 1, 5)
                else:
                    with warnings.catch_warnings():  # counted once, with the wrenches' states
                        warnings.simplefilter("ignore", DynamicsWarning)
                        tau = np.array(self.inverse_dynamics(q, v, x), dtype=float)
                    # the count of rows NaN after the last wrench (made NaN whole): the batch's
                    bad = fast.add_wrenches(q, f_ext, tau, -1.0)
                    if bad is not NotImplemented:
                        return reported_rows((tau, bad) if bad else tau, 1, 5)
        inputs = (q, v, x, *f_ext.values()) if isinstance(f_ext, Mapping) else (q, v, x)
        return undefined_rows(self._wrenches_numpy, (q, v, x, f_ext, forward), inputs, 1, 5)

    # -- the configuration space: a floating base's is a manifold (free_flyer.py) ---------------

    def _integrate_rows(self, Q, V) -> np.ndarray:
        """Q (+) V over rows (N, nq), (N, nv): a floating base along its twist, each ball joint
        by q exp(w dt), the joints by q + v dt."""
        if self.velocity_names is None:
            return super()._integrate_rows(Q, V)
        tree = getattr(self, "tree", None)
        if tree is not None and tree.quaternion_joints:  # each ball turned by exp(w dt) (spherical.py)
            from .tree.spherical import check_tree_quaternions, integrate_tree

            check_tree_quaternions(tree, Q)
            return integrate_tree(tree, Q, V)
        from .tree.free_flyer import check_quaternions, integrate

        check_quaternions(Q)
        return integrate(Q, V)

    def _difference_rows(self, Q0, Q1) -> np.ndarray:
        """V with Q0 (+) V = Q1 over rows (N, nq) each, (N, nv)."""
        if self.velocity_names is None:
            return super()._difference_rows(Q0, Q1)
        tree = getattr(self, "tree", None)
        if tree is not None and tree.quaternion_joints:
            from .tree.spherical import check_tree_quaternions, difference_tree

            check_tree_quaternions(tree, Q0, "q0")
            check_tree_quaternions(tree, Q1, "q1")
            return difference_tree(tree, Q0, Q1)
        from .tree.free_flyer import check_quaternions, difference

        check_quaternions(Q0)
        check_quaternions(Q1)
        return difference(Q0, Q1)

    def coriolis_matrix(self, q, v) -> np.ndarray:
        if self.velocity_names is not None:  # quasi-velocities: Pinocchio's factorization
            fast = self._reach if self._reach is not None else self._reach_kernel()
            if fast and fast.coriolis is not None:  # compiled (reach_kernel.c)
                out = fast.coriolis(q, v)  # NotImplemented: numpy below names the fault
                if out is not NotImplemented:
                    return out if out.__class__ is not tuple else reported_rows(out, 2)
            from .algorithms.coriolis_tree import coriolis_matrix

            # partial, not a lambda: a closure over self would slow the compiled path above
            return self._guarded(partial(coriolis_matrix, self.kinematics), (q, v),
                                 ("q", "v"), (self.n, self.n))
        self._require_christoffel()
        fast = self._reach if self._reach is not None else self._reach_kernel()
        if fast:  # a fixed tree's C by the same factorization, compiled, where checked equal
            compiled = fast.fixed_coriolis
            if compiled is None:
                compiled = fast.checked_coriolis(self)
            if compiled:
                out = compiled(q, v)  # NotImplemented: numpy below names the fault
                if out is not NotImplemented:
                    return out if out.__class__ is not tuple else reported_rows(out, 2)
        return self._guarded(self._christoffel_coriolis, (q, v), ("q", "v"), (self.n, self.n))

    coriolis_matrix.__doc__ = Dynamics.coriolis_matrix.__doc__


__all__ = ["TreeFrames"]
