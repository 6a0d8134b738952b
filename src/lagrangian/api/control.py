"""System's methods for control: linearization along a run (the rest of the control API is
lagrangian.control's controllers, taken by System.simulate)."""

from __future__ import annotations

from collections.abc import Sequence

from ..control.along import TrajectoryLinearization, linearize_along
from ..errors import ModelError


class ControlMethods:
    """Mixed into System (api/system.py)."""

    def linearize_along(self, simulation, inputs: Sequence[str] | None = None
                        ) -> TrajectoryLinearization:
        """A(t), B(t) of x_dot = A x + B u (x = [q; q_dot], u the generalized forces on
        ``inputs``, default every coordinate) at ``simulation``'s saved samples, from the
        derivatives of forward dynamics (Dynamics.forward_dynamics_derivatives); a controlled
        run's own forces are held in place. Unconstrained models (a constrained one is refused
        in one line: its A(t) would be on the constraint manifold, not done yet)."""
        constraints = self.model.constraints
        if constraints:
            raise ModelError(f"linearize_along needs a model without constraints (this one has "
                             f"{len(constraints)}: {', '.join(c.name for c in constraints)}); "
                             "about an equilibrium, linearize() works on the constraint "
                             "manifold", field="constraints")
        return linearize_along(self.dynamics(), simulation, inputs)
