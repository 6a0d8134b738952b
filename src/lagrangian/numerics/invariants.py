"""Which quantity a run should conserve, asked of the symbolic equations once per run.

For now the total energy T + V: conserved when nothing dissipates, no non-conservative load
acts and nothing depends on t explicitly. (A Jacobi integral or a work balance would cover
more models; this is the one place to change.)
"""

from __future__ import annotations

from ..derivation.equations import EquationsOfMotion
from ..model.expressions import as_expression


def energy_is_conserved(eom: EquationsOfMotion) -> bool:
    """No dissipation, no non-conservative loads, no explicit time dependence."""
    model = eom.model
    t = model.time
    if eom.dissipation != 0 or any(Q != 0 for Q in eom.generalized_forces):
        return False
    terms = [eom.kinetic_energy, eom.potential_energy, *eom.mass_matrix, *eom.forcing,
             *(c.expression for c in model.constraints)]
    return not any(t in as_expression(e).free_symbols for e in terms)
