"""Linearization along a trajectory: x_dot = A(t) x + B(t) u about a run's saved samples, x =
[q; q_dot], from the derivatives of forward dynamics (dynamics/derivatives.py; a constrained
model's dynamics/constrained.py) at each sample,
with the controller's generalized forces of that run held in place (SI units)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError


@dataclass(frozen=True, repr=False)
class TrajectoryLinearization:
    """A(t) (N, 2n, 2n) and B(t) (N, 2n, r) at the run's sample times t (N,): the variation
    dx_dot = A dx + B du of x = [q; q_dot] about the run, u the generalized forces on
    ``inputs`` (coordinates) on top of the run's own."""

    t: np.ndarray
    A: np.ndarray
    B: np.ndarray
    state_names: tuple[str, ...]
    inputs: tuple[str, ...]
    dependent: tuple[str, ...] = ()  # on the constraint manifold: the coordinates left out

    def __len__(self) -> int:
        return len(self.t)

    def summary(self) -> dict:
        """JSON-ready: t (s), the states, the inputs, A (N x 2n x 2n) and B (N x 2n x r); on
        the constraint manifold also the dependent coordinates left out of the states."""
        document = {"t": self.t.tolist(), "states": list(self.state_names),
                    "inputs": list(self.inputs), "A": self.A.tolist(), "B": self.B.tolist()}
        if self.dependent:
            document["dependent"] = list(self.dependent)
        return document

    def __repr__(self) -> str:
        tied = f", dependent={list(self.dependent)}" if self.dependent else ""
        return (f"TrajectoryLinearization({len(self.t)} samples, states="
                f"{list(self.state_names)}, inputs={list(self.inputs)}{tied})")


def linearize_along(dynamics, simulation, inputs=None,
                    independent=None) -> TrajectoryLinearization:
    """A(t), B(t) of ``dynamics`` (System.dynamics(); a constrained model's through its
    multipliers: A(t) of the index-1 form in all n coordinates, or with ``independent`` (n - m
    coordinate names, or "auto") on the constraint manifold, control/manifold.py) about
    ``simulation``'s samples; ``inputs`` names the coordinates whose generalized forces are u
    (default all)."""
    names = tuple(dynamics.coordinates)
    _refuse_quaternions(dynamics)
    if tuple(simulation.coordinates) != names:
        raise InputError("the simulation is not of this system (its coordinates are "
                         f"{', '.join(simulation.coordinates)})", field="simulation")
    inputs = names if inputs is None else tuple(inputs)
    unknown = [name for name in inputs if name not in names]
    if unknown:
        raise InputError(f"'{unknown[0]}' is not a coordinate (inputs along a run are the "
                         f"generalized forces on: {', '.join(names)})", field="inputs")
    q, v = np.asarray(simulation.q, dtype=float), np.asarray(simulation.q_dot, dtype=float)
    forces = simulation.control_forces
    tau = np.zeros_like(q) if forces is None else np.asarray(forces, dtype=float)
    t = np.asarray(simulation.t, dtype=float)
    # dynamics/constrained.py's at each sample's time (moving constraints, explicit t)
    timed = {"t": t} if getattr(dynamics, "timed", False) else {}
    by_position, by_velocity, by_force = dynamics.forward_dynamics_derivatives(q, v, tau, **timed)
    count, n = q.shape
    A = np.zeros((count, 2 * n, 2 * n))
    A[:, :n, n:] = np.eye(n)
    A[:, n:, :n], A[:, n:, n:] = by_position, by_velocity
    columns = [names.index(name) for name in inputs]
    B = np.zeros((count, 2 * n, len(columns)))
    B[:, n:, :] = by_force[:, :, columns]
    if independent is None:
        return TrajectoryLinearization(t, A, B, (*names, *(f"{c}_dot" for c in names)), inputs)
    from .manifold import reduce_to_manifold

    A, B, kept, dependent = reduce_to_manifold(
        dynamics, TrajectoryLinearization(t, A, B, (), inputs), q, v, t, independent)
    return TrajectoryLinearization(t, A, B, (*kept, *(f"{c}_dot" for c in kept)), inputs,
                                   dependent)


def _refuse_quaternions(dynamics) -> None:
    """One line for a tree whose q and v differ (a ball joint, a floating joint or base): A(t)
    here is built on q_dot = v."""
    tree = getattr(getattr(dynamics, "model", None), "kinematic_tree", None)
    joints = getattr(tree, "quaternion_joints", ()) or ()
    if tree is None or not (joints or tree.floating_base):
        return
    if not joints:
        raise InputError("a floating base is not linearized along a run yet (q_dot is not v "
                         "for its quaternion)", field="simulation")
    raise InputError(f"the joint '{joints[0].name}' is not linearized along a run yet (q_dot is "
                     "not v for its quaternion); linearize and lqr take it about a rest, in "
                     "its Euler angles", field="simulation")
