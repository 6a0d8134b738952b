"""The run options of System.simulate and System.sweep: the option types or the plain keywords."""

from __future__ import annotations

from ..errors import InputError
from ..simulation.options import SaveAt, StepControl


def run_options(step_control: StepControl | None, save_at: SaveAt | None, method: str,
                rtol: float, atol: float, samples: int, samples_default: int
                ) -> tuple[StepControl, SaveAt]:
    """The option values from the option types or the plain keywords (a thin shim), never
    both: a plain keyword that differs from its default beside its option type is refused."""
    plain = {"method": (method, "DOP853"), "rtol": (rtol, 1e-9), "atol": (atol, 1e-9)}
    if step_control is not None:
        if not isinstance(step_control, StepControl):
            raise InputError("step_control must be a lagrangian.StepControl",
                             field="step_control")
        both = [k for k, (value, default) in plain.items() if value != default]
        if both:
            raise InputError(f"give {', '.join(both)} in step_control or as a keyword, not both",
                             field="step_control")
    else:
        step_control = StepControl(method, rtol, atol)
    if save_at is not None:
        if not isinstance(save_at, SaveAt):
            raise InputError("save_at must be a lagrangian.SaveAt", field="save_at")
        if samples != samples_default:
            raise InputError("give samples in save_at or as a keyword, not both",
                             field="save_at")
    else:
        save_at = SaveAt(samples)
    return step_control, save_at
