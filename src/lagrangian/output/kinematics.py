"""A robot frame's kinematics at one state (`kinematics`): text for a terminal, the JSON document."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np


def kinematics_document(coordinates, frame: str, reference: str, values: Mapping[str, Any],
                        velocities=None) -> dict[str, Any]:
    """The `kinematics --json` document: the frame, the reference of its Jacobian and every array
    as nested lists (SI: m, rad): q, placement, jacobian, center_of_mass,
    center_of_mass_jacobian; with --v also v and jacobian_dot_times_v (6); with --centroidal
    centroidal_momentum_matrix (6 x n) and, with --v, centroidal_momentum (6); a floating base
    adds ``nq``, ``nv`` and ``velocities`` (the names of the Jacobian's columns)."""
    document: dict[str, Any] = {"coordinates": list(coordinates), "frame": frame,
                                "reference": reference}
    if velocities is not None:
        document.update(nq=len(coordinates), nv=len(velocities), velocities=list(velocities))
    for key, value in values.items():
        document[key] = np.asarray(value, dtype=float).tolist()
    return document


_TITLES = {
    "q": "q", "placement": "placement (rotation | origin in m) in the world",
    "jacobian": "Jacobian [v; w] = J q_dot (linear rows first)",
    "center_of_mass": "centre of mass (m, world)",
    "center_of_mass_jacobian": "centre-of-mass Jacobian", "v": "q_dot",
    "jacobian_dot_times_v": "J_dot q_dot: [a; w_dot] at q_ddot = 0 (m/s^2, rad/s^2)",
    "centroidal_momentum_matrix": "centroidal momentum matrix A_g (linear rows first; angular "
                                  "about the centre of mass, world axes)",
    "centroidal_momentum": "centroidal momentum h_g = A_g q_dot (kg m/s, kg m^2/s)",
}


def kinematics_text(coordinates, frame: str, reference: str, values: Mapping[str, Any],
                    velocities=None) -> str:
    names = list(coordinates)
    lines = [f"Frame {frame}; coordinates {', '.join(names)} (SI: rad or m)"]
    if velocities is not None:  # a floating base: the Jacobian's columns are v's
        lines.append(f"Velocities (the Jacobian's columns): {', '.join(velocities)}")
    for key, value in values.items():
        array = np.asarray(value, dtype=float)
        title = _TITLES.get(key, key)
        if velocities is not None:  # a floating base: v is not q's rate (nv = nq - 1)
            title = title.replace("[v; w] = J q_dot", "J: the frame's [v; w] = J v")
            title = title.replace("q_ddot", "v_dot").replace("q_dot", "v")
        if key in ("jacobian", "jacobian_dot_times_v"):
            title += f", reference {reference}"
        lines.append(f"{title}:")
        rows = array[None] if array.ndim == 1 else array
        lines += ["  " + "  ".join(f"{x: .9g}" for x in row) for row in rows]
    return "\n".join(lines) + "\n"


__all__ = ["kinematics_document", "kinematics_text"]
