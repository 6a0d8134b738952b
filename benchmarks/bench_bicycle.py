"""The Whipple bicycle (built-in example whipple_bicycle): derivation to compiled functions,
one compiled right-hand side with the constraint solve, a 10 s nonlinear simulation, and the
lean-steer form with its speed sweep.

    python benchmarks/bench_bicycle.py

Each stage is timed once in this process (wall and CPU time), after the imports; the compiled
C is built into an empty cache (a temporary LAGRANGIAN_CACHE) so the compiler is counted. The
right-hand side is timed with timeit (best of 5 x 20000 calls). The load average is printed:
the machine this was measured on is shared, so read ratios rather than absolute figures.
"""

from __future__ import annotations

import os
import tempfile
import time
import timeit


def _timed(label: str, function):
    wall, cpu = time.perf_counter(), time.process_time()
    value = function()
    print(f"{label:<48} {time.perf_counter() - wall:8.3f} s wall {time.process_time() - cpu:8.3f}"
          " s CPU", flush=True)
    return value


def main() -> None:
    os.environ.setdefault("LAGRANGIAN_CACHE", tempfile.mkdtemp(prefix="bench-bicycle-"))
    import numpy as np

    import lagrangian
    from lagrangian.analysis.speed_form import speed_sweep

    print(f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} "
          f"{os.getloadavg()[2]:.2f}")
    system = _timed("read the model file (4 bodies, 2 contacts)",
                    lambda: lagrangian.load("whipple_bicycle"))
    _timed("derive M, f, Phi_q, gamma (Lagrange)", system.equations_of_motion)
    numeric = _timed("compile (C, empty cache)", lambda: system.numeric(backend="c"))
    v = 5.0
    y = np.zeros(16)
    y[8], y[8 + 3], y[8 + 5], y[8 + 7] = v, 0.5, -v / 0.3, -v / 0.35
    numeric.rhs(0.0, y)
    calls = 20000
    best = min(timeit.repeat(lambda: numeric.rhs(0.0, y), number=calls, repeat=5)) / calls
    print(f"{'one compiled rhs(t, y) with the constraint solve':<48} {best * 1e6:8.2f} us")
    system.simulate(0.01, samples=2)  # the run's one-time set-up (invariant, stop rows)
    initial = {"x_dot": v, "thetaR_dot": -v / 0.3, "thetaF_dot": -v / 0.35, "phi_dot": 0.5}
    run = _timed("simulate 10 s at 5 m/s (DOP853, rtol = atol = 1e-9)",
                 lambda: system.simulate(10.0, initial=initial, samples=201))
    print(f"    {run}")
    rates = {"x_dot": "v", "thetaR_dot": "-v/rR", "thetaF_dot": "-v/rF"}
    form = _timed("lean-steer form (symbolic slopes, compiled, fit)",
                  lambda: system.speed_form(rates, "v", ["phi", "delta"]))
    sweep = _timed("speed sweep 0..10 m/s, 101 speeds + crossings",
                   lambda: speed_sweep(form, np.linspace(0, 10, 101)))
    for c in sweep.crossings:
        print(f"    {c.kind} crossing at {c.speed:.10f} m/s")


if __name__ == "__main__":
    main()
