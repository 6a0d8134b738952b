"""Every quantity of the dynamics at one state, judged: what `lagrangian dynamics` prints.

The numbers come from a Dynamics (System.dynamics); here they are judged as numbers: a state
without dynamics (M not positive definite there, a DynamicsWarning) is NaN and named in one
warning line, and a value that is not finite otherwise (an overflow) is refused.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from ..errors import DerivationError, DynamicsWarning


@dataclass(frozen=True)
class StateDynamics:
    """The values at one state by key, in the order printed (q, v, mass_matrix, bias_forces,
    gravity, then a and inverse_dynamics or tau and forward_dynamics, their derivatives, the
    Coriolis matrix, kinetic_energy and potential_energy; SI units), the constraints' names
    (the order of ``multipliers``) and ``warnings``: one line per finding, for the user."""

    values: dict[str, Any]
    constraints: tuple[str, ...]
    undefined: tuple[str, ...]  # the keys whose values are all NaN: no dynamics at this state
    warnings: tuple[str, ...]


def state_dynamics(dynamics, q: Sequence[float], v: Sequence[float], *,
                   a: Sequence[float] | None = None, tau: Sequence[float] | None = None,
                   f_ext: Mapping[str, Sequence[float]] | None = None,
                   derivatives: bool = False, coriolis: bool = False) -> StateDynamics:
    """M(q), the bias C q_dot + g, g(q), with ``a`` the inverse dynamics tau = M a + C q_dot + g
    (N, N m), with ``tau`` the forward dynamics q_ddot (and a constrained model's multipliers),
    ``derivatives`` their derivatives, ``coriolis`` C(q, q_dot), and the energies T, V (J).
    A value that is not finite where the dynamics are defined (an overflow: m L^2 of 1e299
    each) is a DerivationError naming it."""
    import numpy as np

    constraints = tuple(getattr(dynamics, "constraint_names", ()) or ())
    with np.errstate(over="ignore", invalid="ignore"), \
            warnings.catch_warnings(record=True) as seen:
        # a state without dynamics (M not positive definite) is a DynamicsWarning and NaN
        warnings.simplefilter("always", DynamicsWarning)
        values: dict[str, Any] = {
            "q": list(q), "v": list(v), "mass_matrix": dynamics.mass_matrix(q),
            "bias_forces": dynamics.bias_forces(q, v), "gravity": dynamics.gravity(q)}
        if a is not None:
            values["a"] = list(a)
            values["inverse_dynamics"] = dynamics.inverse_dynamics(q, v, a, f_ext=f_ext)
            if derivatives:
                values["dtau_dq"], values["dtau_dv"] = (  # + 0.0: no -0 printed
                    x + 0.0 for x in dynamics.inverse_dynamics_derivatives(q, v, a))
        if tau is not None:
            values["tau"] = list(tau)
            values["forward_dynamics"] = dynamics.forward_dynamics(q, v, tau, f_ext=f_ext)
            if constraints:
                values["multipliers"] = dynamics.multipliers(q, v, tau)
            if derivatives:
                values["dqdd_dq"], values["dqdd_dv"], values["dqdd_dtau"] = (
                    x + 0.0 for x in dynamics.forward_dynamics_derivatives(q, v, tau))
        if coriolis:
            values["coriolis_matrix"] = dynamics.coriolis_matrix(q, v)
        values["kinetic_energy"] = dynamics.kinetic_energy(q, v)
        values["potential_energy"] = dynamics.potential_energy(q)
    lines = []
    undefined: tuple[str, ...] = ()
    if any(issubclass(w.category, DynamicsWarning) for w in seen):
        undefined = tuple(key for key, value in values.items()
                          if np.isnan(np.asarray(value, dtype=float)).all())
        named = ", ".join(key.replace("_", " ") for key in undefined) or "dynamics"
        lines.append(f"no {named} at this state: the mass matrix is not positive definite "
                     "there (or an input is not finite); shown as NaN (null in JSON)")
    for key, value in values.items():
        if key not in undefined and not np.all(np.isfinite(np.asarray(value, dtype=float))):
            raise DerivationError(f"the {key.replace('_', ' ')} is not finite at this state "
                                  "(a number beyond floating point, or a state outside the "
                                  "model's domain)")
    return StateDynamics(values, constraints, undefined, tuple(lines))


def state_kinematics(kinematics, q: Sequence[float], frame: str, reference: str,
                     v: Sequence[float] | None = None, centroidal: bool = False
                     ) -> dict[str, Any]:
    """A frame's placement (4 x 4) and Jacobian (6 x nv), the centre of mass (m) and its
    Jacobian, with ``v`` J_dot q_dot ([a; w_dot] at q_ddot = 0, m/s^2 and rad/s^2), with
    ``centroidal`` A_g (and A_g q_dot, kg m/s and kg m^2/s). A value that is not finite (an
    overflow: a rate of 1e200 rad/s squared) is a DerivationError naming it."""
    import numpy as np

    with np.errstate(over="ignore", invalid="ignore"):
        values: dict[str, Any] = {
            "q": q, "placement": kinematics.placement(q, frame),
            "jacobian": kinematics.jacobian(q, frame, reference),
            "center_of_mass": kinematics.center_of_mass(q),
            "center_of_mass_jacobian": kinematics.center_of_mass_jacobian(q)}
        if v is not None:
            values["v"] = v
            values["jacobian_dot_times_v"] = kinematics.jacobian_dot_times_v(q, v, frame,
                                                                           reference)
        if centroidal:
            values["centroidal_momentum_matrix"] = kinematics.centroidal_momentum_matrix(q)
            if v is not None:
                values["centroidal_momentum"] = values["centroidal_momentum_matrix"] @ v
    named = {"jacobian_dot_times_v": "J_dot q_dot", "centroidal_momentum": "A_g q_dot",
             "centroidal_momentum_matrix": "the centroidal momentum matrix A_g"}
    for key, value in values.items():
        if not np.all(np.isfinite(np.asarray(value, dtype=float))):
            raise DerivationError(f"{named.get(key, 'the ' + key.replace('_', ' '))} is not "
                                  "finite at this state (a number beyond floating point)")
    return values

