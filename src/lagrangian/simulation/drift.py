"""Drift control for constrained models: coordinate projection back onto Phi = 0, Phi_dot = 0.

The index-1 form keeps Phi_ddot = 0 exactly, but Phi and Phi_dot drift with the truncation
error; after an accepted step the state is moved to the nearest consistent one.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..compile.functions import NumericSystem
from ..compile.lambdified import StateFunction
from ..errors import ModelError
from ..kinds import ConstraintKind

# Explicit Runge-Kutta solvers keep only (y, f) between steps, so a projected state can be put
# back in place; the others carry a history and are restarted from the projected state instead.
IN_PLACE = {"DOP853", "RK45", "RK23"}
_DRIFT_IN_PLACE = 1e-12
_DRIFT_RESTART = 1e-10
# A restarted multistep solver begins again at order 1 with small steps; restarting it more
# often than this many steps keeps it at low order for ever (BDF then crawls).
_STEPS_BETWEEN_RESTARTS = 50


class DriftControl:
    """Coordinate projection onto Phi = 0 and Phi_dot = 0 (velocity constraints: A q_dot + b = 0).

    Positions: Gauss-Newton steps dq = -W^-1 J^T (J W^-1 J^T)^-1 Phi over the holonomic rows;
    velocities: one step of the same form with the velocity-level residual J q_dot + b. W is the
    mass matrix (the smallest change in kinetic-energy norm).
    """

    def __init__(self, functions: NumericSystem, velocity_bias: StateFunction):
        self.functions = functions
        self.velocity_bias = velocity_bias
        self.holonomic = np.array([k == ConstraintKind.HOLONOMIC for k in functions.constraint_kinds])
        self.nfev = 0
        self.steps_since_restart = 0

    def residuals(self, q, v, t):
        f = self.functions
        phi = f.constraint_residual(q, v, t)[self.holonomic]
        jacobian = f.constraint_jacobian(q, v, t)
        velocity = jacobian @ v + self.velocity_bias.at(q, v, t)
        return phi, velocity, jacobian

    def project(self, q, v, t, inverse_metric=None, tolerance=0.0):
        """The nearest state (in the metric) with Phi = 0 and J q_dot + b = 0."""
        phi, velocity, jacobian = self.residuals(q, v, t)
        for _ in range(12):
            if not phi.size or np.max(np.abs(phi)) <= tolerance:
                break
            W = self._metric(q, v, t, inverse_metric)
            J = jacobian[self.holonomic]
            dq = -W @ J.T @ np.linalg.solve(J @ W @ J.T, phi)
            q = q + dq
            phi, velocity, jacobian = self.residuals(q, v, t)
            if np.max(np.abs(dq)) <= 1e-15 * (1.0 + np.max(np.abs(q))):
                break
        if velocity.size and np.max(np.abs(velocity)) > tolerance:
            W = self._metric(q, v, t, inverse_metric)
            v = v - W @ jacobian.T @ np.linalg.solve(jacobian @ W @ jacobian.T, velocity)
        return q, v

    def _metric(self, q, v, t, inverse_metric):
        if inverse_metric is not None:
            return inverse_metric
        return np.linalg.inv(self.functions.mass_matrix(q, v, t))

    def project_initial(self, q, v, t, given: Mapping[str, bool]):
        """Project the initial state, moving the values the user did not give where possible."""
        n = self.functions.n
        names = list(given)
        free = np.array([not given[name] for name in names])
        # Euclidean metric restricted to the free entries; all entries if that is not enough.
        for mask in (free, np.ones(2 * n, dtype=bool)):
            try:
                q_new, _ = self.project(q, v, t, np.diag(mask[:n].astype(float)))
                _, v_new = self.project(q_new, v, t, np.diag(mask[n:].astype(float)))
                phi, velocity, _ = self.residuals(q_new, v_new, t)
                if np.max(np.abs(np.concatenate([phi, velocity])), initial=0.0) < 1e-10:
                    return q_new, v_new
            except np.linalg.LinAlgError:
                continue
        raise ModelError("the initial state cannot be brought onto the constraints "
                         "(Phi = 0 and its rate); check the initial values", field="initial")

    def correct(self, solver, start):
        """Project the solver's state if it drifted; returns the solver to continue with."""
        n = self.functions.n
        y = solver.y
        phi, velocity, _ = self.residuals(y[:n], y[n:], solver.t)
        worst = np.max(np.abs(np.concatenate([phi, velocity])), initial=0.0)
        in_place = type(solver).__name__ in IN_PLACE
        self.steps_since_restart += 1
        if worst <= (_DRIFT_IN_PLACE if in_place else _DRIFT_RESTART):
            return solver
        if not in_place and self.steps_since_restart < _STEPS_BETWEEN_RESTARTS:
            return solver
        self.steps_since_restart = 0
        q, v = self.project(y[:n], y[n:], solver.t, tolerance=1e-15)
        y_new = np.concatenate([q, v])
        if in_place:
            solver.y = y_new
            solver.f = solver.fun(solver.t, y_new)
            return solver
        self.nfev += solver.nfev
        return start(solver.t, y_new, first_step=min(solver.step_size, solver.t_bound - solver.t)
                     if solver.step_size else None)
