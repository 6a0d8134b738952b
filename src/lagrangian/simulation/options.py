"""How a simulation runs, as small immutable options (in the spirit of diffrax's SaveAt and
step-size controllers): where the trajectory is saved and how steps are controlled."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError

METHODS = ("DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA")
MAX_SAMPLES = 10_000_000  # about 1 GB of results for a small model


@dataclass(frozen=True)
class StepControl:
    """The integrator and its error control: local error <= atol + rtol |y| per step.

    ``method`` is one of METHODS (scipy's names); ``max_step`` bounds the step size (s).
    """

    method: str = "DOP853"
    rtol: float = 1e-9
    atol: float = 1e-9
    max_step: float = math.inf

    def __post_init__(self):
        # any case is accepted (rk45, dop853), and kept in scipy's spelling
        canonical = {name.lower(): name for name in METHODS}
        if isinstance(self.method, str) and self.method.lower() in canonical:
            object.__setattr__(self, "method", canonical[self.method.lower()])
        if self.method not in METHODS:
            raise InputError(f"unknown method '{self.method}'; choose one of {', '.join(METHODS)}",
                             field="method")
        for name in ("rtol", "atol", "max_step"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float) or \
                    math.isnan(value) or value <= 0 or (name != "max_step" and math.isinf(value)):
                raise InputError(f"{name} must be a positive number, got {value}", field=name)


@dataclass(frozen=True)
class SaveAt:
    """Where the trajectory is saved: ``samples`` evenly spaced times from start to end, both
    included (a run stopped early ends with its stop time)."""

    samples: int = 1001

    def __post_init__(self):
        if isinstance(self.samples, bool) or not isinstance(self.samples, int) or \
                self.samples < 2:
            raise InputError(f"samples must be at least 2, got {self.samples}", field="samples")
        if self.samples > MAX_SAMPLES:
            # refused up front: each sample holds q, q_dot, energy, power, ... (1e12 was 7 TiB)
            raise InputError(f"samples must be at most {MAX_SAMPLES:,}, got {self.samples:,}",
                             field="samples")
