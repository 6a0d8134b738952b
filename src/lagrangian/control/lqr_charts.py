"""LQR on a robot with ball joints (or a floating joint between links): the linear model is in
the model's Euler angles theta (dynamics/tree/model_charts.py, as equilibria and modes take
it), the run in the tree's quaternions. The controller reads theta from q on the Euler branch
nearest the equilibrium and theta_dot = E(theta)^-1 v (v = E theta_dot), and gives its
generalized forces Q_theta = B_q u back as the tree's, tau = E^-T Q_theta (virtual work:
Q_theta . dtheta = tau . E dtheta), so a ball's moment in its body's axes (N m)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError

if TYPE_CHECKING:  # loaded where a tree has a ball (tree_charts): linearize's path stays small
    from ..dynamics.tree.model_charts import ModelCharts


@dataclass(frozen=True)
class TreeCharts:
    """The model's Euler charts of a tree, and the input names that are generalized forces
    there (its coordinates and its actuators' tau_<joint>)."""

    charts: ModelCharts
    forces: tuple[str, ...]

    @property
    def nq(self) -> int:
        return self.charts.nq

    def model_state(self, q, v, near: np.ndarray):
        """(theta, theta_dot, E) of the tree's (q, v), theta nearest ``near`` (rad, m)."""
        theta = self.charts.angles(np.asarray(q, dtype=float), near)
        if self.charts.singular(theta):
            raise InputError("the state reached gimbal lock of a ball joint's Euler angles "
                             "(the middle one at +-90 deg), where the LQR's linear model has "
                             "no coordinates", field="controller")
        E = self.charts.rates(theta)
        return theta, np.linalg.solve(E, np.asarray(v, dtype=float)[..., None])[..., 0], E

    @staticmethod
    def torques(E: np.ndarray, forces: np.ndarray) -> np.ndarray:
        """The tree's generalized forces tau = E^-T Q_theta (nv)."""
        return np.linalg.solve(np.swapaxes(E, -1, -2), forces[..., None])[..., 0]

    def check_inputs(self, inputs) -> None:
        """Every input a generalized force in theta (a coordinate or an actuator): a parameter
        such as g has no torque that the run can apply."""
        for name in inputs:
            if name not in self.forces:
                raise InputError(f"on a robot with a ball joint LQR drives its coordinates or "
                                 f"actuators ({', '.join(self.forces)}), not '{name}'",
                                 field="inputs")


def tree_charts(system) -> TreeCharts | None:
    """The Euler charts of a fixed-base tree with a ball joint or a floating joint between
    links; None where the model's coordinates are the tree's own."""
    model = system.model
    tree = model.kinematic_tree
    if tree is None or tree.floating_base or not tree.quaternion_joints \
            or not system.runs_on_tree:
        return None
    from ..dynamics.tree.model_charts import ModelCharts

    actuators = tuple(a for a in tree.actuators if a)
    return TreeCharts(ModelCharts(model, system.dynamics().velocity_names),
                      (*(c.name for c in model.coordinates), *actuators))


def refuse_state_names(system, about) -> None:
    """One line for a run's number (a ball's shoulder_qw, its shoulder_wx) named where the
    model's coordinates are wanted (linearize's and modes' ``about``), naming the joint's."""
    tree = system.model.kinematic_tree
    if not about or tree is None or not tree.quaternion_joints:
        return
    dynamics = system.dynamics()
    model = [c.name for c in system.model.coordinates]
    run = set(dynamics.coordinates) | set(dynamics.velocity_names)
    for key in map(str, dict(about)):
        if key in run and key not in model:
            joint = key.rsplit("_", 1)[0]
            own = [c for c in model if c.startswith(f"{joint}_")]
            raise InputError(f"'{key}' is a number of the run's state; a linear model takes "
                             f"the model's coordinates, for the joint '{joint}' "
                             f"{', '.join(own)} (a ball's Euler angles, R = Rx Ry Rz, rad; a "
                             "floating joint's x y z, roll pitch yaw)", field="about")


__all__ = ["TreeCharts", "refuse_state_names", "tree_charts"]
