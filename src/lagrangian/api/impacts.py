"""System methods for models with impacts: the derived impact maps, a run through the impacts
and the limit cycle of a walker (derivation/impact_map.py, simulation/hybrid.py,
analysis/limit_cycle.py)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

from ..errors import InputError

if TYPE_CHECKING:  # imported by the methods that use them (issue 38)
    from ..analysis.limit_cycle import LimitCycle
    from ..derivation.impact_map import ImpactMap


class ImpactMethods:
    """impact_maps(), limit_cycle(guess) and the run through impacts of a System."""

    def impact_maps(self) -> tuple[ImpactMap, ...]:
        """Each impact's map in symbols: M, the rows J of the striking point's velocity the law
        sets, E, the guard and the relabelling (derived once per System)."""
        from ..derivation.impact_map import derive_impact_maps

        found = self.__dict__.get("_impact_maps")
        if found is None:
            found = self.__dict__["_impact_maps"] = derive_impact_maps(
                self.equations_of_motion())
        return found

    def limit_cycle(self, guess: Mapping[str, float] | None = None) -> LimitCycle:
        """The periodic orbit through the model's impacts (a walker's gait): ``.state`` just
        after the impact (by name, SI), ``.period`` (s), ``.multipliers`` (the linearized
        Poincare map's eigenvalues, exact to integration tolerance) and ``.stable``. ``guess``:
        a state just after an impact (default: the model's initial state, carried to one)."""
        from ..analysis.limit_cycle import limit_cycle
        from ..model.values import resolve_parameters

        if not self.model.impacts:
            raise InputError("the model has no impacts ([[impacts]]): no cycle through one",
                             field="impacts")
        eom = self.equations_of_motion()
        values = resolve_parameters(self.model, None)
        return limit_cycle(eom, values.symbol_values(self.model), self._numeric, guess,
                           maps=self.impact_maps())

    def _run_through_impacts(self, t_end, start, step_control, save_at, progress, stop,
                             controller, max_impacts, settle):
        """simulate()'s run for a model with impacts (simulation/hybrid.py)."""
        from ..simulation.hybrid import MAX_IMPACTS, simulate_through_impacts

        if stop is not None:
            raise InputError("a stop condition is not available for a model with impacts "
                             "(the run ends at t_end, an accumulation or max_impacts)",
                             field="stop_when")
        if controller is not None:
            raise InputError("a controller is not available for a model with impacts",
                             field="controller")
        return simulate_through_impacts(
            self.equations_of_motion(), t_end, initial=start, step_control=step_control,
            save_at=save_at, progress=progress, functions=self._numeric,
            max_impacts=MAX_IMPACTS if max_impacts is None else max_impacts, settle=settle,
            maps=self.impact_maps())
