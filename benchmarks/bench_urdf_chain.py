"""How cost grows with the number of links: a chain of n links built in URDF (revolute joints
about x, y, x, ... 0.5 m apart, 1 kg links with full inertia), ours (recursive generated C,
``arm.dynamics()``) against Pinocchio's aba, crba and rnea, n = 2 ... 50.

    python benchmarks/bench_urdf_chain.py [--sizes 2,3,...] [--plot docs/images/urdf_chain_scaling.png]

Per call: one state through the Python API and through Pinocchio's Python bindings, measured
in alternation in this process (best of 7 runs of 1000 calls). Build: URDF -> compiled functions
in this process (C generation and compilation; the compiled-module cache is used when it holds
the chain already: run with LAGRANGIAN_CACHE=$(mktemp -d) for cold builds). Error: the largest
relative difference from Pinocchio over 5 random states (forward dynamics, M, inverse dynamics).
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np
from bench_urdf import side_by_side  # the sibling benchmark's: turns taken, best per call

import lagrangian

SIZES = (2, 3, 4, 5, 6, 8, 10, 12, 15, 20, 25, 30, 40, 50)


def chain_urdf(n: int) -> str:
    parts = [f'<?xml version="1.0"?><robot name="chain{n}"><link name="l0"/>']
    for i in range(1, n + 1):
        parts.append(
            f'<link name="l{i}"><inertial><origin xyz="0 0 -0.25"/><mass value="1"/>'
            '<inertia ixx="0.02" ixy="0.001" ixz="0" iyy="0.021" iyz="0.0005" izz="0.005"/>'
            '</inertial></link>')
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
            f'<origin xyz="0 0 {0 if i == 1 else -0.5}"/><axis xyz="{"1 0 0" if i % 2 else "0 1 0"}"/>'
            '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')
    parts.append("</robot>")
    return "".join(parts)


def relative(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - b)) / np.max(np.abs(b)))


def measure(n: int, folder: Path) -> dict:
    import pinocchio as pin

    path = folder / f"chain{n}.urdf"
    path.write_text(chain_urdf(n))
    start = time.perf_counter()
    f = lagrangian.load(path).dynamics()
    f.forward_dynamics(np.zeros(n), np.zeros(n), np.zeros(n))
    build = time.perf_counter() - start
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    rng = np.random.default_rng(n)
    error = 0.0
    for _ in range(5):
        q, v, a = (rng.uniform(-1, 1, n) for _ in range(3))
        m = pin.crba(model, data, q).copy()
        m = np.triu(m) + np.triu(m, 1).T
        error = max(error, relative(f.forward_dynamics(q, v, a), pin.aba(model, data, q, v, a)),
                    relative(f.mass_matrix(q), m),
                    relative(f.inverse_dynamics(q, v, a), pin.rnea(model, data, q, v, a)))
    q, v, a = (rng.uniform(-1, 1, n) for _ in range(3))
    row = {"n": n, "build_s": build, "error": error, "load": os.getloadavg()[0]}
    for key, mine, theirs in (
            ("forward", lambda: f.forward_dynamics(q, v, a), lambda: pin.aba(model, data, q, v, a)),
            ("mass", lambda: f.mass_matrix(q), lambda: pin.crba(model, data, q)),
            ("inverse", lambda: f.inverse_dynamics(q, v, a),
             lambda: pin.rnea(model, data, q, v, a))):
        ours, theirs_ = side_by_side(mine, theirs, number=1000)
        row[f"{key}_ours_us"], row[f"{key}_pin_us"] = ours * 1e6, theirs_ * 1e6
    return row


def plot(rows: list[dict], target: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = [r["n"] for r in rows]
    fig, ax = plt.subplots(figsize=(6, 3.6), dpi=90)
    for key, label, style in (("forward", "forward dynamics", "-"), ("mass", "mass matrix", "--"),
                              ("inverse", "inverse dynamics", ":")):
        ax.plot(n, [r[f"{key}_ours_us"] for r in rows], "o" + style, color="C0", ms=3,
                label=f"lagrangian {label}")
        pin_name = {"forward": "aba", "mass": "crba", "inverse": "rnea"}[key]
        ax.plot(n, [r[f"{key}_pin_us"] for r in rows], "s" + style, color="C3", ms=3,
                label=f"Pinocchio {pin_name}")
    ax.set_xlabel("links n")
    ax.set_ylabel("time per call from Python (µs)")
    ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    ax.set_title("n-link URDF chain, per call (one process, side by side)", fontsize=9)
    fig.tight_layout()
    fig.savefig(target)
    print(f"wrote {target}")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--sizes", default=",".join(map(str, SIZES)))
    parser.add_argument("--plot", help="write the figure here (PNG)")
    parser.add_argument("--json", help="write the rows here")
    args = parser.parse_args()
    rows = []
    print(" n   build s   error    fd / aba (us)   ratio    M / crba (us)   ratio   "
          "id / rnea (us)   ratio  load")
    with tempfile.TemporaryDirectory() as folder:
        for n in map(int, args.sizes.split(",")):
            r = measure(n, Path(folder))
            rows.append(r)
            print(f"{n:2d} {r['build_s']:8.1f} {r['error']:8.1e} "
                  f"{r['forward_ours_us']:7.2f} {r['forward_pin_us']:7.2f} "
                  f"{r['forward_pin_us'] / r['forward_ours_us']:7.2f} "
                  f"{r['mass_ours_us']:7.2f} {r['mass_pin_us']:7.2f} "
                  f"{r['mass_pin_us'] / r['mass_ours_us']:7.2f} "
                  f"{r['inverse_ours_us']:7.2f} {r['inverse_pin_us']:7.2f} "
                  f"{r['inverse_pin_us'] / r['inverse_ours_us']:7.2f} {r['load']:5.2f}",
                  flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    if args.plot:
        plot(rows, args.plot)


if __name__ == "__main__":
    main()
