"""The regressor at one state (`regressor`): the JSON document and its text."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import DerivationError


def regressor_document(coordinates, names, values, Y, base=None,
                       velocities=None) -> dict[str, Any]:
    """coordinates, parameters (names and the model's values pi), the regressor Y (n x k
    nested lists, tau = Y pi), tau; with ``base`` its names, tolerance and combination
    (beta = combination pi); ``velocities`` where q and v differ (a floating base, a ball
    joint), the names of Y's rows and tau's (``coordinates`` are q's). SI units."""
    Y = np.asarray(Y, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is refused just below
        tau = Y @ np.asarray(values, dtype=float)
    for what, value in (("regressor Y", Y), ("torque tau = Y pi", tau)):
        if not np.all(np.isfinite(value)):  # as the dynamics' own values (api/state_dynamics)
            raise DerivationError(f"the {what} is not finite at this state (a number beyond "
                                  "floating point: an acceleration of 1e308 times a mass)")
    document: dict[str, Any] = {
        "coordinates": list(coordinates),
        "parameters": list(names),
        "values": [float(x) for x in values],
        "regressor": Y.tolist(),
        "tau": tau.tolist(),
    }
    if velocities is not None:
        document["velocities"] = list(velocities)
    if base is not None:
        document["base"] = {"tolerance": base.tolerance, "names": list(base.base_names),
                            "combination": base.combination.tolist(),
                            "values": base.values(values).tolist(),
                            "description": base.describe()}
    return document


def regressor_text(document: dict[str, Any]) -> str:
    """The parameters with their values, Y row by row, tau; the base set when present."""
    names = document["parameters"]
    rows = document.get("velocities", document["coordinates"])
    lines = [f"Coordinates: {', '.join(document['coordinates'])}; tau = Y pi "
             f"({len(names)} parameters, SI)"]
    if "velocities" in document:
        lines.append(f"Velocities (Y's rows): {', '.join(rows)}")
    lines.append("parameters pi:")
    width = max(len(n) for n in names)
    lines += [f"  {n:<{width}}  {x: .9g}" for n, x in zip(names, document["values"], strict=True)]
    lines.append("regressor Y (one row per "
                 f"{'velocity' if 'velocities' in document else 'coordinate'}):")
    lines += ["  " + "  ".join(f"{x: .6g}" for x in row) for row in document["regressor"]]
    lines.append("tau = Y pi:")
    lines += [f"  {c}  {x: .9g}" for c, x in zip(rows, document["tau"], strict=True)]
    base = document.get("base")
    if base is not None:
        lines.append(f"base parameters ({len(base['names'])} of {len(names)}, tolerance "
                     f"{base['tolerance']:g}), beta = each line's combination:")
        lines += [f"  {line}" for line in base["description"]]
    return "\n".join(lines) + "\n"
