"""Our equations through opty: System.to_opty() handed to opty.Problem as its users would, the
torque-limited pendulum's and the cart-pole's minimum-effort swing-ups solved by opty's own
collocation and IPOPT, against lagrangian.optimize and the held-out optima of
swing_up_references.py (CasADi multiple shooting; SciPy SLSQP).

    python benchmarks/opty_swing_up.py      # about a minute: opty compiles its constraints

Needs opty (``pip install opty``: its cyipopt builds against a system IPOPT, e.g. Debian's
coinor-libipopt-dev, liblapack-dev and libblas-dev). Objective: the trapezoid rule on the
input's node values; 201 nodes, opty's midpoint rule (its backward Euler, first order, stops
about 11 % above the optimum on the pendulum: the scheme's damping costs effort).
"""

from __future__ import annotations

import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import lagrangian

sys.path.insert(0, str(Path(__file__).parents[1] / "tests" / "control"))
from test_optimize import MOTOR_PENDULUM, SWING_UP_OPTIMA  # noqa: E402

# the cart-pole's held-out optimum (N^2 s; tests/test_docs_bridges.py, swing_up_references.py)
CART_POLE_OPTIMA = {"casadi multiple shooting": 323.73, "scipy slsqp trapezoidal": 324.89}


def opty_swing_up(system, input_name, t_final, start, goal, bound, state_bounds, nodes=201):
    """opty's optimum (cost, seconds, IPOPT's status) from our to_opty() equations."""
    from opty import Problem

    equations = system.to_opty(inputs=[input_name])
    t, (r,) = equations.time, equations.specified
    h = t_final / (nodes - 1)
    n = len(equations.states)

    def cost(free):
        u = free[n * nodes:(n + 1) * nodes]
        return h * (np.sum(u ** 2) - 0.5 * (u[0] ** 2 + u[-1] ** 2))

    def gradient(free):
        g = np.zeros_like(free)
        u = free[n * nodes:(n + 1) * nodes]
        g[n * nodes:(n + 1) * nodes] = 2 * h * u
        g[n * nodes] -= h * u[0]
        g[(n + 1) * nodes - 1] -= h * u[-1]
        return g

    names = [str(s.func) for s in equations.states]
    constraints = [s.subs(t, 0) - start.get(name, 0.0) for s, name in
                   zip(equations.states, names, strict=True)]
    constraints += [s.subs(t, t_final) - goal.get(name, 0.0) for s, name in
                    zip(equations.states, names, strict=True)]
    bounds = {r: bound}
    for s, name in zip(equations.states, names, strict=True):
        if name in state_bounds:
            bounds[s] = state_bounds[name]
    began = time.perf_counter()
    problem = Problem(cost, gradient, equations.eom, equations.states, nodes, h,
                      known_parameter_map=equations.parameters,
                      instance_constraints=tuple(constraints), bounds=bounds, time_symbol=t,
                      integration_method="midpoint")
    problem.add_option("print_level", 0)
    guess = np.zeros(problem.num_free)
    for k, name in enumerate(names):  # the angle from start to goal, the rest at rest
        guess[k * nodes:(k + 1) * nodes] = np.linspace(start.get(name, 0.0),
                                                       goal.get(name, 0.0), nodes)
    _, info = problem.solve(guess)
    return info["obj_val"], time.perf_counter() - began, info["status"]


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "motor_pendulum.toml"
        path.write_text(MOTOR_PENDULUM)
        pendulum = lagrangian.load(path)
        cases = [
            ("pendulum", pendulum, "u", 3.0, {}, {"theta": math.pi}, (-5.0, 5.0), {},
             SWING_UP_OPTIMA, {"nodes": 30}),
            ("cart-pole", lagrangian.load("cart_pendulum"), "push", 2.0, {}, {"theta": math.pi},
             (-20.0, 20.0), {"x": (-1.0, 1.0)}, CART_POLE_OPTIMA, {"nodes": 25}),
        ]
        for name, system, u, t_final, start, goal, bound, state_bounds, held_out, ours in cases:
            cost, seconds, status = opty_swing_up(system, u, t_final, start, goal, bound,
                                                  state_bounds)
            states = {c: 0.0 for c in system.coordinates}
            rates = {f"{c}_dot": 0.0 for c in system.coordinates}
            mine = lagrangian.optimize(system, [u], t_final, ours["nodes"],
                                       method="hermite-simpson", start={**states, **rates},
                                       goal={**states, **rates, **goal},
                                       bounds={u: bound, **state_bounds})
            others = ", ".join(f"{k} {v:.2f} ({cost / v - 1:+.2%})" for k, v in held_out.items())
            print(f"{name}: opty from to_opty() {cost:.3f} (IPOPT status {status}, "
                  f"{seconds:.0f} s with its compile); optimize {mine.cost:.3f} "
                  f"({cost / mine.cost - 1:+.2%}); held out: {others}")


if __name__ == "__main__":
    main()
