"""The equations at rest of a kinematic tree, from its recursive algorithms (nothing derived):
what equilibria, linearization and modes evaluate, as compile/at_rest.AtRestFunctions gives them
for derived equations (the same ``evaluate`` and attributes).

At rest (q_dot = 0) a tree's forcing is f = -g(q) (gravity and the actuator parameters), its
mass matrix M(q), and -df/dq_dot = 0: a tree's velocity terms are quadratic in q_dot. The
stiffness K = dg/dq is taken by central differences of g, refined once by Richardson's
extrapolation (error of order h^4: about 1e-12 of g with h = 1e-3), all in one batched call.
"""

from __future__ import annotations

import numpy as np

STEP = 1e-3  # rad or m: the difference step of K = dg/dq


class TreeAtRest:
    """M, f, K = -df/dq and C = -df/dq_dot at q_dot = 0 of a tree's dynamics (TreeDynamics),
    batched over configurations q (..., n); SI units. No constraints (m = 0)."""

    parametric = False
    eom = None  # nothing derived: inputs of a linear model go through the derived equations
    static_names: tuple[str, ...] = ()

    def __init__(self, dynamics):
        tree = dynamics.tree
        if tree.floating_base:  # the model's coordinates are the joints': a base has no rest
            from ..errors import ModelError

            raise ModelError("a floating-base robot has no rest in its joint coordinates "
                             "(equilibria, linearize, modes and lqr take a fixed base): load it "
                             "with a fixed base, or linearize a run with linearize_along")
        self.dynamics = dynamics
        self.model = dynamics.model
        self.n, self.m = len(self.model.coordinates), 0
        # a ball joint or a free flyer below the root: the model's coordinates are its Euler
        # angles (what derive shows), the tree's numbers a quaternion (tree/model_charts.py)
        self._charts = None
        if tree.quaternion_joints:
            from .tree.model_charts import ModelCharts

            self._charts = ModelCharts(self.model, dynamics.velocity_names)
        self.parameter_names = tuple(p.name for p in self.model.parameters)
        self.parameters = dict(dynamics.parameters)
        self.search_parameters = tuple(range(len(self.parameter_names)))
        # the coordinates the forces at rest depend on (a joint about the vertical is neutral),
        # found by value at a few random configurations
        rng = np.random.default_rng(5)
        stiffness = self.evaluate(rng.uniform(-np.pi, np.pi, (3, self.n)))["stiffness"]
        scale = 1e-9 * (1.0 + np.abs(stiffness).max())
        moving = np.abs(stiffness).max(axis=(0, 1)) > scale
        self.depends_on = frozenset(c.symbol for c, m in zip(self.model.coordinates, moving,
                                                             strict=True) if m)

    def chart_singular(self, q: np.ndarray) -> bool:
        """Whether q is at a gimbal lock of the Euler angles the model gives a ball joint or a
        free flyer below the root (no stability is claimed there)."""
        return self._charts is not None and self._charts.singular(q)

    def same_configuration(self, first: np.ndarray, second: np.ndarray) -> bool:
        """Whether two configurations place the tree alike (Euler angles cover a ball's turns
        twice); False where the model's coordinates are the tree's own."""
        return self._charts is not None and self._charts.same(first, second)

    def evaluate(self, q: np.ndarray, t: float = 0.0, parameters: np.ndarray | None = None
                 ) -> dict[str, np.ndarray]:
        """Every matrix at configurations q (..., n), at rest (t: no effect on a tree)."""
        if parameters is not None:
            raise ValueError("a tree's equations at rest are for its own parameter values")
        q = np.asarray(q, dtype=float)
        batch, n = q.shape[:-1], self.n
        gravity, mass = self.dynamics.gravity, self.dynamics.mass_matrix
        if self._charts is not None:  # M_theta = E^T M E, g_theta = E^T g (virtual work)
            charts = self._charts

            def gravity(theta):
                E = charts.rates(theta)
                return np.einsum("...ji,...j->...i", E,
                                 self.dynamics.gravity(charts.configuration(theta)))

            def mass(theta):
                E = charts.rates(theta)
                M = self.dynamics.mass_matrix(charts.configuration(theta))
                return np.swapaxes(E, -1, -2) @ M @ E
        # rows: +h, -h, +h/2, -h/2 along each coordinate (4 n states per configuration)
        eye = np.eye(n) * STEP
        shifts = np.concatenate([eye, -eye, eye / 2, -eye / 2])
        g = gravity(q[..., None, :] + shifts)
        wide = (g[..., :n, :] - g[..., n:2 * n, :]) / (2 * STEP)
        narrow = (g[..., 2 * n:3 * n, :] - g[..., 3 * n:, :]) / STEP
        stiffness = np.swapaxes((4 * narrow - wide) / 3, -1, -2)  # K_ij = dg_i/dq_j
        return {
            "mass": mass(q),
            "forcing": -gravity(q),
            "stiffness": stiffness,
            "damping": np.zeros(batch + (n, n)),
            "jacobian": np.zeros(batch + (0, n)),
            "hessians": np.zeros(batch + (0, n, n)),
            "static": np.zeros(batch + (0,)),
            "static_jacobian": np.zeros(batch + (0, n)),
        }


__all__ = ["TreeAtRest"]
