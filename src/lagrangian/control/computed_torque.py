"""Computed torque (feedback linearization) over a system's own dynamics:
tau = M(q) (q_ddot_d + Kd (q_dot_d - q_dot) + Kp (q_d - q)) + C(q, q_dot) q_dot + g(q).

On the model it was computed from, the error e = q_d - q then obeys e_ddot + Kd e_dot + Kp e = 0
exactly: with Kp = w^2 I and Kd = 2 w I (critical damping) each joint's error is
(e0 + (e0_dot + w e0) t) exp(-w t). Where q and v differ in length (a ball joint, a free flyer
below the root) the error is taken on the manifold, e = q_d (-) q (the dynamics' difference: q
(+) e = q_d, a ball's turn in its body's axes), and the law holds to first order in e (the
exponential map's Jacobian is 1 + O(e)). Units SI (rad or m; tau in N m or N; gains 1/s^2, 1/s).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, ModelError
from .gains import square_matrix


@dataclass(frozen=True, repr=False)
class ComputedTorque:
    """The computed-torque law as a controller (t, q, q_dot) -> tau (one generalized force per
    coordinate) for System.simulate; ``reference(t)`` gives (q_d, q_dot_d, q_ddot_d)."""

    dynamics: object
    coordinates: tuple[str, ...]
    Kp: np.ndarray
    Kd: np.ndarray
    reference: Callable[[float], tuple[np.ndarray, np.ndarray, np.ndarray]]
    inputs: tuple[str, ...] = ()  # generalized forces on every coordinate
    # q and v differ in length (ball joints, free flyers below the root): e = q_d (-) q
    manifold: bool = False

    @property
    def error_eigenvalues(self) -> np.ndarray:
        """The eigenvalues of the error dynamics [[0, I], [-Kp, -Kd]] (1/s)."""
        n = len(self.Kp)
        return np.linalg.eigvals(np.block([[np.zeros((n, n)), np.eye(n)], [-self.Kp, -self.Kd]]))

    def __call__(self, t, q, q_dot) -> np.ndarray:
        q_d, v_d, a_d = self.reference(t)
        q, v = np.asarray(q, dtype=float), np.asarray(q_dot, dtype=float)
        # a target of 1e308 m overflows Kp e: inf, quietly (the control loop refuses a command
        # that is not finite in one line; numpy's warning printed around it)
        with np.errstate(over="ignore", invalid="ignore"):
            error = self.dynamics.difference(q, q_d) if self.manifold else q_d - q
            command = a_d + self.Kd @ (v_d - v) + self.Kp @ error
            mass = self.dynamics.mass_matrix(q)
            return mass @ command + self.dynamics.bias_forces(q, v)

    def summary(self) -> dict:
        """JSON-ready: coordinates, gains, the error dynamics' eigenvalues (re, im)."""
        return {"coordinates": list(self.coordinates), "Kp": self.Kp.tolist(),
                "Kd": self.Kd.tolist(),
                "closed_loop_eigenvalues": [[float(v.real), float(v.imag)]
                                            for v in self.error_eigenvalues]}

    def __repr__(self) -> str:
        return f"ComputedTorque(coordinates={list(self.coordinates)})"


