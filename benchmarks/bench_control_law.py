"""A control law written in the model file ([control], compiled into the equations' C) against
the same law as a Python callable, on the cart-pole balancing upright.

    python benchmarks/bench_control_law.py [--t-end 20]

- The law: push = -K (x, theta - pi, x_dot, theta_dot), K the LQR gain of the upright cart-pole
  (Q = diag(1, 10, 1, 1), R = 0.1), in the file; the callable returns the same u with
  inputs=["F"].
- Timed: System.simulate(t_end) with rtol = atol = 1e-10 and 201 samples, best of 3, after one
  warm-up run (the C module built and cached, the derivation done): the compiled DOP853 loop
  for the file's law, scipy's stepped DOP853 for the callable. Per evaluation: wall time over
  the right-hand-side calls (nfev) of that run, so it includes the loop's own work.
- Agreement: the largest difference of the two runs' q over the samples.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np

import lagrangian
from lagrangian.control import lqr
from lagrangian.model.examples import example_path


def best(function, repeat: int = 3):
    times, result = [], None
    for _ in range(repeat):
        began = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - began)
    return min(times), result


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--t-end", type=float, default=20.0)
    args = parser.parse_args()
    cart = lagrangian.load("cart_pendulum")
    K = [float(k) for k in lqr(cart.linearize({"x": 0, "theta": np.pi}, inputs=["F"]),
                                Q=[1, 10, 1, 1], R=0.1).K[0]]
    law = (f"-({K[0]!r})*x - ({K[1]!r})*(theta - pi) - ({K[2]!r})*x_dot "
           f"- ({K[3]!r})*theta_dot")
    text = example_path("cart_pendulum").read_text(encoding="utf-8")
    path = Path(tempfile.mkdtemp()) / "cart_pole_law.toml"
    path.write_text(text + f'\n[control]\npush = "{law}"\n', encoding="utf-8")
    system = lagrangian.load(path)

    def callable_law(t, q, v):
        return [-(K[0] * q[0] + K[1] * (q[1] - np.pi) + K[2] * v[0] + K[3] * v[1])]

    start = {"theta": np.pi - 0.2}
    options = {"initial": start, "rtol": 1e-10, "atol": 1e-10, "samples": 201}
    runs = {"file law (compiled)": lambda: system.simulate(args.t_end, controller="model",
                                                            **options),
            "Python callable": lambda: system.simulate(args.t_end, controller=callable_law,
                                                       inputs=["F"], **options)}
    results = {}
    for name, run in runs.items():
        run()  # warm-up: the C module, the derivation
        wall, result = best(run)
        results[name] = result
        print(json.dumps({"run": name, "backend": result.backend, "wall_s": round(wall, 4),
                          "nfev": result.nfev,
                          "per_evaluation_us": round(1e6 * wall / result.nfev, 2)}))
    a, b = results.values()
    print(json.dumps({"max_abs_difference_q": float(np.abs(a.q - b.q).max())}))


if __name__ == "__main__":
    main()
