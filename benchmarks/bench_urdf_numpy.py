"""The numpy fallback of the recursive URDF dynamics (no C compiler) beside the generated C
and Pinocchio, on the Panda (fingers locked, 7-DOF), per call and for a batch of 10^4 states.

    python benchmarks/bench_urdf_numpy.py [--states 100]

Needs the bench extra (pin, example-robot-data). Best of 7 rounds, the three measured in
alternation in one process (the same load for all); the load average is printed with them.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import lagrangian

sys.path.insert(0, str(Path(__file__).parent))
from bench_urdf import load_average, robots_folder  # noqa: E402 (the sibling benchmark's)

LOCK = {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}


def per_call(functions, number) -> list[float]:
    """Best time per call of each function, measured in alternation."""
    best = [np.inf] * len(functions)
    for _ in range(7):
        for k, function in enumerate(functions):
            start = time.perf_counter()
            for _ in range(number):
                function()
            best[k] = min(best[k], (time.perf_counter() - start) / number)
    return best


def main() -> None:
    import pinocchio as pin

    parser = argparse.ArgumentParser()
    parser.add_argument("--states", type=int, default=100)
    args = parser.parse_args()
    path = robots_folder() / "panda_description/urdf/panda.urdf"
    arm = lagrangian.load(path, lock=LOCK)
    slow, fast = arm.dynamics(backend="numpy"), arm.dynamics()
    assert slow.kernel == "numpy" and fast.backend == "recursive"
    model = pin.buildModelFromUrdf(str(path))
    model = pin.buildReducedModel(model, [model.getJointId(j) for j in LOCK], pin.neutral(model))
    data = model.createData()
    n = slow.n
    rng = np.random.default_rng(0)
    q, v, a, tau = (rng.uniform(-2, 2, (args.states, n)) for _ in range(4))
    worst = 0.0
    for k in range(args.states):
        theirs = pin.aba(model, data, q[k], v[k], tau[k])
        worst = max(worst, np.abs(slow.forward_dynamics(q[k], v[k], tau[k]) - theirs).max()
                    / np.abs(theirs).max())
        theirs = pin.rnea(model, data, q[k], v[k], a[k])
        worst = max(worst, np.abs(slow.inverse_dynamics(q[k], v[k], a[k]) - theirs).max()
                    / np.abs(theirs).max())
    print(f"Panda n = {n}: numpy fallback vs Pinocchio, max relative error (aba, rnea) over "
          f"{args.states} states {worst:.1e}")
    q0, v0, a0, t0 = q[0].copy(), v[0].copy(), a[0].copy(), tau[0].copy()
    print(f"per call (us): numpy fallback, generated C, Pinocchio; numpy/C, numpy/pin; "
          f"load average {load_average()}")
    for label, mine, c, theirs in [
            ("mass matrix / crba", lambda: slow.mass_matrix(q0), lambda: fast.mass_matrix(q0),
             lambda: pin.crba(model, data, q0)),
            ("inverse dyn / rnea", lambda: slow.inverse_dynamics(q0, v0, a0),
             lambda: fast.inverse_dynamics(q0, v0, a0), lambda: pin.rnea(model, data, q0, v0, a0)),
            ("forward dyn / aba", lambda: slow.forward_dynamics(q0, v0, t0),
             lambda: fast.forward_dynamics(q0, v0, t0), lambda: pin.aba(model, data, q0, v0, t0))]:
        t_numpy = per_call([mine], 200)[0]
        t_c, t_pin = per_call([c, theirs], 2000)
        print(f"  {label:<20} {t_numpy * 1e6:9.1f} {t_c * 1e6:7.2f} {t_pin * 1e6:7.2f} "
              f"{t_numpy / t_c:7.0f} {t_numpy / t_pin:7.0f}")
    big = 10_000
    Q, V, TAU = (rng.uniform(-1, 1, (big, n)) for _ in range(3))
    t_numpy, t_c, t_pin = per_call([
        lambda: slow.forward_dynamics(Q, V, TAU), lambda: fast.forward_dynamics(Q, V, TAU),
        lambda: [pin.aba(model, data, x, y, z) for x, y, z in zip(Q, V, TAU, strict=True)]], 1)
    print(f"forward dynamics, batch of {big} (ms): numpy {t_numpy * 1e3:.1f}, C {t_c * 1e3:.2f}, "
          f"Pinocchio loop {t_pin * 1e3:.1f}; numpy per state {t_numpy / big * 1e6:.2f} us; "
          f"load average {load_average()}")


if __name__ == "__main__":
    main()
