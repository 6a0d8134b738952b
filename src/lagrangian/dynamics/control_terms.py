"""What a controller or an identification asks of Dynamics beyond M and the bias: the
derivatives of inverse and forward dynamics (derivatives.py), the torque regressor Y
(tau = Y pi), the inertial parameters pi, a minimal identifiable set;
mixed into joint_space.Dynamics (every path, a URDF tree's and a model file's)."""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial

import numpy as np

from ..errors import InputError
from .regressor import BASE_TOLERANCE, BaseParameters, ModelRegressor


class ControlTerms:
    """Regressor and parameters (a mixin of joint_space.Dynamics; SI units)."""

    def _regressor_of(self, parameters: Sequence[str] | None):
        if parameters is None:
            raise InputError("name the parameters the model's T and V are linear in: "
                             "regressor(q, v, a, parameters=[...])", field="parameters")
        if self._equations is None:
            raise InputError("this dynamics object was built without its equations",
                             field="parameters")
        names = [parameters] if isinstance(parameters, str) else list(parameters)
        found = ModelRegressor(self._equations(), names, dict(self.functions.parameters))
        return found, found.names, found.values

    def regressor(self, q, v, a, parameters: Sequence[str] | None = None) -> np.ndarray:
        """Y with tau = Y pi (inverse dynamics, the actuator parameters aside), shape
        (..., n, k). A URDF robot: 10 parameters per moving body in Pinocchio's order
        (m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz about the body's joint
        frame; see ``parameter_names``); a floating base's (q of nv + 1 numbers with its
        quaternion, v and a of nv) has nv rows, the first six the wrench on the base in its own
        axes, force then moment (Pinocchio's layout). A model file: the named ``parameters``, in
        which T and V must be linear."""
        compute, names, _ = self._regressor_of(parameters)
        return self._guarded(compute, (q, v, a), ("q", "v", "a"), (self.n, len(names)))

    def parameter_names(self, parameters: Sequence[str] | None = None) -> tuple[str, ...]:
        """The names of pi's entries ('m@panda_joint1', ...; a model file's own names)."""
        return tuple(self._regressor_of(parameters)[1])

    def inertial_parameters(self, parameters: Sequence[str] | None = None) -> np.ndarray:
        """pi: the model's own values of the regressor's parameters (SI)."""
        return np.array(self._regressor_of(parameters)[2], dtype=float)

    def base_parameters(self, parameters: Sequence[str] | None = None, *,
                        tolerance: float = BASE_TOLERANCE, states: int | None = None,
                        seed: int = 0) -> BaseParameters:
        """A minimal identifiable set by QR with column pivoting of Y stacked over ``states``
        random states (default 20 per parameter; q in [-pi, pi], rates in [-1, 1]; a floating
        base's position in [-1, 1] m and a random unit quaternion): a column is kept where
        |R_kk| > ``tolerance`` |R_00| (default 1e-8)."""
        compute, names, _ = self._regressor_of(parameters)
        count = states if states is not None else max(20 * len(names) // max(self.n, 1), 20)
        rng = np.random.default_rng(seed)
        q = rng.uniform(-np.pi, np.pi, (count, self.nq))
        self._place_bases(q, rng)
        v, a = rng.uniform(-1.0, 1.0, (2, count, self.n))
        stacked = np.asarray(compute(q, v, a)).reshape(count * self.n, len(names))
        return BaseParameters(names, stacked, tolerance)

    # -- derivatives (derivatives_c.py, derivatives.py) -------------------------------------------

    def _place_bases(self, q, rng) -> None:
        """Put random floating-base states into q (count, nq) in place: a model file has none
        (tree_terms.py)."""

    def _inverse_derivatives(self):
        found = self.__dict__.get("_derivatives")
        if found is None:
            found = self.__dict__["_derivatives"] = self._derivatives_source()
        return found

    def _derivatives_source(self):
        """(Q, V, A) -> (d tau/dq, d tau/dq_dot): a model file's from its derived M and f
        (derivatives.py; a URDF tree's: tree_terms.py)."""
        from .derivatives import ModelDerivatives

        if self._equations is None:
            raise InputError("this dynamics object was built without its equations",
                             field="q")
        return ModelDerivatives(self._equations(), dict(self.functions.parameters))

    def inverse_dynamics_derivatives(self, q, v, a) -> tuple[np.ndarray, np.ndarray]:
        """(d tau/dq, d tau/dq_dot) of tau = M(q) q_ddot + C q_dot + g, (..., n, n) each (row
        i: tau_i), as Pinocchio's computeRNEADerivatives: a URDF tree's analytic in compiled C
        (derivatives_c.py; a floating base's d/dq along its own axes, q (+) dq, n = nv); else
        the complex step through the numpy reference's Newton-Euler, along every joint's
        tangent (ball joints and free flyers too), exact to rounding; a model file's from its
        derived M and f."""
        compute = self._inverse_derivatives()
        n = self.n
        # partial, not a lambda: a closure pays for its cells on every call
        both = self._guarded(partial(_side_by_side, compute), (q, v, a), ("q", "v", "a"),
                             (n, 2 * n))
        return both[..., :n], both[..., n:]

    def forward_dynamics_derivatives(self, q, v, tau) -> tuple[np.ndarray, np.ndarray,
                                                               np.ndarray]:
        """(d q_ddot/dq, d q_ddot/dq_dot, d q_ddot/d tau), (..., n, n) each, as Pinocchio's
        computeABADerivatives: -M^-1 d tau/dq and -M^-1 d tau/dq_dot at q_ddot = FD(q, q_dot,
        tau), and M^-1."""
        n = self.n
        # forward dynamics' rule: one warning for the three, a state's three rows NaN together
        # (an input not finite, or M not positive definite), as the C's
        out = self._guarded(self._forward_derivatives_numpy, (q, v, tau), ("q", "v", "tau"),
                            (n, 3 * n), forward=True, quiet=True)
        return out[..., :n], out[..., n:2 * n], out[..., 2 * n:]

    def _forward_derivatives_numpy(self, q, v, tau) -> np.ndarray:
        """The three side by side, (..., n, 3n), from forward dynamics, the inverse dynamics'
        derivatives and M^-1."""
        acceleration = self.forward_dynamics(q, v, tau)  # NaN where M is not definite
        by_position, by_velocity = self.inverse_dynamics_derivatives(q, v, acceleration)
        inverse = _inverses(self.mass_matrix(q))
        return np.concatenate([-inverse @ by_position, -inverse @ by_velocity, inverse], axis=-1)


def _side_by_side(compute, Q, V, A) -> np.ndarray:
    """compute's two (N, n, n) side by side, (N, n, 2n)."""
    return np.concatenate(compute(Q, V, A), axis=-1)


def _inverses(mass: np.ndarray) -> np.ndarray:
    """M^-1 over a batch (..., n, n), NaN for a state whose M is not finite or is singular
    (each as if alone: one such state does not fail the batch)."""
    flat = mass.reshape((-1,) + mass.shape[-2:])
    out = np.full(flat.shape, np.nan)
    fine = np.isfinite(flat).all(axis=(1, 2))
    try:
        out[fine] = np.linalg.inv(flat[fine])
    except np.linalg.LinAlgError:
        for k in np.flatnonzero(fine):
            try:
                out[k] = np.linalg.inv(flat[k])
            except np.linalg.LinAlgError:
                pass
    return out.reshape(mass.shape)