def computed_torque(system, q_des, Kp, Kd) -> ComputedTorque:
    """Computed torque on ``system`` (its dynamics(): an unconstrained model or a URDF robot).
    ``q_des`` is the reference: a configuration held still (an array in the coordinates' order,
    or name -> value, the others at the model's initial values), or a callable t -> (q_d,
    q_dot_d, q_ddot_d); ``Kp`` (1/s^2) and ``Kd`` (1/s) are numbers, diagonals or matrices,
    positive definite."""
    dynamics = system.dynamics()
    constraints = getattr(dynamics, "constraint_names", ())
    if constraints:  # M q_ddot = tau - bias would ignore the constraint forces
        raise ModelError(f"computed torque needs a model without constraints (this one has "
                         f"{len(constraints)}: {', '.join(constraints)})", field="constraints")
    velocities = getattr(dynamics, "velocity_names", None)
    tree = getattr(dynamics, "tree", None)
    if velocities is not None and not getattr(tree, "floating_base", False):
        # a ball joint or a free flyer below the root: every velocity number driven, the
        # error on the manifold
        n = len(velocities)
        Kp = square_matrix(Kp, n, "Kp", definite=True)
        Kd = square_matrix(Kd, n, "Kd", definite=True)
        return ComputedTorque(dynamics, tuple(velocities), Kp, Kd,
                              _reference(q_des, dynamics, system, manifold=True), manifold=True)
    if velocities is not None:
        # tau = M(q) q_ddot_d + b commands all nv forces, the base's wrench among them: a
        # floating base's simulation takes the joints' forces only (nothing pushes the base)
        raise ModelError("computed torque needs every coordinate actuated, and a floating "
                         "base's six are not (its wrench is the contacts'); load the robot "
                         "with a fixed base, or close the loop with a controller of the "
                         "joints (t, q, v) -> u", field="floating_base")
    names = tuple(dynamics.coordinates)
    n = len(names)
    Kp = square_matrix(Kp, n, "Kp", definite=True)
    Kd = square_matrix(Kd, n, "Kd", definite=True)
    reference = _reference(q_des, dynamics, system)
    return ComputedTorque(dynamics, names, Kp, Kd, reference)


def _reference(q_des, dynamics, system, manifold: bool = False):
    """t -> (q_d, q_dot_d, q_ddot_d), checked once at t = 0: a target by name, numbers in the
    coordinates' order, or a callable. ``manifold`` (q and v differ in length: a ball joint, a
    free flyer below the root): q_d of nq numbers with unit quaternions, the rates of nv, and
    names as simulate's start takes them (a ball's <ball>_qw..qz)."""
    names = tuple(dynamics.coordinates)
    nq = len(names)
    nv = len(dynamics.velocity_names) if manifold else nq
    if callable(q_des):
        reference = _called(q_des, (nq, nv, nv), f"q_d of {nq} values and q_dot_d, q_ddot_d "
                            f"of {nv}" if manifold else
                            f"three arrays of {nq} values ({', '.join(names)})")
        target = reference(0.0)[0]
    else:
        if isinstance(q_des, Mapping) and manifold:
            from ..simulation.tree_state import TreeState

            _, target, _ = TreeState(dynamics, system.model).start(system.model, dict(q_des))
        elif isinstance(q_des, Mapping):
            from ..model.values import resolve_state

            target = np.asarray(resolve_state(system.model, dict(q_des), field="q_des",
                                              velocities=False, time=False).q, dtype=float)
        else:
            target = np.asarray(q_des, dtype=float)
            if target.shape != (nq,):
                raise InputError(f"expected {nq} values ({', '.join(names)}), got shape "
                                 f"{target.shape}", field="q_des")
        if not np.all(np.isfinite(target)):
            raise InputError("the reference must be finite", field="q_des")
        zero = np.zeros(nv)
        reference = lambda t: (target, zero, zero)  # noqa: E731
    if manifold:
        dynamics.difference(target, target)  # a quaternion off unit norm: one line naming it
    return reference


def _called(q_des, widths: tuple[int, int, int], expected: str):
    """A reference callable t -> (q_d, q_dot_d, q_ddot_d) whose answers are checked: three
    arrays of the given widths, else one line saying what was expected."""
    def reference(t):
        value = q_des(t)
        if not (isinstance(value, tuple | list) and len(value) == 3):
            raise InputError("a reference callable must return (q_d, q_dot_d, q_ddot_d)",
                             field="q_des")
        parts = tuple(np.asarray(x, dtype=float) for x in value)
        if [x.shape for x in parts] != [(w,) for w in widths]:
            raise InputError(f"a reference callable must return {expected}, got shapes "
                             f"{[x.shape for x in parts]}", field="q_des")
        return parts

    return reference


