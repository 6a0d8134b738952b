"""The compact tree kernel (dynamics/engine/tree_kernel.c: one compiled module for every tree, the tree
an array at run time) against Pinocchio's aba, and against the unrolled module of each tree.

    python benchmarks/bench_tree_kernel.py                 # Panda (n = 7), chains of 50 and 200
    python benchmarks/bench_tree_kernel.py --threshold 4,8,12,16,20,24  # unrolled vs compact

Rows: "first s" is load (URDF -> tree) plus the first forward dynamics in a fresh process with
an empty compiled-module cache (LAGRANGIAN_CACHE a new folder; the compact kernel compiled
there once, ~3 s, import of lagrangian apart). Per call: one state through the Python API and
through Pinocchio's Python bindings, alternating in this process (best of 7 runs of 1000
calls, 200 for n = 200). Batch: forward dynamics of 10^4 states in one call (threads as the
machine has) against a Python loop over pin.aba (best of 3). Error: the largest relative
difference from aba over 5 random states. --threshold: per call forward dynamics and mass
matrix, compact and unrolled (cold compile time of the unrolled module), chains of n links.
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


def chain_urdf(n: int) -> str:
    """A serial chain (a snake robot): revolute joints about x, y, x, ... 0.1 m apart, 0.5 kg
    links with a full inertia tensor."""
    parts = [f'<?xml version="1.0"?><robot name="snake{n}"><link name="l0"/>']
    for i in range(1, n + 1):
        parts.append(
            f'<link name="l{i}"><inertial><origin xyz="0.01 0 -0.05"/><mass value="0.5"/>'
            '<inertia ixx="0.002" ixy="0.0001" ixz="0" iyy="0.0021" iyz="0.00005" izz="0.0005"/>'
            '</inertial></link>')
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
            f'<origin xyz="0 0 {0 if i == 1 else -0.1}"/><axis xyz="{"1 0 0" if i % 2 else "0 1 0"}"/>'
            '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')
    parts.append("</robot>")
    return "".join(parts)


_FIRST = """
import json, sys, time
start = time.perf_counter()
import numpy as np, lagrangian
imported = time.perf_counter()
f = lagrangian.load(sys.argv[1], **json.loads(sys.argv[2])).dynamics(kernel=sys.argv[3])
n = f.n
f.forward_dynamics(np.zeros(n), np.zeros(n), np.zeros(n))
print(time.perf_counter() - imported)
"""


def first_result(path: str, lock: dict, kernel: str = "auto") -> float:
    """Seconds from load to the first forward dynamics, cold cache, in a fresh process."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, LAGRANGIAN_CACHE=cache)
        done = subprocess.run([sys.executable, "-c", _FIRST, path, json.dumps({"lock": lock} if lock
                                                                               else {}), kernel],
                              env=env, capture_output=True, text=True, check=True)
        return float(done.stdout.split()[-1])


def measure(name: str, path: str, lock: dict) -> dict:
    import pinocchio as pin

    first = first_result(path, lock)
    system = lagrangian.load(path, lock=lock) if lock else lagrangian.load(path)
    f = system.dynamics()
    model = pin.buildModelFromUrdf(path)
    if lock:
        locked = [model.getJointId(j) for j in lock]
        q_lock = pin.neutral(model)
        for j, value in zip(locked, lock.values(), strict=True):
            q_lock[model.joints[j].idx_q] = value
        model = pin.buildReducedModel(model, locked, q_lock)
    data = model.createData()
    n = f.n
    rng = np.random.default_rng(n)
    error = 0.0
    for _ in range(5):
        q, v, tau = (rng.uniform(-1, 1, n) for _ in range(3))
        theirs = pin.aba(model, data, q, v, tau)
        error = max(error, float(np.max(np.abs(f.forward_dynamics(q, v, tau) - theirs))
                                 / np.max(np.abs(theirs))))
    q, v, tau = (rng.uniform(-1, 1, n) for _ in range(3))
    number = 200 if n > 100 else 1000
    ours, theirs = side_by_side(lambda: f.forward_dynamics(q, v, tau),
                                lambda: pin.aba(model, data, q, v, tau), number=number)
    Q, V, TAU = (rng.uniform(-1, 1, (10_000, n)) for _ in range(3))
    batch_ours, batch_pin = side_by_side(  # one call of ours, a loop of Pinocchio's, best of 3
        lambda: f.forward_dynamics(Q, V, TAU),
        lambda: [pin.aba(model, data, Q[k], V[k], TAU[k]) for k in range(len(Q))], 3, 1)
    return {"name": name, "n": n, "kernel": getattr(f, "kernel", "?"), "first_s": first,
            "error": error, "ours_us": ours * 1e6, "pin_us": theirs * 1e6,
            "batch_ours_ms": batch_ours * 1e3, "batch_pin_ms": batch_pin * 1e3}


def _per_call(system, n: int):
    """Forward dynamics and M per call (s): (unrolled, compact) each."""
    u, c = system.dynamics(kernel="unrolled"), system.dynamics(kernel="compact")
    q = np.linspace(-1, 1, n)
    return (side_by_side(lambda: u.forward_dynamics(q, q, q), lambda: c.forward_dynamics(q, q, q),
                         number=1000),
            side_by_side(lambda: u.mass_matrix(q), lambda: c.mass_matrix(q), number=1000))


def threshold(sizes: list[int]) -> None:
    print(" n  unrolled cold s | FD unrolled / compact us | M unrolled / compact us")
    with tempfile.TemporaryDirectory() as folder:
        for n in sizes:
            path = Path(folder) / f"chain{n}.urdf"
            path.write_text(chain_urdf(n))
            cold = first_result(str(path), {}, "unrolled")
            fd, m = _per_call(lagrangian.load(path), n)
            print(f"{n:3d} {cold:8.1f} | {fd[0] * 1e6:7.2f} {fd[1] * 1e6:7.2f} | "
                  f"{m[0] * 1e6:7.2f} {m[1] * 1e6:7.2f}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--threshold", help="chain sizes: unrolled against compact")
    parser.add_argument("--sizes", default="50,200", help="chain sizes besides the Panda")
    args = parser.parse_args()
    if args.threshold:
        threshold([int(x) for x in args.threshold.split(",")])
        return
    cases = [("panda (fingers locked)", str(ROBOTS / "panda_description/urdf/panda.urdf"),
              {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0})]
    with tempfile.TemporaryDirectory() as folder:
        for n in map(int, args.sizes.split(",")):
            path = Path(folder) / f"snake{n}.urdf"
            path.write_text(chain_urdf(n))
            cases.append((f"snake chain {n}", str(path), {}))
        print("robot                    n  kernel   first s  error    FD ours / aba us  ratio "
              "  10^4 FD ours / aba loop ms  ratio  load")
        for name, path, lock in cases:
            r = measure(name, path, lock)
            print(f"{name:22s} {r['n']:4d}  {r['kernel']:8s} {r['first_s']:6.2f}  "
                  f"{r['error']:7.1e}  {r['ours_us']:7.2f} {r['pin_us']:7.2f}  "
                  f"{r['ours_us'] / r['pin_us']:5.2f}   {r['batch_ours_ms']:8.2f} "
                  f"{r['batch_pin_ms']:8.1f}  {r['batch_pin_ms'] / r['batch_ours_ms']:6.1f}  "
                  f"{os.getloadavg()[0]:4.1f}", flush=True)


if __name__ == "__main__":
    main()
