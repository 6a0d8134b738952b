"""The engine (every robot's default kernel) against the opt-in unrolled module and Pinocchio on
the Panda: M, ID and FD per call through the API, and batches of 10^4 states in one call against
a Python loop over Pinocchio (issue "One engine for every robot").

    python benchmarks/bench_engine.py [--states 10000]

Per call: one state, best of 15 runs of 1000 calls, our kernels and Pinocchio alternating in
this process. Batch: one call over the states (threads as the machine has), best of 5, against
the best of 3 Python loops over pin.crba / pin.rnea / pin.aba. Warm: the compiled modules are
built (or loaded from the cache) before any timing. Needs the bench extra (pin,
example-robot-data).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from bench_variants import robots

import lagrangian


def best(call, calls: int = 1000, runs: int = 15) -> float:
    """Seconds per call, the best of ``runs`` runs of ``calls`` calls."""
    fastest = float("inf")
    for _ in range(runs):
        start = time.perf_counter()
        for _ in range(calls):
            call()
        fastest = min(fastest, (time.perf_counter() - start) / calls)
    return fastest


def main() -> None:
    import pinocchio as pin

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=10_000)
    args = parser.parse_args()
    urdf = str(robots() / "panda_description/urdf/panda.urdf")
    system = lagrangian.load(urdf)
    model = pin.buildModelFromUrdf(urdf)
    data = model.createData()
    rng = np.random.default_rng(0)
    kernels = {name: system.dynamics(kernel=name) for name in ("compact", "unrolled")}
    n = kernels["compact"].n
    q, v, a = rng.uniform(-1, 1, (3, n))
    pq, pv = pin.neutral(model), np.zeros(model.nv)
    print(f"Panda: nv {n} (Pinocchio {model.nv}: its mimic finger a joint of its own)")
    print("per call (us)   engine  unrolled  Pinocchio  engine ratio  unrolled ratio")
    theirs = {"M": lambda: pin.crba(model, data, pq), "ID": lambda: pin.rnea(model, data, pq, pv, pv),
              "FD": lambda: pin.aba(model, data, pq, pv, pv)}
    for name in ("M", "ID", "FD"):
        ours = {}
        for kernel, f in kernels.items():
            ours[kernel] = {"M": lambda f=f: f.mass_matrix(q),
                            "ID": lambda f=f: f.inverse_dynamics(q, v, a),
                            "FD": lambda f=f: f.forward_dynamics(q, v, a)}[name]
        t = {k: best(call) * 1e6 for k, call in ours.items()}
        p = best(theirs[name]) * 1e6
        print(f"{name:15s} {t['compact']:7.3f} {t['unrolled']:9.3f} {p:10.3f} "
              f"{p / t['compact']:12.1f}x {p / t['unrolled']:14.1f}x")
    N = args.states
    Q, V, A = rng.uniform(-1, 1, (3, N, n))
    PQ = np.tile(pq, (N, 1))
    print(f"batch of {N} (ms)  engine  unrolled  Pinocchio loop  engine ratio  unrolled ratio")
    loops = {"M": lambda: [pin.crba(model, data, x) for x in PQ],
             "ID": lambda: [pin.rnea(model, data, x, pv, pv) for x in PQ],
             "FD": lambda: [pin.aba(model, data, x, pv, pv) for x in PQ]}
    for name in ("M", "ID", "FD"):
        t = {}
        for kernel, f in kernels.items():
            call = {"M": lambda f=f: f.mass_matrix(Q), "ID": lambda f=f: f.inverse_dynamics(Q, V, A),
                    "FD": lambda f=f: f.forward_dynamics(Q, V, A)}[name]
            t[kernel] = best(call, 1, 5) * 1e3
        p = best(loops[name], 1, 3) * 1e3
        print(f"{name:17s} {t['compact']:6.2f} {t['unrolled']:9.2f} {p:15.2f} "
              f"{p / t['compact']:12.1f}x {p / t['unrolled']:14.1f}x")


if __name__ == "__main__":
    main()
