"""The cost of a compiled-module cache hit in a fresh process: an n-link pendulum's equations
(derived first, not timed) to a NumericSystem whose C module is already on disk.

    python benchmarks/bench_cache_hit.py 10     # run twice: the first run fills the cache
"""

from __future__ import annotations

import sys
import time

from n_link import build_lagrangian

from lagrangian.compile.functions import numeric


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 10
    eom = build_lagrangian(n).equations_of_motion()
    began = time.perf_counter()
    system = numeric(eom, backend="c")
    print(f"n = {n}: equations -> compiled functions ({system.backend}) "
          f"{time.perf_counter() - began:.3f} s")


if __name__ == "__main__":
    main()
