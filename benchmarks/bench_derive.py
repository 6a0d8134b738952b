"""Derivation speed: the n-link pendulum to mass matrix and forcing, ours vs sympy.physics.mechanics.

Run:  python benchmarks/bench_derive.py [--sizes 1,2,4,...] [--limit 90] [--ours-only 20,30]

Each run is a child process under a time limit (a run past it is reported as "> limit"), best
of three where a run takes under 5 s. Before timing, our accelerations are checked to equal
KanesMethod's at a random state.
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import random
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

import n_link  # noqa: E402
import numpy as np  # noqa: E402
import sympy as sp  # noqa: E402


def _timed(name: str, n: int, queue) -> None:
    function = {"ours": n_link.ours, "lagrange": n_link.sympy_lagranges_method,
                "kane": n_link.sympy_kanes_method}[name]
    start = time.perf_counter()
    function(n)
    queue.put(time.perf_counter() - start)


def run(name: str, n: int, limit: float) -> float | None:
    """Best wall time of up to three derivations, each in a fresh process (so caches do not
    help), repeated only while a run takes under 5 s (the same rule for every library)."""
    best = None
    for _ in range(3):
        elapsed = run_once(name, n, limit)
        if elapsed is None:
            return best
        best = elapsed if best is None else min(best, elapsed)
        if elapsed > 5.0:
            break
    return best


def run_once(name: str, n: int, limit: float) -> float | None:
    """Wall time of one derivation in a fresh process, or None past the time limit."""
    context = mp.get_context("fork")
    queue = context.Queue()
    process = context.Process(target=_timed, args=(name, n, queue))
    process.start()
    process.join(limit)
    if process.is_alive():
        process.kill()
        process.join()
        return None
    return queue.get() if not queue.empty() else None


def agree(n: int) -> bool:
    """Our M q_ddot - f and sympy's (Kane) agree at a random state (independent derivations)."""
    import sympy.physics.mechanics as me

    rng = random.Random(n)
    M1, f1 = n_link.ours(n)
    M2, f2 = n_link.sympy_kanes_method(n)
    values, values2 = {}, {}
    for i in range(1, n + 1):
        th, w = rng.uniform(-2, 2), rng.uniform(-2, 2)
        m, length = rng.uniform(0.5, 2), rng.uniform(0.5, 2)
        values.update({sp.Symbol(f"theta{i}"): th, sp.Symbol(f"theta{i}_dot"): w,
                       sp.Symbol(f"m{i}"): m, sp.Symbol(f"l{i}"): length})
        values2.update({me.dynamicsymbols(f"theta{i}"): th, me.dynamicsymbols(f"theta{i}_dot"): w,
                        sp.Symbol(f"m{i}"): m, sp.Symbol(f"l{i}"): length})
    values[sp.Symbol("g")] = values2[sp.Symbol("g")] = 9.81
    values[sp.Symbol("t")] = 0.0
    a = np.array(M1.xreplace(values).evalf(), dtype=float)
    b = np.array(f1.xreplace(values).evalf(), dtype=float)
    c = np.array(M2.subs(values2).evalf(), dtype=float)
    d = np.array(f2.subs(values2).evalf(), dtype=float)
    return np.allclose(np.linalg.solve(a, b), np.linalg.solve(c, d), rtol=1e-9)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sizes", default="1,2,4,6,8,10,12,14,16")
    parser.add_argument("--limit", type=float, default=60.0, help="seconds per anchor run")
    parser.add_argument("--ours-only", default="20,30", help="extra sizes for ours alone")
    args = parser.parse_args()
    sizes = [int(s) for s in args.sizes.split(",")]

    for n in (2, 5):
        print(f"check n={n}: ours and KanesMethod give the same accelerations: {agree(n)}")
    print()
    header = (f"{'n':>3}  {'ours [s]':>9}  {'Lagrange [s]':>12}  {'Kane [s]':>9}  "
              f"{'Lagrange/ours':>13}  {'Kane/ours':>9}")
    print(header)
    print("-" * len(header))
    skip = {"lagrange": False, "kane": False}
    for n in sizes:
        ours = run("ours", n, args.limit)
        row = {}
        for name in ("lagrange", "kane"):
            row[name] = None if skip[name] else run(name, n, args.limit)
            if row[name] is None:
                skip[name] = True  # larger n would only take longer
        def cell(value):
            return f"{value:.3f}" if value is not None else f"> {args.limit:.0f}"

        def ratio(value, ours=ours):
            return f"{value / ours:.0f}x" if value is not None and ours else "-"

        print(f"{n:>3}  {cell(ours):>9}  {cell(row['lagrange']):>12}  {cell(row['kane']):>9}  "
              f"{ratio(row['lagrange']):>13}  {ratio(row['kane']):>9}", flush=True)
    for n in [int(s) for s in args.ours_only.split(",") if s]:
        print(f"{n:>3}  {run('ours', n, args.limit * 5) or float('nan'):>9.3f}  "
              f"{'(not run)':>12}  {'(not run)':>9}", flush=True)


if __name__ == "__main__":
    main()
