"""A constrained model file's forward dynamics and its derivatives, through the multipliers:
the index-1 form of M q_ddot + Phi_q^T lambda = f + tau, Phi_q q_ddot = gamma,

    K z = r,   K = [[M, A^T], [A, 0]],   z = [q_ddot; lambda],   r = [f + tau; gamma],

(A = Phi_q, or a velocity constraint's A) differentiated exactly: dz/dx = K^-1 (dr/dx - dK/dx z)
for x each q_k and q_dot_k, and dz/d tau = K^-1 [I; 0], the entries of dM, dA, df and d gamma
differentiated by sympy once (numpy functions of q, q_dot, t). The same q_ddot as a constrained
run's right-hand side (simulate); a constrained system's tau is not unique (it is defined up to
A^T lambda), so there is no inverse dynamics. Units SI.
"""

from __future__ import annotations

import warnings

import numpy as np
import sympy as sp

from ..compile.functions import NumericSystem
from ..compile.lambdified import StateFunction
from ..errors import DynamicsWarning, InputError, ModelError
from ..model.expressions import as_expression
from .tree.numbers import float_array


class ConstrainedDynamics:
    """What System.dynamics() gives for a model file with constraints: M, the DAE's forward
    dynamics (q_ddot and lambda) and forward dynamics' derivatives, batched over leading axes,
    at time ``t`` (s; moving constraints and forces depend on it). With no constraints (m = 0,
    K = M) the same for a model whose equations hold t explicitly (linearize_along)."""

    timed = True  # every function takes t (linearize_along passes each sample's)

    def __init__(self, functions: NumericSystem, equations, model=None):
        self.functions = functions
        self.coordinates = functions.coordinates
        self.constraint_names = functions.constraint_names
        self.n, self.m = functions.n, functions.m
        self.model = model
        self._equations = equations
        self._derivatives = None

    def __repr__(self) -> str:
        return (f"ConstrainedDynamics(coordinates={list(self.coordinates)}, "
                f"constraints={list(self.constraint_names)})")

    @property
    def nq(self) -> int:
        return self.n

    @property
    def nv(self) -> int:
        return self.n

    def _states(self, q, v, tau, t):
        arrays = []
        for value, field in ((q, "q"), (v, "v"), (tau, "tau")):
            array = float_array(value, field)
            if array.ndim == 0 or array.shape[-1] != self.n:
                shape = "()" if array.ndim == 0 else str(array.shape)
                raise InputError(f"expected {self.n} values ({', '.join(self.coordinates)}) "
                                 f"along the last axis, got shape {shape}", field=field)
            arrays.append(array)
        batch = np.broadcast_shapes(*(a.shape[:-1] for a in arrays), np.shape(t))
        flat = [np.broadcast_to(a, batch + (self.n,)).reshape(-1, self.n) for a in arrays]
        times = np.broadcast_to(np.asarray(t, dtype=float), batch).reshape(-1)
        return batch, *flat, times

    def _kkt(self, Q, V, TAU, T):
        """K (N, n+m, n+m), z (N, n+m) at each state."""
        n, m = self.n, self.m
        mass, forcing, jacobian, gamma = self.functions._parts(Q, V, T)
        kkt = np.zeros((len(Q), n + m, n + m))
        kkt[:, :n, :n], kkt[:, :n, n:], kkt[:, n:, :n] = mass, np.swapaxes(jacobian, -1, -2), \
            jacobian
        rhs = np.concatenate([forcing + TAU, gamma], axis=-1)
        return kkt, solve_rows(kkt, rhs[..., None])[..., 0]

    def mass_matrix(self, q, t=0.0) -> np.ndarray:
        """M(q), shape (..., n, n)."""
        q = np.asarray(q, dtype=float)
        return self.functions.mass_matrix(q, np.zeros_like(q), t)

    def bias_forces(self, q, v, t=0.0) -> np.ndarray:
        """-f(q, q_dot): the model's own forces with the sign of a bias, shape (..., n)."""
        q = np.asarray(q, dtype=float)
        return -self.functions.forcing(q, v, t)

    def gravity(self, q, t=0.0) -> np.ndarray:
        """-f(q, 0), shape (..., n)."""
        q = np.asarray(q, dtype=float)
        return -self.functions.forcing(q, np.zeros_like(q), t)

    def potential_energy(self, q, t=0.0) -> np.ndarray:
        """V(q) in J, shape (...)."""
        q = np.asarray(q, dtype=float)
        return self.functions.energy(q, np.zeros_like(q), t)

    def kinetic_energy(self, q, v, t=0.0) -> np.ndarray:
        """T(q, q_dot) in J, shape (...)."""
        q = np.asarray(q, dtype=float)
        return self.functions.energy(q, v, t) - self.functions.energy(q, np.zeros_like(q), t)

    @property
    def kinematics(self):
        """The model's points and bodies, frames and Jacobians (model_frames.py)."""
        from .model_frames import ModelKinematics

        found = self.__dict__.get("_kinematics")
        if found is None:
            if self.model is None:
                raise InputError("this dynamics object was built without its model", field="q")
            found = self.__dict__["_kinematics"] = ModelKinematics(self.model,
                                                                   self.functions.parameters)
        return found

    def forward_dynamics(self, q, v, tau, t=0.0, f_ext=None) -> np.ndarray:
        """q_ddot of the constrained system with tau (N m or N per coordinate) on top of f,
        shape (..., n)."""
        if f_ext is not None:
            raise InputError("wrenches at frames are not taken by a constrained model's "
                             "forward dynamics (not yet)", field="f_ext")
        batch, Q, V, TAU, T = self._states(q, v, tau, t)
        return self._kkt(Q, V, TAU, T)[1][:, :self.n].reshape(batch + (self.n,))

    def multipliers(self, q, v, tau, t=0.0) -> np.ndarray:
        """lambda (one per constraint, in the constraint's force units), shape (..., m)."""
        batch, Q, V, TAU, T = self._states(q, v, tau, t)
        return self._kkt(Q, V, TAU, T)[1][:, self.n:].reshape(batch + (self.m,))

    def forward_dynamics_derivatives(self, q, v, tau, t=0.0
                                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(d q_ddot/dq, d q_ddot/dq_dot, d q_ddot/d tau), (..., n, n) each (row i: q_ddot_i),
        of the constrained system's accelerations (the multipliers eliminated, exact)."""
        batch, Q, V, TAU, T = self._states(q, v, tau, t)
        n, m = self.n, self.m
        kkt, z = self._kkt(Q, V, TAU, T)
        parts = self._parts()
        count, size = len(Q), n + m
        out = []
        for wrt in ("q", "v"):
            # dK/dx_k z as [N, k, row]: the M block's dM/dx_k q_ddot + dA^T/dx_k lambda, then
            # the A block's dA/dx_k q_ddot; dr/dx_k the same way from df and d gamma.
            dmass = parts[f"mass_{wrt}"](Q, V, T).reshape(count, n, n, n)  # [N, k, i, j]
            djac = parts[f"jacobian_{wrt}"](Q, V, T).reshape(count, n, m, n)  # [N, k, c, j]
            dforce = parts[f"forcing_{wrt}"](Q, V, T).reshape(count, n, n)  # [N, k, i]
            dgamma = parts[f"gamma_{wrt}"](Q, V, T).reshape(count, n, m)  # [N, k, c]
            acc, lam = z[:, :n], z[:, n:]
            top = dforce - np.einsum("nkij,nj->nki", dmass, acc) \
                - np.einsum("nkcj,nc->nkj", djac, lam)
            bottom = dgamma - np.einsum("nkcj,nj->nkc", djac, acc)
            rhs = np.concatenate([top, bottom], axis=-1)  # [N, k, n+m]
            dz = solve_rows(kkt, np.swapaxes(rhs, -1, -2), warn=False)  # [N, n+m, k]
            out.append(dz[:, :n, :].reshape(batch + (n, n)))
        unit = np.zeros((count, size, n))
        unit[:, :n, :] = np.eye(n)
        out.append(solve_rows(kkt, unit, warn=False)[:, :n, :].reshape(batch + (n, n)))
        return out[0], out[1], out[2]

    def constraint_rows(self, q, v, t=0.0) -> tuple[np.ndarray, np.ndarray]:
        """(A, dc/dq) at each state, (..., m, n) each: the velocity-level constraints c = A q_dot
        + b = 0 (Phi_q q_dot + Phi_t for a holonomic one) and their change with q."""
        batch, Q, V, _, T = self._states(q, v, np.zeros(self.n), t)
        n, m = self.n, self.m
        jacobian = self.functions._parts(Q, V, T)[2].reshape(len(Q), m, n)
        found = self.__dict__.get("_velocity_rate")
        if found is None:
            eom = self._equations()
            model = eom.model
            values = self.functions.parameters
            substitution = {p.symbol: sp.Float(values[p.name]) for p in model.parameters
                            if p.name in values}
            rows = sp.Matrix(eom.constraint_jacobian) * sp.Matrix(model.q_dot) \
                + sp.Matrix(eom.velocity_bias)
            found = self.__dict__["_velocity_rate"] = StateFunction(
                model, [as_expression(rows[c]).diff(x) for c in range(m) for x in model.q],
                substitution)
        rate = found(Q, V, T).reshape(len(Q), m, n)
        return jacobian.reshape(batch + (m, n)), rate.reshape(batch + (m, n))

    def _parts(self) -> dict[str, StateFunction]:
        """The symbolic derivatives, compiled on first use."""
        if self._derivatives is None:
            if self._equations is None:
                raise InputError("this dynamics object was built without its equations",
                                 field="q")
            eom = self._equations()
            model = eom.model
            values = self.functions.parameters
            substitution = {p.symbol: sp.Float(values[p.name]) for p in model.parameters
                            if p.name in values}
            mass = [as_expression(e) for e in eom.mass_matrix]
            jacobian = [as_expression(e) for e in eom.constraint_jacobian]
            forcing = [as_expression(e) for e in eom.forcing]
            gamma = [as_expression(e) for e in eom.acceleration_rhs]
            parts = {}
            for wrt, symbols in (("q", model.q), ("v", model.q_dot)):
                for name, entries in (("mass", mass), ("jacobian", jacobian),
                                      ("forcing", forcing), ("gamma", gamma)):
                    parts[f"{name}_{wrt}"] = StateFunction(
                        model, [e.diff(x) for x in symbols for e in entries], substitution)
            self._derivatives = parts
        return self._derivatives

    def __getattr__(self, name: str):
        # Dynamics' other methods (inverse dynamics, its derivatives, the regressor, C(q, v))
        # ask for a tau that a constrained model does not define: one line, not AttributeError.
        from .joint_space import Dynamics

        if not name.startswith("_") and hasattr(Dynamics, name):
            raise ModelError(f"{name}: a constrained model's generalized forces are defined only "
                             "up to Phi_q^T lambda, so it has no inverse dynamics, regressor or "
                             "Coriolis matrix; forward dynamics and its derivatives work through "
                             "the multipliers", field="constraints")
        raise AttributeError(name)


def solve_rows(kkt: np.ndarray, rhs: np.ndarray, warn: bool = True) -> np.ndarray:
    """K^-1 rhs for a flat batch (N, s, s), (N, s, k): NaN in the rows whose K is singular (a
    constraint Jacobian without full rank, an input not finite), the others exact, with one
    DynamicsWarning counting them."""
    try:
        out = np.linalg.solve(kkt, rhs)
    except np.linalg.LinAlgError:
        out = np.full(rhs.shape, np.nan)
        for k in range(len(kkt)):  # only on this path: find the singular rows
            try:
                out[k] = np.linalg.solve(kkt[k], rhs[k])
            except np.linalg.LinAlgError:
                pass
    bad = ~np.isfinite(out).all(axis=(-2, -1))
    out[bad] = np.nan
    if bad.any() and warn:  # once per call: the first solve of a call warns
        warnings.warn(DynamicsWarning(
            f"{int(bad.sum())} of {len(kkt)} states have no constrained dynamics (an input not "
            "finite, or [[M, Phi_q^T], [Phi_q, 0]] singular: redundant constraints there): "
            "their rows are NaN", int(bad.sum()), len(kkt)), stacklevel=4)
    return out
