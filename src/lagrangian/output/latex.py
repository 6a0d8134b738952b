"""LaTeX for papers and notebooks: energies, equations, generalized forces, matrices."""

from __future__ import annotations

import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..model.notation import latex_symbol_names


def derivation_latex(eom: EquationsOfMotion) -> str:
    """A self-contained LaTeX fragment (amsmath) ready to paste into a paper."""
    model = eom.model
    names = latex_symbol_names(model)

    def tex(expr) -> str:
        return sp.latex(expr, symbol_names=names)

    lines = [f"% {model.name}: equations of motion by Lagrange's method",
             r"% Convention: M \ddot{q} + \Phi_q^T \lambda = f", r"\begin{align}"]
    lines.append(rf"T &= {tex(eom.kinetic_energy)} \\")
    lines.append(rf"V &= {tex(eom.potential_energy)} \\")
    if eom.dissipation != 0:
        lines.append(rf"D &= {tex(eom.dissipation)} \\")
    lines.append(rf"L &= T - V = {tex(eom.lagrangian)} \\")
    for c, total in zip(model.coordinates, eom.generalized_forces, strict=True):
        lines.append(rf"Q_{{{tex(c.symbol)}}} &= {tex(total)} \\")
    for c, equation in zip(model.coordinates, eom.equations, strict=True):
        lines.append(rf"0 &= {tex(equation)} && \text{{({c.name})}} \\")
    lines.append(rf"M &= {tex(eom.mass_matrix)} \\")
    lines.append(rf"f &= {tex(eom.forcing)}")
    if model.constraints:
        lines[-1] += r" \\"
        lines.append(rf"\Phi_q &= {tex(eom.constraint_jacobian)} \\")
        lines.append(rf"\gamma &= {tex(eom.acceleration_rhs)}")
    lines.append(r"\end{align}")
    return "\n".join(lines) + "\n"
