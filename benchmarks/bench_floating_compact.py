"""A floating base on the compact kernel (dynamics/engine/tree_kernel.c, the free flyer as body 0)
against the unrolled module of the same tree (tree_c.py) and Pinocchio's aba, for Talos.

    python benchmarks/bench_floating_compact.py            # talos_reduced and talos_full_v2
    python benchmarks/bench_floating_compact.py --json
    python benchmarks/bench_floating_compact.py --no-cold  # per call and batch only (warm cache)

Rows, per robot and kernel: "first s" is load (URDF -> tree, floating_base=True) plus the
first forward dynamics in a fresh process with an empty compiled-module cache (LAGRANGIAN_CACHE
a new folder: the compact kernel's one module, or the robot's own unrolled module, compiled
there; import of lagrangian apart), one run each. Per call: forward dynamics of one state
through the Python API and pin.aba through Pinocchio's bindings, alternating in this process
(best of 7 runs of 1000 calls). Batch: 10^4 states in one call (threads as the machine has)
against a Python loop over pin.aba (best of 3). Error: the largest difference from aba
relative to its largest entry over 5 random states, by joint name (talos_reduced; the full
Talos's grippers are mimic joints here, separate coordinates in Pinocchio: no error column).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from bench_urdf import side_by_side  # the sibling benchmark's: turns taken, best per call

import lagrangian

ROBOTS = Path(sys.prefix) / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" \
    / "site-packages" / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
TALOS = {"talos_reduced": ROBOTS / "talos_data/robots/talos_reduced.urdf",
         "talos_full_v2": ROBOTS / "talos_data/robots/talos_full_v2.urdf"}

_FIRST = """
import sys, time
import numpy as np, lagrangian
imported = time.perf_counter()
f = lagrangian.load(sys.argv[1], floating_base=True).dynamics(kernel=sys.argv[2])
q = np.zeros(f.nq); q[6] = 1.0
f.forward_dynamics(q, np.zeros(f.nv), np.zeros(f.nv))
print(time.perf_counter() - imported)
"""


def first_result(path: Path, kernel: str) -> float:
    """Seconds from load to the first forward dynamics, cold cache, in a fresh process."""
    with tempfile.TemporaryDirectory() as cache:
        done = subprocess.run([sys.executable, "-c", _FIRST, str(path), kernel],
                              env=dict(os.environ, LAGRANGIAN_CACHE=cache),
                              capture_output=True, text=True, check=True)
        return float(done.stdout.split()[-1])


def _states(rng, count, nq, nv):
    q = rng.uniform(-1, 1, (count, nq))
    q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
    return q, rng.uniform(-1, 1, (count, nv)), rng.uniform(-1, 1, (count, nv))


def measure(name: str, path: Path, kernel: str, cold: bool = True) -> dict:
    import pinocchio as pin

    first = first_result(path, kernel) if cold else float("nan")
    f = lagrangian.load(path, floating_base=True).dynamics(kernel=kernel)
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = model.createData()
    rng = np.random.default_rng(7)
    error = None
    if (f.nq, f.nv) == (model.nq, model.nv):  # compare by joint name (Pinocchio's order)
        ids = [model.getJointId(j.name) for j in f.tree.joints[1:]]
        iq = np.array(list(range(7)) + [model.idx_qs[i] for i in ids])
        iv = np.array(list(range(6)) + [model.idx_vs[i] for i in ids])
        error = 0.0
        for q, v, tau in zip(*_states(rng, 5, model.nq, model.nv), strict=True):
            theirs = pin.aba(model, data, q, v, tau)[iv]
            error = max(error, float(np.abs(f.forward_dynamics(q[iq], v[iv], tau[iv]) - theirs)
                                     .max() / np.abs(theirs).max()))
    (q,), (v,), (tau,) = _states(rng, 1, f.nq, f.nv)
    (pq,), (pv,), (ptau,) = _states(rng, 1, model.nq, model.nv)
    ours, theirs = side_by_side(lambda: f.forward_dynamics(q, v, tau),
                                lambda: pin.aba(model, data, pq, pv, ptau), number=1000)
    Q, V, TAU = _states(rng, 10_000, f.nq, f.nv)
    PQ, PV, PTAU = _states(rng, 10_000, model.nq, model.nv)
    batch_ours, batch_pin = side_by_side(  # one call of ours, a loop of Pinocchio's, best of 3
        lambda: f.forward_dynamics(Q, V, TAU),
        lambda: [pin.aba(model, data, PQ[k], PV[k], PTAU[k]) for k in range(len(PQ))], 3, 1)
    return {"robot": name, "kernel": f.kernel, "bodies": len(f.tree.joints), "nv": f.nv,
            "pinocchio_nv": model.nv, "first_s": first, "call_us": ours * 1e6,
            "aba_us": theirs * 1e6, "batch_ms": batch_ours * 1e3,
            "aba_loop_ms": batch_pin * 1e3, "error": error}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--robots", default=",".join(TALOS))
    parser.add_argument("--no-cold", action="store_true", help="leave out the cold first result")
    args = parser.parse_args()
    rows = [measure(name, TALOS[name], kernel, not args.no_cold)
            for name in args.robots.split(",") for kernel in ("compact", "unrolled")]
    load = os.getloadavg()[0]
    if args.json:
        print(json.dumps({"load": load, "rows": rows}, indent=1))
        return
    print(f"load average {load:.2f}")
    print(f"{'robot':15} {'kernel':9} {'bodies':>6} {'nv':>4} {'first s':>8} {'call us':>8} "
          f"{'aba us':>7} {'batch ms':>9} {'aba loop ms':>12} {'error':>8}")
    for r in rows:
        error = "-" if r["error"] is None else f"{r['error']:.1e}"
        print(f"{r['robot']:15} {r['kernel']:9} {r['bodies']:6d} {r['nv']:4d} "
              f"{r['first_s']:8.2f} {r['call_us']:8.2f} {r['aba_us']:7.2f} "
              f"{r['batch_ms']:9.2f} {r['aba_loop_ms']:12.1f} {error:>8}")


if __name__ == "__main__":
    main()
