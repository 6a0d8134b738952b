"""lagrangian.optimize: an optimal trajectory of a System by direct collocation (CasADi, IPOPT)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from ..control.optimize import Trajectory, check_model, collocate
from .system import System


def optimize(system: System, inputs: Sequence[str], t_final: float, nodes: int = 100, *,
             start: Mapping[str, float] | None = None, goal: Mapping[str, float] | None = None,
             bounds: Mapping[str, tuple[float, float]] | None = None,
             objective: str = "effort", method: str = "trapezoidal",
             parameters: Mapping[str, float] | None = None, tolerance: float = 1e-8,
             max_iterations: int = 3000) -> Trajectory:
    """The trajectory from ``start`` (the model's initial state where not given) to ``goal``
    (the named states at ``t_final`` s) that minimises the effort, the integral of |u|^2 dt,
    with u the named ``inputs`` (loads, parameters or coordinates, as in ``linearize``) within
    ``bounds`` {name: (lower, upper)} (SI; a robot's joint position limits are bounds too
    unless ``bounds`` names the joint); direct collocation on ``nodes`` points,
    ``method`` "trapezoidal" or "hermite-simpson", solved by IPOPT through CasADi (extra
    [casadi]). A floating base's states are its position, quaternion and twist (base_x ..
    base_wz) before the joints', a ball joint's its quaternion and angular velocity in its
    body's axes (shoulder_qw .. shoulder_qz, shoulder_wx .. shoulder_wz; its moment inputs
    shoulder_wx ..), named as simulate's start, each quaternion held unit at the nodes; the
    base at the origin and level, each ball unturned, at rest unless ``start`` names them;
    a model with t in its equations is collocated at the nodes' times from t = 0.
    Replay it with ``system.simulate(t_final, initial=trajectory.initial_state(),
    controller=trajectory.controller())``: docs/bridges.md."""
    if not isinstance(system, System):
        raise TypeError("optimize(system, ...) takes a lagrangian System (lagrangian.load)")
    check_model(system.model)
    if isinstance(inputs, str):
        inputs = [inputs]
    functions = system.to_casadi(inputs=inputs, parameters=parameters)
    limits = {name: span for name, span in system.joint_limits.items() if name not in inputs}
    return collocate(functions, system.model, t_final, nodes, start=start, goal=goal,
                     bounds={**limits, **dict(bounds or {})}, objective=objective,
                     method=method, tolerance=tolerance, max_iterations=max_iterations)


__all__ = ["Trajectory", "optimize"]
