"""How the model's symbols are written in LaTeX: q_dot as a dot over q, multipliers as lambda."""

from __future__ import annotations

import sympy as sp

from .model import Model, multiplier_name


def latex_symbol_names(model: Model) -> dict[sp.Symbol, str]:
    """Symbol -> LaTeX for velocities, accelerations and multipliers of ``model``."""
    names: dict[sp.Symbol, str] = {}
    for c in model.coordinates:
        base = sp.latex(c.symbol)
        names[c.velocity] = rf"\dot{{{base}}}"
        names[c.acceleration] = rf"\ddot{{{base}}}"
    for constraint in model.constraints:
        label = constraint.name.replace("_", r"\_")
        names[sp.Symbol(multiplier_name(constraint.name))] = rf"\lambda_{{\mathrm{{{label}}}}}"
    return names
