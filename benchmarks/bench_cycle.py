"""Limit cycles through impacts: ``lagrangian cycle compass_gait`` and the library's
``System.limit_cycle()`` warm (the equations derived and compiled once, in the same process).

Reproduce: ``python benchmarks/bench_cycle.py``. Prints the whole command in fresh processes
(wall, median of three) and, in one process, the first call (derivation, compiles of the flow's
sensitivity and of the impact map's derivatives) and later calls (median of five) of
limit_cycle() for the compass gait and the rimless wheel, with the load average (the
development machine is shared).
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import time


def load() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def command(args: list[str], runs: int = 3) -> float:
    walls = []
    for _ in range(runs):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "lagrangian", *args], check=True,
                       capture_output=True)
        walls.append(time.perf_counter() - start)
    return statistics.median(walls)


def main() -> None:
    import lagrangian

    print(f"lagrangian cycle compass_gait: {command(['cycle', 'compass_gait']):.2f} s wall "
          f"(fresh process, median of 3; {load()})")
    for name in ("compass_gait", "rimless_wheel"):
        system = lagrangian.load(name)
        start = time.perf_counter()
        system.limit_cycle()
        first = time.perf_counter() - start
        times = []
        for _ in range(5):
            start = time.perf_counter()
            cycle = system.limit_cycle()
            times.append(time.perf_counter() - start)
        print(f"{name}: limit_cycle() first {first:.2f} s, warm {statistics.median(times):.3f} s "
              f"(median of 5; {cycle.iterations} Newton steps; {load()})")


if __name__ == "__main__":
    main()
