"""An optimal trajectory (lagrangian.optimize) as text and as a JSON document."""

from __future__ import annotations

import numpy as np

from ..control.optimize import Trajectory


def trajectory_document(trajectory: Trajectory) -> dict:
    """cost, converged, status, t (s), states and inputs (SI) at the nodes, and the defects."""
    return trajectory.to_dict()


def trajectory_text(trajectory: Trajectory, rows: int = 11) -> str:
    """The verdict, the cost, the defects and the trajectory at about ``rows`` times."""
    verdict = "converged" if trajectory.converged else f"NOT converged ({trajectory.status})"
    unit = "(u in SI units: u^2 s)"
    lines = [f"Optimal trajectory by {trajectory.method} collocation on {len(trajectory.t)} "
             f"nodes: {verdict} after {trajectory.iterations} IPOPT iterations",
             f"  effort (integral of u^2 dt): {trajectory.cost:.9g} {unit}",
             "  defects: collocation {collocation:.2g}, final state {final_state:.2g}, "
             "constraints {constraints:.2g}, replay {replay:.2g}".format(**trajectory.defects)]
    names = [*trajectory.states, *trajectory.inputs]
    columns = [trajectory.states[k] for k in trajectory.states] + \
        [trajectory.inputs[k] for k in trajectory.inputs]
    picks = np.unique(np.linspace(0, len(trajectory.t) - 1, rows).round().astype(int))
    width = max(14, *(len(n) + 2 for n in names))
    lines.append("")
    lines.append(f"{'t (s)':>10}" + "".join(f"{n:>{width}}" for n in names))
    for i in picks:
        lines.append(f"{trajectory.t[i]:>10.4g}" + "".join(f"{c[i]:>{width}.6g}" for c in columns))
    return "\n".join(lines) + "\n"


__all__ = ["trajectory_document", "trajectory_text"]
