"""What a simulation returns: the sampled trajectory, its energy and constraint residuals, and
how the run went (status, steps, wall time). Its text and JSON forms are in output/simulation.py.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..kinds import InvariantKind, RunStatus
from ..model.model import Model
from ..model.values import State
from .invariants import energy_drift, relative_drift
from .options import StepControl

STATUS_MESSAGES = {
    "finished": "reached the end time",
    "stopped": "stopped by the stop condition",
    "limit": "stopped at a joint's position limit",
    "interrupted": "interrupted",
    "failed": "integration failed",
}


@dataclass(frozen=True, repr=False)
class SimulationResult:
    """Sampled trajectory t (s), q, q_dot, energy T + V (J), power of non-conservative loads
    Q . q_dot (W; a controller's B u . q_dot included), multipliers lambda and constraint
    residuals, with run statistics.

    ``invariant`` names the monitored quantity: "energy" (T + V), "jacobi_integral" (h, in
    ``invariant_values``) or "work_balance" (h - h0 - ``work``, the work int P dt done on the
    system by loads, dissipation, explicit time and moving constraints).
    """

    model: Model
    coordinates: tuple[str, ...]
    constraint_names: tuple[str, ...]
    parameters: dict[str, float]
    t: np.ndarray
    q: np.ndarray
    q_dot: np.ndarray
    energy: np.ndarray
    power: np.ndarray
    multipliers: np.ndarray
    residuals: np.ndarray
    step_control: StepControl
    status: str
    message: str
    steps: int | None
    nfev: int
    wall_time: float
    backend: str
    energy_conserved: bool
    t_end: float
    stop_when: str | None = None
    projected_initial_state: dict[str, tuple[float, float]] = field(default_factory=dict)
    kinetic_energy: np.ndarray | None = None
    invariant: str = "energy"
    invariant_values: np.ndarray | None = None
    work: np.ndarray | None = None
    # URDF velocity and effort limits exceeded (simulate.JointLimit): one dict each, with
    # joint, coordinate, quantity, limit, value, t (None for effort) and unit
    limits_exceeded: tuple[dict, ...] = ()
    # under a controller (simulation/control.py): its output u at each sample (N, r), and the
    # names of its entries (the inputs, or the coordinates for generalized forces)
    controls: np.ndarray | None = None
    control_names: tuple[str, ...] = ()
    control_forces: np.ndarray | None = None  # B u: the generalized forces it added (N, n)
    # a floating base's velocity names (nv = n + 6: its twist, then the joints), q of nq = n + 7
    velocity_names: tuple[str, ...] | None = None
    # a run in (q, p) (canonical=...): the momenta p = dL/dq_dot at each sample (N, n)
    momenta: np.ndarray | None = None

    @property
    def rate_names(self) -> tuple[str, ...]:
        """The velocity columns' names: <q>_dot, or a floating base's twist (base_vx ..
        base_wz) then <joint>_dot."""
        if self.velocity_names is None:
            return tuple(f"{name}_dot" for name in self.coordinates)
        return tuple(name if name not in self.coordinates else f"{name}_dot"
                     for name in self.velocity_names)

    @property
    def model_name(self) -> str:
        return self.model.name

    @property
    def method(self) -> str:
        return self.step_control.method

    @property
    def rtol(self) -> float:
        return self.step_control.rtol

    @property
    def atol(self) -> float:
        return self.step_control.atol

    @property
    def completed(self) -> bool:
        """True when the run reached its end time, its stop condition or a joint's limit."""
        return self.status in (RunStatus.FINISHED, RunStatus.STOPPED, RunStatus.LIMIT)

    def columns(self) -> dict[str, np.ndarray]:
        """Named columns: t, <q>, <q>_dot (p_<q> for a run in (q, p)), energy, lambda_<c>,
        residual_<c>, power."""
        out: dict[str, np.ndarray] = {"t": self.t}
        for i, name in enumerate(self.coordinates):
            out[name] = self.q[:, i]
        for i, name in enumerate(self.rate_names):
            out[name] = self.q_dot[:, i]
        if self.momenta is not None:  # a run in (q, p): p_<q>, the module's notation
            for i, name in enumerate(self.coordinates):
                out[f"p_{name}"] = self.momenta[:, i]
        out["energy"] = self.energy
        for i, name in enumerate(self.constraint_names):
            out[f"lambda_{name}"] = self.multipliers[:, i]
        for i, name in enumerate(self.constraint_names):
            out[f"residual_{name}"] = self.residuals[:, i]
        out["power"] = self.power
        for i, name in enumerate(self.control_names):
            out[f"control_{name}"] = self.controls[:, i]
        if self.invariant == InvariantKind.JACOBI_INTEGRAL and self.invariant_values is not None:
            out["jacobi_integral"] = self.invariant_values
        elif self.invariant == InvariantKind.WORK_BALANCE and self.balance is not None:
            out["work_balance"] = self.balance
        return out

    @property
    def balance(self) -> np.ndarray | None:
        """What should stay zero (J): I - I0 for a conserved I, h - h0 - int P dt for a work
        balance; None before the quantity is known."""
        values = self.invariant_values if self.invariant_values is not None else self.energy
        if values is None or len(values) == 0 or not np.all(np.isfinite(values)):
            return None  # none (a run that failed on an overflow has an infinite energy)
        change = values - values[0]
        if self.invariant == InvariantKind.WORK_BALANCE:
            if self.work is None:
                return None
            change = change - self.work
        return change

    @property
    def invariant_drift(self) -> float | None:
        """max |balance| relative to the size of the quantity (|I0|, or the largest T, or the
        largest work done, whichever is largest where I0 is near 0)."""
        balance = self.balance
        if balance is None:
            return None
        values = self.invariant_values if self.invariant_values is not None else self.energy
        return relative_drift(balance, values[0], (self.kinetic_energy, self.work),
                              against_others=self.invariant == InvariantKind.WORK_BALANCE)

    @property
    def last_state(self) -> State:
        """The state at the last sample."""
        return State(self.coordinates, tuple(float(x) for x in self.q[-1]),
                     tuple(float(x) for x in self.q_dot[-1]), float(self.t[-1]))

    @property
    def final_state(self) -> dict[str, float]:
        """t, then q, then q_dot at the last sample, by name."""
        state = {"t": float(self.t[-1])}
        for i, name in enumerate(self.coordinates):
            state[name] = float(self.q[-1, i])
        for i, name in enumerate(self.rate_names):
            state[name] = float(self.q_dot[-1, i])
        return state

    @property
    def energy_drift(self) -> float | None:
        """max |E - E0| / |E0| where energy should be conserved, else None (max T if E0 = 0)."""
        if not self.energy_conserved or len(self.energy) == 0 or \
                not np.all(np.isfinite(self.energy)):  # a run failed on an overflow
            return None
        return energy_drift(self.energy, self.kinetic_energy)

    @property
    def max_residual(self) -> float | None:
        """Largest |Phi| (holonomic) or |A q_dot + b| (velocity) over the samples, else None."""
        if not self.constraint_names or len(self.t) == 0:
            return None
        return float(np.max(np.abs(self.residuals)))

    def __repr__(self) -> str:
        parts = [f"{self.status}", f"t = {self.t[0]:g}..{self.t[-1]:g} s", f"{len(self.t)} samples",
                 f"{self.method}"]
        if self.energy_drift is not None:
            parts.append(f"energy drift {self.energy_drift:.1e}")
        if self.max_residual is not None:
            parts.append(f"max residual {self.max_residual:.1e}")
        return f"{type(self).__name__}({self.model_name!r}: {', '.join(parts)})"
