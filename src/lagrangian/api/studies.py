"""System's methods for steady motion and parameter studies: the speed form of a bicycle's
linear equations, its eigenvalues over speed, and sweeps and ensembles on Dask (docs/sweeps.md).
Mixed into System (api/system.py)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import InputError

if TYPE_CHECKING:  # imported by the methods that use them (issue 38)
    from ..analysis.speed_form import SpeedForm, SpeedSweep
    from ..simulation.options import SaveAt, StepControl


class StudyMethods:
    """Mixed into System (api/system.py)."""

    def speed_form(self, steady: Mapping[str, float | str] | None = None,
                   speed: str | None = None, keep: Sequence[str] | None = None,
                   *, about: Mapping[str, float] | None = None) -> SpeedForm:
        """The reduced linear equations of the ``keep`` coordinates about steady motion at the
        speed parameter ``speed``, in the form M q'' + v C1 q' + (g K0 + v^2 K2) q = f
        (analysis/speed_form.py); ``steady`` gives each steady rate as an expression in the
        parameters, e.g. {"x_dot": "v", "thetaR_dot": "-v/rR", "thetaF_dot": "-v/rF"}. What is
        not given comes from the model's [steady] table."""
        from ..analysis.speed_form import speed_form

        steady, speed, keep, about = self._steady_motion(steady, speed, keep, about)
        return speed_form(self.equations_of_motion(), about, steady, speed, keep)

    def speed_sweep(self, steady: Mapping[str, float | str] | None = None,
                    speed: str | None = None, keep: Sequence[str] | None = None,
                    speeds: Sequence[float] | None = None, *,
                    about: Mapping[str, float] | None = None) -> SpeedSweep:
        """Eigenvalues (1/s) of the reduced equations at each speed (m/s; default 0 to 10 in
        steps of 0.1), and the speeds where their real parts cross zero (a bicycle's weave and
        capsize speeds) with the stable range."""
        from ..analysis.speed_form import speed_sweep

        if speeds is None:
            speeds = [i / 10 for i in range(101)]
        return speed_sweep(self.speed_form(steady, speed, keep, about=about), speeds)

    def _steady_motion(self, steady, speed, keep, about):
        """The steady motion asked for, each part not given taken from the model's [steady]."""
        default = self._model.steady_motion
        if default is None and (steady is None or speed is None or keep is None):
            missing = [n for n, v in (("steady", steady), ("speed", speed), ("keep", keep))
                       if v is None][0]
            from ..errors import ModelError

            raise ModelError("give the steady rates, the speed parameter and the kept "
                             "coordinates, or a [steady] table in the model file",
                             field=missing)
        if default is not None:
            steady = dict(default.rates) if steady is None else steady
            speed = default.speed if speed is None else speed
            keep = list(default.keep) if keep is None else keep
            about = (dict(default.about) or None) if about is None else about
        return steady, speed, keep, about

    # -- parameter studies and ensembles (Dask; see docs/sweeps.md) -------------------------------

    def sweep(self, vary: Mapping[str, Sequence[float]] | None = None, compute: str = "modes", *,
              sample: Mapping[str, str] | None = None, members: int = 0, seed: int = 0,
              t_end: float | None = None, method: str = "DOP853", rtol: float = 1e-9,
              atol: float = 1e-9, samples: int = 201, stop_when: str | None = None,
              trajectories: bool = False, out: str | Path | None = None, resume: bool = False,
              scheduler: str | None = None, client=None, workers: int | None = None,
              chunk_size: int | None = None, progress=None,
              about: Mapping[str, float] | None = None,
              step_control: StepControl | None = None, save_at: SaveAt | None = None):
        """A parameter study or ensemble as an xarray Dataset, one dimension per varied name.

        ``vary`` maps parameters (and, for ``compute="simulate"``, coordinates and velocities)
        to their values (SI); ``compute`` is "modes" (frequency, damping_ratio, growth_rate,
        stable about the equilibrium System.modes(about) uses), "equilibria" (each one and its
        stability, along ``equilibrium``) or "simulate" (per member: final state, extremes,
        energy drift, stop time; ``trajectories=True`` adds the states on the time grid).
        ``sample`` draws ``members`` values per name from 'normal(mean, std)' or
        'uniform(low, high)'. Runs on Dask: a LocalCluster of one process per core by default,
        ``scheduler`` an address of a running one, ``client`` a dask Client. A failing point is
        NaN with its reason in ``status``. With ``out`` (*.nc or *.zarr) the chunks are kept as
        they finish and ``resume=True`` continues an interrupted study. ``step_control`` and
        ``save_at`` (or the plain ``method``, ``rtol``, ``atol``, ``samples``) and ``stop_when`` (a
        condition or a StopCondition) set each member's simulation, as in System.simulate.
        """
        from ..analysis.study import SimulationOptions, make_study
        from ..derivation.regularity import require_inertia
        from ..output.sweep import require_study_packages
        from ..simulation.events import StopCondition
        from ..simulation.simulate import parse_stop_condition
        from ..study.engine import run_study
        from .options import run_options

        require_study_packages(out)  # the extra [sweep], asked before the derivation
        eom = self.equations_of_motion()
        require_inertia(eom, "simulate" if compute == "simulate" else "modes")
        options = None
        if compute == "simulate":
            if t_end is None:
                raise InputError("a simulation study needs t_end (s)", field="t_end")
            step, save = run_options(step_control, save_at, method, rtol, atol, samples, 201)
            if isinstance(stop_when, StopCondition):
                stop_when = stop_when.text
            if stop_when is not None:
                parse_stop_condition(stop_when, self._model)
            options = SimulationOptions(float(t_end), step.method, step.rtol, step.atol,
                                        int(save.samples), stop_when, bool(trajectories))
        study = make_study(eom, compute, vary or {}, sample, members, seed, options, chunk_size,
                           about)
        from .sweep import Sweep

        return Sweep.of(run_study(study, out=out, resume=resume, scheduler=scheduler,
                                  client=client, workers=workers, progress=progress))
