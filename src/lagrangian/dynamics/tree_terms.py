"""A URDF tree's side of Dynamics' control terms: its compiled derivatives (derivatives_c.py),
its regressor over the bodies' inertial parameters (regressor.py), the complex step through the
numpy reference's Newton-Euler (derivatives.py), on top of its frames (tree_frames.py); mixed in
first by recursive.TreeDynamics and actuators.ActuatedDynamics, so that joint_space.Dynamics and
control_terms.ControlTerms know no tree. Without a tree each step is the base class's."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import partial
from typing import NamedTuple

import numpy as np

from ..errors import InputError
from .control_terms import ControlTerms, _side_by_side
from .regressor import tree_parameter_names, tree_parameters, tree_regressor
from .tree_frames import TreeFrames


class DerivativesKernel(NamedTuple):
    """A tree's compiled derivatives (derivatives_c.py): each function takes (Q, V, X, P) and
    answers NotImplemented for inputs it does not take (widths, batch shapes, a quaternion off
    unit norm); the checked ones name the state and the norm in one line first (the guarded
    way)."""

    inverse: Callable
    forward: Callable
    regressor: Callable
    P: np.ndarray
    checked_inverse: Callable
    checked_regressor: Callable


class TreeTerms(TreeFrames):
    """A tree's derivatives, regressor and frames (a mixin ahead of joint_space.Dynamics)."""

    def _regressor_of(self, parameters: Sequence[str] | None):
        tree = getattr(self, "tree", None)
        if tree is None:
            return super()._regressor_of(parameters)
        if parameters is not None:
            raise InputError("a robot's regressor is over its bodies' 10 inertial "
                             "parameters each; parameters=[...] is for model files",
                             field="parameters")
        # compiled C (derivatives_c.py) where a compiler works, else numpy
        fast = self._derivatives_kernel()
        if fast is not None:
            compute, P = fast.checked_regressor, fast.P
            return (lambda Q, V, A: compute(Q, V, A, P),
                    tree_parameter_names(tree), tree_parameters(tree))
        recursions = self.__dict__.get("_regressor_recursions")
        if recursions is None:  # once per dynamics: the bodies in their own joint frames
            from .recursive_numpy import NumpyBackend

            recursions = NumpyBackend(tree, self.parameters, self.n, own_frames=True)
            self.__dict__["_regressor_recursions"] = recursions
        return (lambda Q, V, A: tree_regressor(recursions, Q, V, A),
                tree_parameter_names(tree), tree_parameters(tree))

    def regressor(self, q, v, a, parameters: Sequence[str] | None = None) -> np.ndarray:
        fast = self._derivatives_kernel() if parameters is None else None
        if fast is not None:  # one C call; NotImplemented: the guarded way names the fault
            out = fast.regressor(q, v, a, fast.P)
            if out is not NotImplemented:
                return out if out.__class__ is not tuple else _reported(out)[0]
        compute, names, _ = self._regressor_of(parameters)  # as the base's: one frame deep
        return self._guarded(compute, (q, v, a), ("q", "v", "a"), (self.n, len(names)))

    regressor.__doc__ = ControlTerms.regressor.__doc__

    def _place_bases(self, q, rng) -> None:
        """A floating base's random states in q (count, nq), in place: its position in
        [-1, 1] m and a random unit quaternion."""
        if getattr(getattr(self, "tree", None), "floating_base", False):
            count = len(q)
            q[:, :3] = rng.uniform(-1.0, 1.0, (count, 3))
            quaternion = rng.normal(size=(count, 4))  # uniform on the unit sphere
            q[:, 3:7] = quaternion / np.linalg.norm(quaternion, axis=-1, keepdims=True)

    # -- derivatives (derivatives_c.py, derivatives.py) -------------------------------------------

    def _derivatives_kernel(self):
        """The tree's compiled module's DerivativesKernel (derivatives_c.py), or None: a
        compiled backend's tree of revolute, prismatic, helical and ball joints (a floating base
        too); a free flyer below the root, the numpy backend and a model file keep
        derivatives.py."""
        found = self.__dict__.get("_derivatives_c", False)
        if found is False:
            found = None
            tree = getattr(self, "tree", None)
            if tree is not None and getattr(self, "module", None) is not None:
                from .engine.derivatives_c import applies, derivatives_module, runtime_values

                module = derivatives_module(tree) if applies(tree) else None
                if module is not None:
                    inverse, regressor = module.inverse_derivatives, module.regressor
                    checked = (inverse, regressor)
                    if tree.floating_base:
                        from .tree.free_flyer import checking_quaternions

                        checked = tuple(checking_quaternions(f) for f in checked)
                    found = DerivativesKernel(inverse, module.forward_derivatives, regressor,
                                              runtime_values(tree, self.parameters), *checked)
            self.__dict__["_derivatives_c"] = found
        return found

    def _derivatives_source(self):
        """(Q, V, A) -> (d tau/dq, d tau/dq_dot): the compiled C's, else the complex step
        through the numpy reference's Newton-Euler; without a tree the base class's."""
        tree = getattr(self, "tree", None)
        fast = self._derivatives_kernel()
        if fast is not None:
            inverse, P = fast.checked_inverse, fast.P

            def found(Q, V, A):
                return inverse(Q, V, A, P)[:2]
            return found
        if tree is None:
            return super()._derivatives_source()
        # the numpy reference's Newton-Euler, by the complex step
        from .derivatives import tree_inverse_dynamics_derivatives
        from .recursive_numpy import NumpyBackend

        recursions = getattr(self, "recursions", None)
        if not isinstance(recursions, NumpyBackend):
            recursions = NumpyBackend(tree, self.parameters, self.n)

        def found(Q, V, A):
            return tree_inverse_dynamics_derivatives(recursions, Q, V, A)
        return found

    def inverse_dynamics_derivatives(self, q, v, a) -> tuple[np.ndarray, np.ndarray]:
        fast = self._derivatives_kernel()
        if fast is not None:  # one C call; NotImplemented: the guarded way names the fault
            out = fast.inverse(q, v, a, fast.P)
            if out is not NotImplemented:
                return out if len(out) == 2 else _reported(out)
        compute = self._inverse_derivatives()  # as the base's, one frame deep for the warning
        n = self.n
        # partial, not a lambda: a closure would slow the compiled path above on every call
        both = self._guarded(partial(_side_by_side, compute), (q, v, a), ("q", "v", "a"),
                             (n, 2 * n))
        return both[..., :n], both[..., n:]

    inverse_dynamics_derivatives.__doc__ = ControlTerms.inverse_dynamics_derivatives.__doc__

    def forward_dynamics_derivatives(self, q, v, tau) -> tuple[np.ndarray, np.ndarray,
                                                               np.ndarray]:
        fast = self._derivatives_kernel()
        if fast is not None:  # as inverse_dynamics_derivatives
            out = fast.forward(q, v, tau, fast.P)
            if out is not NotImplemented:
                return out if len(out) == 3 else _reported(out)
        n = self.n
        # forward dynamics' rule: one warning for the three, a state's three rows NaN together
        # (an input not finite, or M not positive definite), as the C's
        out = self._guarded(self._forward_derivatives_numpy, (q, v, tau), ("q", "v", "tau"),
                            (n, 3 * n), forward=True, quiet=True)
        return out[..., :n], out[..., n:2 * n], out[..., 2 * n:]

    forward_dynamics_derivatives.__doc__ = ControlTerms.forward_dynamics_derivatives.__doc__


def _reported(out: tuple) -> tuple:
    """The C's (outputs..., count of NaN rows): one DynamicsWarning at the user's call, and the
    outputs."""
    from .tree.numbers import warn_undefined

    first = out[0]
    warn_undefined(out[-1], int(np.prod(first.shape[:-2], dtype=np.int64)), stacklevel=4)
    return out[:-1]


__all__ = ["DerivativesKernel", "TreeTerms"]
