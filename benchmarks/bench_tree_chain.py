"""A spatial chain of n rigid bodies from a model file (benchmarks/model_files.spatial_chain:
revolute joints about x, y, x, ...), through its kinematic tree: model built -> M, f -> the
compiled right-hand side, each size in a fresh process with an empty module cache.

    python benchmarks/bench_tree_chain.py [--sizes 20,50,100] [--pinocchio 20]

Per size: ``seconds`` from reading the file to the first rhs call (load, the tree in numbers,
C generated and compiled, M(q) and f(q, q_dot) evaluated once), ``peak MB`` the largest
resident set of the process or of a compiler it ran (ru_maxrss), ``rhs us`` one call of
``System.numeric().rhs(t, y)`` from Python (best of 5 x 2000), then ``simulate`` (2 s of motion,
module cached) and ``modes`` about the hanging chain; ``crosscheck`` (sizes up to
--crosscheck) is the whole command ``lagrangian crosscheck chain.toml`` in a fresh process
(start-up, load, Lagrange's equations, Newton-Euler and the comparison). With --pinocchio n:
the same chain written as a URDF, Pinocchio's ``aba`` timed in the same process (best of
5 x 2000 from Python), after checking that the two forward dynamics agree at random states.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
import timeit
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from model_files import spatial_chain, spatial_chain_urdf  # noqa: E402


def _peak_mb() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return max(own, children) / 1024


def _child(n: int, pinocchio: bool, crosscheck: bool) -> None:
    import numpy as np

    import lagrangian

    lagrangian.System  # noqa: B018  (imports are not part of the time)
    folder = Path(tempfile.mkdtemp())
    os.environ["LAGRANGIAN_CACHE"] = str(folder / "cache")
    path = folder / "chain.toml"
    path.write_text(spatial_chain(n))
    start = time.perf_counter()
    system = lagrangian.load(path)
    dynamics = system.dynamics()
    rng = np.random.default_rng(0)
    q, v = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
    dynamics.mass_matrix(q), dynamics.bias_forces(q, v)
    rhs = system.numeric().rhs
    y = np.concatenate([q, v])
    rhs(0.0, y)
    report = {"n": n, "seconds": time.perf_counter() - start, "peak_mb": _peak_mb(),
              "backend": dynamics.backend}
    report["rhs_us"] = min(timeit.repeat(lambda: rhs(0.0, y), number=2000, repeat=5)) / 2000 * 1e6
    started = time.perf_counter()
    run = system.simulate(2.0)
    report["simulate_s"] = time.perf_counter() - started
    report["simulate_status"] = run.status
    report["energy_drift"] = float(np.abs(run.energy - run.energy[0]).max()
                                   / np.abs(run.energy).max())
    started = time.perf_counter()
    modes = system.modes(about={f"q{i}": 0.0 for i in range(n)})
    report["modes_s"] = time.perf_counter() - started
    report["lowest_hz"] = modes.modes[0].frequency / (2 * np.pi)
    if crosscheck:
        started = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", "from lagrangian.cli import main; main()",
                               "crosscheck", str(path)], capture_output=True, text=True)
        report["crosscheck_s"] = time.perf_counter() - started
        report["crosscheck_agree"] = done.returncode == 0 and done.stdout.rstrip().endswith(
            "agree") and "DIFFER" not in done.stdout
    if pinocchio:
        import pinocchio as pin

        model = pin.buildModelFromXML(spatial_chain_urdf(n))
        data = model.createData()
        for _ in range(3):
            q, v, tau = (rng.uniform(-1, 1, n) for _ in range(3))
            ours = dynamics.forward_dynamics(q, v, tau)
            theirs = pin.aba(model, data, q, v, tau)
            assert np.allclose(ours, theirs, rtol=1e-9, atol=1e-9), (ours, theirs)
        tau = np.zeros(n)
        report["aba_us"] = min(timeit.repeat(lambda: pin.aba(model, data, q, v, tau),
                                             number=2000, repeat=5)) / 2000 * 1e6
    print(json.dumps(report))


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--sizes", default="20,50,100")
    parser.add_argument("--pinocchio", type=int, default=20)
    parser.add_argument("--crosscheck", type=int, default=20,
                        help="time the crosscheck command for sizes up to this")
    parser.add_argument("--limit", type=float, default=900.0)
    parser.add_argument("--child", type=int)
    args = parser.parse_args()
    if args.child:
        _child(args.child, args.child == args.pinocchio, args.child <= args.crosscheck)
        return
    print(f"load average at start: {os.getloadavg()[0]:.2f}")
    print("| n | model -> rhs (s) | peak (MB) | rhs (µs) | Pinocchio aba (µs) | simulate 2 s (s) "
          "| energy drift | modes (s) | crosscheck (s) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for n in (int(s) for s in args.sizes.split(",")):
        try:
            out = subprocess.run([sys.executable, __file__, "--child", str(n), "--pinocchio",
                                  str(args.pinocchio), "--crosscheck", str(args.crosscheck)],
                                 capture_output=True, text=True,
                                 timeout=args.limit, check=True).stdout
        except subprocess.TimeoutExpired:
            print(f"| {n} | > {args.limit:g} | | | | | | | |", flush=True)
            continue
        r = json.loads(out.strip().splitlines()[-1])
        aba = f"{r['aba_us']:.2f}" if "aba_us" in r else ""
        cross = (f"{r['crosscheck_s']:.1f}" + ("" if r["crosscheck_agree"] else " (FAILED)")
                 if "crosscheck_s" in r else "")
        print(f"| {n} | {r['seconds']:.1f} | {r['peak_mb']:.0f} | {r['rhs_us']:.2f} | {aba} "
              f"| {r['simulate_s']:.2f} | {r['energy_drift']:.1e} | {r['modes_s']:.2f} | {cross} |",
              flush=True)
    print(f"load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
