"""Actuator models on top of the rigid-body dynamics, per coordinate, off unless asked for:

    M' = M + diag(armature),   b' = b + d q_dot + f_c sign(q_dot)

with d the viscous damping (N m s/rad or N s/m) and f_c the Coulomb friction (N m or N) of the
URDF's <dynamics damping friction>, and the armature the rotor inertia reflected through the
transmission (kg m^2 or kg; URDF has no standard tag for it, so it is given per joint). Then
tau = M' a + b' and q_ddot = M'^-1 (tau - b'). sign(0) = 0: a joint at rest feels no Coulomb
friction (no stiction model). C(q, q_dot) and g(q) stay the rigid body's (the armature is
constant; damping and friction are not Coriolis terms). On a floating base they act on the
joints only: the base's six numbers have no actuator.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from ..errors import InputError, ModelError, did_you_mean_or_list
from .joint_space import Dynamics, solve_positive
from .tree.free_flyer import BASE_VELOCITY
from .tree_terms import TreeTerms


def actuator_values(model, armature: Mapping[str, float] | None,
                    friction: bool) -> dict[str, np.ndarray]:
    """Per coordinate, in the model's order: damping, friction (the URDF's, when ``friction``)
    and armature (``armature`` by coordinate or URDF joint name; 0 for the others)."""
    coordinates = [c.name for c in model.coordinates]
    index = {name: k for k, name in enumerate(coordinates)}
    for coordinate, joint in model.source_names:
        index.setdefault(joint, index[coordinate])
    n = len(coordinates)
    values = {"damping": np.zeros(n), "friction": np.zeros(n), "armature": np.zeros(n)}
    if friction:
        for coordinate, damping, coulomb in model.source_dynamics:
            values["damping"][index[coordinate]] = damping
            values["friction"][index[coordinate]] = coulomb
    if armature is not None and not isinstance(armature, Mapping):
        raise InputError("expected a mapping of joint names to rotor inertias (kg m^2 or kg), "
                         f"got {type(armature).__name__}", field="armature")
    for name, value in (armature or {}).items():
        if name not in index:
            raise InputError(f"no joint named '{name}'"
                             f"{did_you_mean_or_list(str(name), list(index))}", field="armature")
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise InputError(f"the value {value!r} is not a number",
                             field=f"armature.{name}") from None
        if not (math.isfinite(value) and value >= 0):
            raise InputError(f"a rotor inertia is a finite number >= 0, got {value!r}",
                             field=f"armature.{name}")
        values["armature"][index[name]] = value
    return values


class ActuatedDynamics(TreeTerms, Dynamics):
    """A robot's dynamics with its actuators: armature on M's diagonal, viscous damping and
    Coulomb friction in the bias (module docstring); frames and the rest from the rigid body's
    dynamics underneath (``rigid``)."""

    def __init__(self, rigid: Dynamics, damping, friction, armature):
        self.rigid = rigid
        self.coordinates, self.n = rigid.coordinates, rigid.n
        self.velocity_names = rigid.velocity_names  # a floating base's nv = n + 6
        self.damping = np.array(damping, dtype=float)
        self.friction = np.array(friction, dtype=float)
        self.armature = np.array(armature, dtype=float)
        self.backend = getattr(rigid, "backend", "symbolic")

    def __repr__(self) -> str:
        return f"ActuatedDynamics({self.rigid!r})"

    # what is the rigid body's unchanged; not its numeric_system (simulation), which would
    # leave the actuators out
    _SHARED = frozenset({"model", "tree", "parameters", "regular"})

    def __getattr__(self, name):
        if name in ActuatedDynamics._SHARED:
            return getattr(self.__dict__["rigid"], name)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    @property
    def actuators(self) -> dict[str, dict[str, float]]:
        """Per joint coordinate: damping, friction, armature (SI); a floating base's six
        numbers have none."""
        names = self.velocity_names or self.coordinates
        base = 0 if self.velocity_names is None else len(BASE_VELOCITY)  # the twist's six
        return {c: {"damping": float(d), "friction": float(f), "armature": float(a)}
                for c, d, f, a in list(zip(names, self.damping, self.friction, self.armature,
                                           strict=True))[base:]}

    def _losses(self, v) -> np.ndarray:
        """d q_dot + f_c sign(q_dot)."""
        v = self._vector(v, "v")
        return self.damping * v + self.friction * np.sign(v)

    def mass_matrix(self, q) -> np.ndarray:
        """M(q) + diag(armature), shape (..., n, n)."""
        return self.rigid.mass_matrix(q) + np.diag(self.armature)

    def bias_forces(self, q, v) -> np.ndarray:
        """C q_dot + g + d q_dot + f_c sign(q_dot), shape (..., n)."""
        return self.rigid.bias_forces(q, v) + self._losses(v)

    def gravity(self, q) -> np.ndarray:
        """g(q), shape (..., n)."""
        return self.rigid.gravity(q)

    def coriolis_matrix(self, q, v) -> np.ndarray:
        """The rigid body's C(q, q_dot) (damping and friction are not in it)."""
        return self.rigid.coriolis_matrix(q, v)

    def inverse_dynamics(self, q, v, a, f_ext=None) -> np.ndarray:
        """tau = (M + diag(armature)) a + b + d q_dot + f_c sign(q_dot) - sum J^T w."""
        return (self.rigid.inverse_dynamics(q, v, a, f_ext) + self.armature * self._vector(a, "a")
                + self._losses(v))

    def forward_dynamics(self, q, v, tau, f_ext=None) -> np.ndarray:
        """q_ddot = (M + diag(armature))^-1 (tau + sum J^T w - b - d q_dot - f_c sign(q_dot)),
        NaN where that matrix is not positive definite."""
        if f_ext is not None:
            return self._with_wrenches(q, v, tau, f_ext, forward=True)

        def compute(Q, V, TAU):
            return solve_positive(self.rigid.mass_matrix(Q) + np.diag(self.armature),
                                  TAU - self.rigid.bias_forces(Q, V) - self._losses(V))

        return self._guarded(compute, (q, v, tau), ("q", "v", "tau"), (self.n,), forward=True)

    def kinetic_energy(self, q, v) -> np.ndarray:
        """T + 1/2 sum armature q_dot^2 (J)."""
        v_ = self._vector(v, "v")
        return self.rigid.kinetic_energy(q, v) + 0.5 * (self.armature * v_ * v_).sum(axis=-1)

    def potential_energy(self, q) -> np.ndarray:
        """V(q) in J."""
        return self.rigid.potential_energy(q)

    def _rigid_only(self, *args, **kwargs):
        """Derivatives and the regressor are the rigid body's: with actuators they would leave
        the damping, friction and armature out, so they are refused in one line."""
        raise InputError("derivatives and the inertial regressor are the rigid body's: call "
                         "them on dynamics() without actuators or armature (not yet with them)",
                         field="actuators")

    inverse_dynamics_derivatives = forward_dynamics_derivatives = _rigid_only
    regressor = inertial_parameters = base_parameters = _rigid_only


def actuated(rigid: Dynamics, model, armature: Mapping[str, float] | None = None,
             friction: bool = True) -> ActuatedDynamics:
    """``rigid`` with the actuator models: the URDF's damping and friction (``friction``) and
    the given armature."""
    constraints = getattr(rigid, "constraint_names", ())
    if constraints:  # (M + armature)^-1 (tau - b - losses) would leave the constraints out
        raise ModelError(f"actuator models need a model without constraints (this one has "
                         f"{len(constraints)}: {', '.join(constraints)})", field="actuators")
    values = actuator_values(model, armature, friction)
    base = rigid.n - len(values["damping"])  # a floating base's six: no actuator there
    return ActuatedDynamics(rigid, *(np.concatenate([np.zeros(base), values[key]])
                                     for key in ("damping", "friction", "armature")))


__all__ = ["ActuatedDynamics", "actuated", "actuator_values"]
