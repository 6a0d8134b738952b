"""Dynamics at one state (`dynamics`): text for a terminal and the JSON document."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np


def dynamics_document(coordinates, values: Mapping[str, Any],
                      joint_names: Mapping[str, str] | None = None) -> dict[str, Any]:
    """The `dynamics --json` document: every array as nested lists, SI units; NaN (a state
    without dynamics, DynamicsWarning) as null; ``joint_names`` (coordinate -> the URDF's
    joint name, {} for a model file) under that key."""
    document: dict[str, Any] = {"coordinates": list(coordinates)}
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


def dynamics_text(coordinates, values: Mapping[str, Any]) -> str:
    names = list(coordinates)
    width = max(len(n) for n in names)
    lines = [f"Coordinates: {', '.join(names)} (SI: rad or m; tau in N m or N)"]
    for key, value in values.items():
        array = np.asarray(value, dtype=float)
        title = _TITLES.get(key, key)
        if array.ndim == 0:
            lines.append(f"{title}: {float(array):.9g}")
        elif array.ndim == 1:
            lines.append(f"{title}:")
            lines += [f"  {n:<{width}}  {x: .9g}" for n, x in zip(names, array, strict=True)]
        else:
            lines.append(f"{title}:")
            lines += ["  " + "  ".join(f"{x: .9g}" for x in row) for row in array]
    return "\n".join(lines) + "\n"
