"""Dynamics at one state (`dynamics`): text for a terminal and the JSON document."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np


def dynamics_document(coordinates, values: Mapping[str, Any],
                      joint_names: Mapping[str, str] | None = None,
                      velocities=None, constraints=None) -> dict[str, Any]:
    """The `dynamics --json` document: every array as nested lists, SI units; NaN (a state
    without dynamics, DynamicsWarning) as null; ``joint_names`` (coordinate -> the URDF's
    joint name, {} for a model file) under that key. A floating base adds ``nq``, ``nv`` and
    ``velocities``, the names of v (``coordinates`` are q's); a constrained model
    ``constraints``, their names, in the order of ``multipliers``."""
    document: dict[str, Any] = {"coordinates": list(coordinates)}
    if constraints:
        document["constraints"] = list(constraints)
    if velocities is not None:
        document.update(nq=len(coordinates), nv=len(velocities), velocities=list(velocities))
    if joint_names is not None:
        document["joint_names"] = dict(joint_names)
    for key, value in values.items():
        array = np.asarray(value, dtype=float)
        listed = array.tolist() if array.ndim else float(array)
        document[key] = _nan_as_null(listed)
    return document


def _nan_as_null(value):
    if isinstance(value, list):
        return [_nan_as_null(x) for x in value]
    return None if value != value else value


_TITLES = {
    "q": "q", "v": "q_dot", "a": "q_ddot (given)", "tau": "tau (given)",
    "mass_matrix": "mass matrix M(q)", "bias_forces": "bias forces C(q, q_dot) q_dot + g(q)",
    "gravity": "gravity g(q)", "coriolis_matrix": "Coriolis matrix C(q, q_dot)",
    "inverse_dynamics": "inverse dynamics tau = M q_ddot + C q_dot + g",
    "forward_dynamics": "forward dynamics q_ddot = M^-1 (tau - C q_dot - g)",
    "kinetic_energy": "kinetic energy T (J)", "potential_energy": "potential energy V (J)",
    "dtau_dq": "d tau/dq (row i: tau_i)", "dtau_dv": "d tau/dq_dot",
    "dqdd_dq": "d q_ddot/dq (row i: q_ddot_i)", "dqdd_dv": "d q_ddot/dq_dot",
    "dqdd_dtau": "d q_ddot/d tau = M^-1",
}
# A constrained model's forward dynamics is the multipliers' system, not M^-1 (tau - b)
# (derive's convention: M q_ddot + Phi_q^T lambda = f + tau, Phi_q q_ddot = gamma)
_CONSTRAINED_TITLES = {
    "forward_dynamics": "forward dynamics q_ddot, with the constraints: M q_ddot + Phi_q^T "
                        "lambda = tau - C q_dot - g, Phi_q q_ddot = gamma",
    "multipliers": "multipliers lambda (one per constraint; Phi_q^T lambda the constraint "
                   "forces' generalized part, taken from the left side)",
    "dqdd_dq": "d q_ddot/dq (row i: q_ddot_i; the constrained system's)",
    "dqdd_dv": "d q_ddot/dq_dot (the constrained system's)",
    "dqdd_dtau": "d q_ddot/d tau (the constrained system's, not M^-1)",
}


def _loaded_titles(actuators: bool, wrenches: bool) -> dict[str, str]:
    """The titles whose equation the actuator models (armature on M's diagonal, viscous and
    Coulomb friction in the bias) and wrenches at frames change: each says what was computed."""
    if not (actuators or wrenches):
        return {}
    mass, losses = ("(M + diag(armature))", " + d q_dot + f_c sign(q_dot)") if actuators \
        else ("M", "")
    outside = " - sum J^T w" if wrenches else ""
    titles = {
        "inverse_dynamics": f"inverse dynamics tau = {mass} q_ddot + C q_dot + g{losses}{outside}",
        "forward_dynamics": f"forward dynamics q_ddot = {mass}^-1 (tau"
                            f"{' + sum J^T w' if wrenches else ''} - C q_dot - g"
                            f"{losses.replace(' + ', ' - ')})",
    }
    if actuators:
        titles.update({
            "mass_matrix": "mass matrix M(q) + diag(armature)",
            "bias_forces": f"bias forces C(q, q_dot) q_dot + g(q){losses}",
            "coriolis_matrix": "Coriolis matrix C(q, q_dot) (the rigid bodies': damping and "
                               "friction are not in it)",
            "kinetic_energy": "kinetic energy T (J; the links', without the rotors')",
        })
    return titles


def dynamics_text(coordinates, values: Mapping[str, Any], velocities=None,
                  extra: Mapping[str, Any] | None = None, constraints=None) -> str:
    """``velocities``: the names of v, a and tau where they are not q's (a floating base);
    ``extra``: the wrenches at frames and the actuator models the values include (`--wrench`,
    `--actuators`, `--armature`); ``constraints``: a constrained model's names (its forward
    dynamics and derivatives are titled as the multipliers' system's, ``multipliers`` listed
    by constraint)."""
    titles = {**_TITLES, **_CONSTRAINED_TITLES} if constraints else dict(_TITLES)
    titles.update(_loaded_titles(bool((extra or {}).get("actuators")),
                                 bool((extra or {}).get("wrenches"))))
    if velocities is not None:  # a floating base: v is not q's rate (nv = nq - 1)
        titles = {key: title.replace("q_ddot", "v_dot").replace("q_dot", "v")
                  for key, title in titles.items()}
    names = list(coordinates)
    rates = names if velocities is None else list(velocities)
    width = max(len(n) for n in names + rates + list(constraints or ()))
    lines = [f"Coordinates: {', '.join(names)} (SI: rad or m; tau in N m or N)"]
    if velocities is not None:  # a floating base's twist, a ball's angular velocity
        what = (["the base's twist in its own axes: m/s, rad/s; its tau is the wrench on it: "
                 "N, N m"] if "base_vx" in rates else []) + (
            ["a ball joint's w x y z quaternion and its angular velocity in its body's axes: "
             "rad/s; its tau the moment, N m"] if any(n.endswith("_qw") and n != "base_qw"
                                                     for n in names) else [])
        lines.append(f"Velocities: {', '.join(rates)} ({'; '.join(what)})")
    for key, value in values.items():
        array = np.asarray(value, dtype=float)
        title = titles.get(key, key)
        if array.ndim == 0:
            lines.append(f"{title}: {float(array):.9g}")
        elif array.ndim == 1:
            lines.append(f"{title}:")
            labels = (names if key == "q" else list(constraints) if key == "multipliers"
                      else rates)
            lines += [f"  {n:<{width}}  {x: .9g}" for n, x in zip(labels, array, strict=True)]
        else:
            lines.append(f"{title}:")
            lines += ["  " + "  ".join(f"{x: .9g}" for x in row) for row in array]
    for frame, wrench in (extra or {}).get("wrenches", {}).items():
        lines.append(f"wrench at {frame} (N, N m; world axes, at its origin): "
                     + " ".join(f"{x:.9g}" for x in wrench))
    actuators = (extra or {}).get("actuators")
    if actuators:
        lines.append("actuators: damping (N m s/rad or N s/m), friction (N m or N), armature "
                     "(kg m^2 or kg):")
        lines += [f"  {n:<{width}}  {a['damping']: .9g}  {a['friction']: .9g}  "
                  f"{a['armature']: .9g}" for n, a in actuators.items()]
    return "\n".join(lines) + "\n"
