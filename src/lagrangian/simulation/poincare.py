"""The Poincare map of a model with impacts, on the section just after an impact, with its
Jacobian from the variational equations and the impact's saltation (no finite differences).

Between impacts y = [q, q_dot] follows y' = f(y), q_ddot = M^-1 F; its sensitivity Phi = dy/dy0
follows Phi' = A Phi, A = [[0, I], [dq_ddot/dq, dq_ddot/dq_dot]], dq_ddot/dx = M^-1 (dF/dx -
dM/dx q_ddot). At the guard g(q) = 0 the impact time moves with the start: the map's Jacobian is

    DP = DDelta (I - f- grad g^T / (grad g . f-)) Phi(T)

with DDelta the Jacobian of the impact map (q' = R(q), q_dot' = dR/dq u, u the q part of the
impact equations' solution), differentiated exactly through the impact equations. Units SI.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from ..compile.lambdified import StateFunction
from ..errors import InputError
from .guards import GuardedRhs, StepCollapse
from .hybrid import CompiledImpact, kkt_system


class FlowSensitivity:
    """M, F, dF/dq, dF/dq_dot and dM/dq at a state, as numbers (parameters put in)."""

    def __init__(self, eom, substitution):
        model = eom.model
        q, v = sp.Matrix(model.q), sp.Matrix(model.q_dot)
        M, F = sp.Matrix(eom.mass_matrix), sp.Matrix(eom.forcing)
        self.n = n = len(q)
        parts = [*M, *F, *F.jacobian(q), *F.jacobian(v)]
        parts += [x for s in q for x in M.diff(s)]
        self._function = StateFunction(model, parts, substitution)
        # where M, F, dF/dq, dF/dq_dot end in the flat values (dM/dq after them)
        self._ends = tuple(int(x) for x in np.cumsum((n * n, n, n * n, n * n)))

    def at(self, q, v, t):
        flat = self._function.at(q, v, t)
        n, (a, b, c, d) = self.n, self._ends
        return (flat[:a].reshape(n, n), flat[a:b], flat[b:c].reshape(n, n),
                flat[c:d].reshape(n, n), flat[d:].reshape(n, n, n))

    def rhs(self, t, z):
        """d/dt [y, Phi] (Phi flattened, 2n x 2n)."""
        n = self.n
        q, v = z[:n], z[n:2 * n]
        M, F, Fq, Fv, Mq = self.at(q, v, t)
        # M^-1 once, then products: at a walker's n the per-call overhead of numpy is the cost
        # (three solves and a 2n x 2n product were 240 of the call's 310 us)
        inverse = np.linalg.inv(M)
        a = inverse @ F
        dq = inverse @ (Fq - Mq.transpose(1, 0, 2) @ a)  # (M^-1 (dF/dq - dM/dq q_ddot))
        dv = inverse @ Fv
        Phi = z[2 * n:].reshape(2 * n, 2 * n)
        out = np.empty_like(z)
        out[:n], out[n:2 * n] = v, a
        rates = out[2 * n:].reshape(2 * n, 2 * n)
        rates[:n] = Phi[n:]
        rates[n:] = dq @ Phi[:n] + dv @ Phi[n:]
        return out


class ImpactDerivatives:
    """The impact map's Jacobian DDelta (2n x 2n) at a pre-impact state, exactly: the impact
    equations K(q) z = b(q, v) differentiated, dz/dq_i = K^-1 (db/dq_i - dK/dq_i z)."""

    def __init__(self, model, impact: CompiledImpact, substitution):
        m = impact.map
        q = sp.Matrix(model.q)
        parts = []
        for s in q:
            parts += [*m.mass_matrix.diff(s), *m.jacobian.diff(s), *m.relabel_jacobian.diff(s)]
        self.impact = impact
        self._function = StateFunction(model, parts, substitution)
        self._shapes = (m.mass_matrix.shape, m.jacobian.shape, m.relabel_jacobian.shape)

    def __call__(self, q, v, t) -> np.ndarray:
        impact, n = self.impact, len(q)
        k, size = impact.k, impact.size
        M, J, E, _, _, _, DR = impact.matrices(q, v, t)
        ve = np.concatenate([np.zeros(k), v])
        kkt, rhs = kkt_system(M, J, E, ve)
        z = np.linalg.solve(kkt, rhs)
        u = z[k:size]
        flat = self._function.at(q, v, t).reshape(n, -1)
        sizes = [r * c for r, c in self._shapes]
        D = np.zeros((2 * n, 2 * n))
        D[:n, :n] = DR
        # v-derivative: the impact equations are linear in v
        right = np.vstack([M, -E @ J])[:, k:]
        D[n:, n:] = DR @ np.linalg.solve(kkt, right)[k:size]
        for i in range(n):
            dM, dJ, dDR = (part.reshape(shape) for part, shape in zip(
                np.split(flat[i], np.cumsum(sizes)[:-1]), self._shapes, strict=True))
            rows = J.shape[0]
            dK = np.block([[dM, -dJ.T], [dJ, np.zeros((rows, rows))]])
            db = np.concatenate([dM @ ve, -E @ (dJ @ ve)])
            dz = np.linalg.solve(kkt, db - dK @ z)
            D[n:, i] = dDR @ u + DR @ dz[k:size]
        return D


class PoincareMap:
    """x (the state just after an impact) -> the state just after the next impact, the time
    between them (s), which impact, and (with ``jacobian``) the map's Jacobian."""

    def __init__(self, eom, substitution, functions, step_control, maps=None, t_max=20.0):
        from .hybrid import compiled_impacts

        model = eom.model
        if any(model.time in m.guard.free_symbols for m in (maps or ())) or \
                any(model.time in i.guard.free_symbols for i in model.impacts):
            raise InputError("a limit cycle needs guards without explicit time t",
                             field="impacts")
        if any(model.time in sp.sympify(part).free_symbols  # safe: sympy objects, no text
               for part in (eom.mass_matrix, eom.forcing)):
            raise InputError("a limit cycle needs equations without explicit time t (a driven "
                             "model's period is its drive's, not a return to an impact)",
                             field="impacts")
        self.model, self.functions, self.steps = model, functions, step_control
        self.impacts, self.guards = compiled_impacts(eom, substitution, maps)
        self.flow = FlowSensitivity(eom, substitution)
        self._derivatives: dict[int, ImpactDerivatives] = {}
        self._substitution = substitution
        grads = [[m.guard.diff(s) for s in model.q] for m in (i.map for i in self.impacts)]
        self._gradients = StateFunction(model, [x for row in grads for x in row], substitution)
        self.t_max = t_max

    def __call__(self, x, jacobian: bool = False, field: str = "guess"):
        from scipy import integrate

        n = self.flow.n
        z0 = np.concatenate([x, np.eye(2 * n).ravel()]) if jacobian else np.array(x, float)
        fun = GuardedRhs(self.flow.rhs if jacobian else self.functions.rhs, "DOP853", len(z0),
                         0.0, self.t_max)
        event, offsets = self.guards.leaving(x[:n], x[n:], 0.0)
        armed = event(x[:n], x[n:], 0.0) < 0
        # scipy's overflow warnings held back: a flow that is not finite is refused below, and
        # a step size that collapses (g = 1e154: steps of 1e-77 s toward t_max) ends the search
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            solver = integrate.DOP853(fun, 0.0, z0, self.t_max, rtol=self.steps.rtol,
                                      atol=self.steps.atol)
            while solver.status == "running":
                try:
                    solver.step()
                    fun.accepted(solver.t)
                except StepCollapse as stop:
                    raise InputError(f"the flow failed before the next impact: {stop.message}",
                                     field=field) from None
                if solver.status == "failed" or not np.all(np.isfinite(solver.y)):
                    raise InputError(f"the flow failed at t = {solver.t:.6g} s before the next "
                                     "impact", field=field)
                y = solver.y
                g = event(y[:n], y[n:2 * n], solver.t)
                if armed and g >= 0:
                    dense = solver.dense_output()
                    t_hit = _crossing(event, dense, solver.t_old, solver.t, n)
                    break
                armed = armed or g < 0
            else:
                t_hit = None
        if t_hit is not None:
            return self._after(dense(t_hit), t_hit, jacobian, offsets, field)
        raise InputError(f"no impact within {self.t_max:g} s of the start (the motion comes to "
                         "rest or falls before its guard: no cycle through an impact from "
                         "there; try a guess nearer a cycle)", field=field)

    def _after(self, z, t, jacobian, offsets, field: str = "guess"):
        from .hybrid import polish

        n = self.flow.n
        y = z[:2 * n]
        which = int(np.argmin(self.guards.values.at(y[:n], y[n:], t) - offsets))
        t, y = polish(self.guards, which, self.functions, t, y, n)
        impact = self.impacts[which]
        q_new, v_new, *_ = impact.apply(y[:n], y[n:], t)
        x_new = np.concatenate([q_new, v_new])
        if not jacobian:
            return x_new, t, impact.name, None
        Phi = z[2 * n:].reshape(2 * n, 2 * n)
        f = self.functions.rhs(t, y)
        grad = np.concatenate([self._gradients.at(y[:n], y[n:], t).reshape(-1, n)[which],
                               np.zeros(n)])
        rate = float(grad @ f)
        if rate == 0 or not math.isfinite(rate):
            raise InputError("the guard is crossed tangentially (a graze): no Poincare map "
                             "there", field=field)
        saltation = np.eye(2 * n) - np.outer(f, grad) / rate
        if which not in self._derivatives:
            self._derivatives[which] = ImpactDerivatives(self.model, impact, self._substitution)
        D = self._derivatives[which](y[:n], y[n:], t)
        return x_new, t, impact.name, D @ saltation @ Phi


def _crossing(event, dense, t_old, t_new, n):
    from scipy import optimize

    def g(t):
        y = dense(t)
        return event(y[:n], y[n:2 * n], t)

    if g(t_old) >= 0:
        return t_old
    return float(optimize.brentq(g, t_old, t_new, xtol=1e-15 * max(1.0, abs(t_new)),
                                 rtol=4 * np.finfo(float).eps, maxiter=200))


__all__ = ["FlowSensitivity", "ImpactDerivatives", "PoincareMap"]
