"""Linearization along a trajectory: x_dot = A(t) x + B(t) u about a run's saved samples, x =
[q; q_dot], from the derivatives of forward dynamics (dynamics/derivatives.py; a constrained
model's dynamics/constrained.py) at each sample,
with the controller's generalized forces of that run held in place (SI units). A tree whose q
holds quaternions (ball joints, free flyers) in its tangent: x = [dq; v], q = q_run (+) dq."""

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
    if tuple(simulation.coordinates) != names:
        raise InputError("the simulation is not of this system (its coordinates are "
                         f"{', '.join(simulation.coordinates)})", field="simulation")
    tree = getattr(getattr(dynamics, "model", None), "kinematic_tree", None)
    manifold = tree is not None and bool(tree.floating_base or tree.quaternion_joints)
    if manifold and independent is not None:
        raise InputError("a tree has no constraints to reduce by: leave independent out",
                         field="independent")
    # the velocity numbers: q's own where q_dot = v; a ball's angular velocity, a free flyer's
    # twist where q holds a quaternion (the generalized forces u act on them)
    velocities = tuple(dynamics.velocity_names) if manifold else names
    inputs = velocities if inputs is None else tuple(inputs)
    unknown = [name for name in inputs if name not in velocities]
    if unknown:
        raise InputError(f"'{unknown[0]}' is not a coordinate (inputs along a run are the "
                         f"generalized forces on: {', '.join(velocities)})", field="inputs")
    q, v = np.asarray(simulation.q, dtype=float), np.asarray(simulation.q_dot, dtype=float)
    forces = simulation.control_forces
    tau = np.zeros_like(v) if forces is None else np.asarray(forces, dtype=float)
    t = np.asarray(simulation.t, dtype=float)
    # dynamics/constrained.py's at each sample's time (moving constraints, explicit t)
    timed = {"t": t} if getattr(dynamics, "timed", False) else {}
    by_position, by_velocity, by_force = dynamics.forward_dynamics_derivatives(q, v, tau, **timed)
    count, n = v.shape
    A = np.zeros((count, 2 * n, 2 * n))
    A[:, :n, n:] = np.eye(n)
    A[:, n:, :n], A[:, n:, n:] = by_position, by_velocity
    if manifold:  # the tangent's own drift: q = q_run (+) dq moves dq by -ad(v_run) dq
        _tangent_drift(tree, v, A[:, :n, :n])
    columns = [velocities.index(name) for name in inputs]
    B = np.zeros((count, 2 * n, len(columns)))
    B[:, n:, :] = by_force[:, :, columns]
    if manifold:
        turned = _turned_numbers(tree)
        states = (*(f"delta_{c}" if i in turned else c for i, c in enumerate(velocities)),
                  *simulation.rate_names)
        return TrajectoryLinearization(t, A, B, states, inputs)
    if independent is None:
        return TrajectoryLinearization(t, A, B, (*names, *(f"{c}_dot" for c in names)), inputs)
    from .manifold import reduce_to_manifold

    A, B, kept, dependent = reduce_to_manifold(
        dynamics, TrajectoryLinearization(t, A, B, (), inputs), q, v, t, independent)
    return TrajectoryLinearization(t, A, B, (*kept, *(f"{c}_dot" for c in kept)), inputs,
                                   dependent)


def _flyers(tree) -> list[int]:
    """Where each free flyer's twist (linear, then angular, in its own axes) starts in v: the
    floating base's, then each one below the root."""
    return ([0] if tree.floating_base else []) + [
        tree.base_nv + tree.velocity_index(j.coordinate) for j in tree.free_joints]


def _turned_numbers(tree) -> set[int]:
    """The velocity numbers whose configuration is on a manifold (a ball's three, a free
    flyer's six): their state in x is the tangent dq, named delta_<velocity>."""
    from ..dynamics.tree.spherical import ball_slices

    balls = {iv + k for _, _, iv in ball_slices(tree) for k in range(3)}
    return balls | {iv + k for iv in _flyers(tree) for k in range(6)}


def _tangent_drift(tree, v: np.ndarray, block: np.ndarray) -> None:
    """d(dq)/dt = dv - ad(v) dq, into ``block`` (N, n, n) (the q-q block of A): the right
    perturbation q (+) dq of the derivatives (Pinocchio's dIntegrate: R = R_run exp([dq]x) for
    a ball, d(dq)/dt = dw - w x dq; a free flyer's twist (v_lin, w): -[[w]x, [v_lin]x; 0, [w]x]),
    zero for a number with q_dot = v."""
    from ..dynamics.regressor import cross_matrix
    from ..dynamics.tree.spherical import ball_slices

    for _, _, iv in ball_slices(tree):
        block[:, iv:iv + 3, iv:iv + 3] = -cross_matrix(v[:, iv:iv + 3])
    for iv in _flyers(tree):
        linear, angular = cross_matrix(v[:, iv:iv + 3]), cross_matrix(v[:, iv + 3:iv + 6])
        block[:, iv:iv + 3, iv:iv + 3] = -angular
        block[:, iv:iv + 3, iv + 3:iv + 6] = -linear
        block[:, iv + 3:iv + 6, iv + 3:iv + 6] = -angular
