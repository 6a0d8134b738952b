"""What an input name stands for: a parameter (a load's magnitude), a load (its one parameter)
or a coordinate (a generalized force on it). Shared by linearization's B and the control loop."""

from __future__ import annotations

import sympy as sp

from ..errors import ModelError
from .expressions import as_expression
from .model import Model


def input_parameter(model: Model, name: str, field: str = "inputs") -> sp.Symbol | None:
    """The parameter an input name stands for; None for a generalized force on a coordinate."""
    for p in model.parameters:
        if p.name == name:
            return p.symbol
    for load in model.loads:
        if load.name == name:
            magnitude = (load.force if hasattr(load, "force") else
                         load.moment if hasattr(load, "moment") else (load.torque,))
            symbols = {s for e in magnitude for s in as_expression(e).free_symbols}
            owned = sorted((p for p in model.parameters if p.symbol in symbols),
                           key=lambda p: p.name)
            if len(owned) != 1:
                listed = ", ".join(p.name for p in owned) or "none"
                raise ModelError(
                    f"load '{name}' must contain exactly one parameter to serve as an input "
                    f"(it has: {listed}); name the parameter instead", field=field)
            return owned[0].symbol
    if name in {c.name for c in model.coordinates}:
        return None
    known = [p.name for p in model.parameters] + [ld.name for ld in model.loads] + \
        [c.name for c in model.coordinates]
    raise ModelError(f"'{name}' is not a parameter, load or coordinate of this model "
                     f"(inputs may be any of: {', '.join(known)})", field=field)
