"""Controllers for the loop of System.simulate: linear-quadratic regulation about a linear
model (lqr.py) and computed torque over a system's dynamics (computed_torque.py).

Each is a callable (t, q, q_dot) -> u that System.simulate(controller=...) takes as it is.
"""

from .along import TrajectoryLinearization, linearize_along
from .computed_torque import ComputedTorque, computed_torque
from .lqr import LQR, lqr

__all__ = ["LQR", "ComputedTorque", "TrajectoryLinearization", "computed_torque", "linearize_along",
           "lqr"]
