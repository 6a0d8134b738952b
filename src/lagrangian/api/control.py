"""System's methods for control: linearization along a run (the rest of the control API is
lagrangian.control's controllers, taken by System.simulate), and the model's own [control]
laws closed into its equations once per System."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # imported by the methods that use them (issue 38)
    from ..control.along import TrajectoryLinearization


class ControlMethods:
    """Mixed into System (api/system.py)."""

    def linearize_along(self, simulation, inputs: Sequence[str] | None = None,
                        independent: Sequence[str] | str | None = None
                        ) -> TrajectoryLinearization:
        """A(t), B(t) of x_dot = A x + B u (x = [q; q_dot], u the generalized forces on
        ``inputs``, default every coordinate) at ``simulation``'s saved samples, from the
        derivatives of forward dynamics (Dynamics.forward_dynamics_derivatives); a controlled
        run's own forces are held in place. A model with constraints gives the derivatives of its
        index-1 form (M q_ddot + Phi_q^T lambda = f + u, Phi_q q_ddot = gamma) in all n
        coordinates: A(t) then also holds the directions off the constraints (double zero
        eigenvalues, Phi_ddot = 0), as the run's own right-hand side does; ``independent`` (its
        n - m independent coordinates, or "auto" for the best conditioned along the run) gives
        A(t), B(t) on the constraint manifold instead, in x = [q_i; q_i_dot] (holonomic
        constraints; the others follow from Phi = 0 and Phi_dot = 0). A tree whose q holds
        quaternions (a ball joint, a free flyer, a floating base) in the tangent: x = [dq; v]
        with q = q_run (+) dq, the states delta_<velocity> and u on each velocity number."""
        from ..control.along import linearize_along

        return linearize_along(self._dynamics_in_time(), simulation, inputs, independent)

    def _dynamics_in_time(self):
        """dynamics(), or where a model file's equations hold t explicitly (a moving support)
        and dynamics() would read them at t = 0, the same through dynamics/constrained.py,
        which takes each sample's t."""
        from ..dynamics.constrained import ConstrainedDynamics
        from ..model.expressions import as_expression

        if self._recursive is None and not self.model.constraints:
            eom = self.equations_of_motion()
            parts = [*eom.mass_matrix, *eom.forcing]
            if any(self.model.time in as_expression(e).free_symbols for e in parts):
                return ConstrainedDynamics(self._numeric, self.equations_of_motion, self.model)
        return self.dynamics()

    def _model_law(self, controller: str):
        """The model's [control] laws closed into its equations (controller="model"), kept."""
        from ..model.values import resolve_parameters
        from ..simulation.simulate import model_law

        found = self.__dict__.get("_closed_loop")
        if found is None or controller != "model":
            eom = self.equations_of_motion()
            substitution = resolve_parameters(self._model, None).symbol_values(self._model)
            found = self.__dict__["_closed_loop"] = model_law(eom, controller, (), substitution)
        return found
