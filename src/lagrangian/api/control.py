"""System's methods for control: linearization along a run (the rest of the control API is
lagrangian.control's controllers, taken by System.simulate)."""

from __future__ import annotations

from collections.abc import Sequence

from ..control.along import TrajectoryLinearization, linearize_along


class ControlMethods:
    """Mixed into System (api/system.py)."""

    def linearize_along(self, simulation, inputs: Sequence[str] | None = None
                        ) -> TrajectoryLinearization:
        """A(t), B(t) of x_dot = A x + B u (x = [q; q_dot], u the generalized forces on
        ``inputs``, default every coordinate) at ``simulation``'s saved samples, from the
        derivatives of forward dynamics (Dynamics.forward_dynamics_derivatives); a controlled
        run's own forces are held in place. Unconstrained models."""
        return linearize_along(self.dynamics(), simulation, inputs)
