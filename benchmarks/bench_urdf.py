"""URDF arms against Pinocchio: relative error and speed of M, bias, gravity, inverse and
forward dynamics and energies, per call and in batches of 10^4 states.

    python benchmarks/bench_urdf.py [ur5|panda|xarm7 ...] [--backend c|numpy] [--states 100]

Needs the bench extra (pin, example-robot-data). The Panda's finger joints are locked at 0.
Build time: URDF -> derived equations -> numeric functions, in this process (cold, no cache of
the generated source). Per-call times: one state through the Python API (ours) and through
Pinocchio's Python bindings (crba, rnea, aba), best of 5 runs of many calls. Batch: one call on
10^4 states (ours) against a Python loop of 10^4 Pinocchio calls.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import lagrangian

ROBOTS = {
    "ur5": ("ur_description/urdf/ur5_robot.urdf", {}),
    "panda": ("panda_description/urdf/panda.urdf",
              {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}),
    "xarm7": ("xarm_description/urdf/xarm7.urdf", {}),
}


def robots_folder() -> Path:
    import pinocchio

    for parent in Path(pinocchio.__file__).resolve().parents:
        candidate = parent / "share/example-robot-data/robots"
        if candidate.is_dir():
            return candidate
    sys.exit("example-robot-data not found (pip install example-robot-data)")


def best(function, repeat=5, number=200) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(number):
            function()
        times.append((time.perf_counter() - start) / number)
    return min(times)


def relative(ours, theirs) -> float:
    ours, theirs = np.asarray(ours), np.asarray(theirs)
    return float(np.max(np.abs(ours - theirs)) / max(np.max(np.abs(theirs)), 1e-300))


def bench(name: str, backend: str, states: int, timing: bool = True) -> None:
    import pinocchio as pin

    relpath, lock = ROBOTS[name]
    path = robots_folder() / relpath
    start = time.perf_counter()
    arm = lagrangian.load(path, lock=lock)
    eom = arm.equations_of_motion()
    derived = time.perf_counter() - start
    f = arm.dynamics(backend=backend)
    built = time.perf_counter() - start
    model = pin.buildModelFromUrdf(str(path))
    if lock:
        locked = [model.getJointId(j) for j in lock]
        model = pin.buildReducedModel(model, locked, pin.neutral(model))
    data = model.createData()
    n = f.n
    assert model.nq == n, (model.nq, n)
    names = [model.names[i] for i in range(1, model.njoints)]
    assert names == [c.name for c in arm.model.coordinates], names
    rng = np.random.default_rng(0)
    lower, upper = model.lowerPositionLimit, model.upperPositionLimit
    q = rng.uniform(np.maximum(lower, -3), np.minimum(upper, 3), (states, n))
    v, a, tau = (rng.uniform(-2, 2, (states, n)) for _ in range(3))
    errors = {k: 0.0 for k in ("M", "bias", "gravity", "inverse", "forward", "T", "V")}
    ours = {"M": f.mass_matrix(q), "bias": f.bias_forces(q, v), "gravity": f.gravity(q),
            "inverse": f.inverse_dynamics(q, v, a), "forward": f.forward_dynamics(q, v, tau),
            "T": f.kinetic_energy(q, v), "V": f.potential_energy(q)}
    for k in range(states):
        m = pin.crba(model, data, q[k]).copy()
        m = np.triu(m) + np.triu(m, 1).T
        theirs = {"M": m, "bias": pin.rnea(model, data, q[k], v[k], np.zeros(n)),
                  "gravity": pin.computeGeneralizedGravity(model, data, q[k]),
                  "inverse": pin.rnea(model, data, q[k], v[k], a[k]),
                  "forward": pin.aba(model, data, q[k], v[k], tau[k]),
                  "T": pin.computeKineticEnergy(model, data, q[k], v[k]),
                  "V": pin.computePotentialEnergy(model, data, q[k])}
        for key in errors:
            errors[key] = max(errors[key], relative(ours[key][k], theirs[key]))
    print(f"\n{name}: n = {n}, backend {f.functions.backend}; derive {derived:.1f} s, "
          f"numeric functions {built - derived:.1f} s, eom ops "
          f"{sum(e.count_ops() for e in eom.mass_matrix) + sum(e.count_ops() for e in eom.forcing)}")
    print("  max relative error vs Pinocchio over", states, "states:",
          ", ".join(f"{k} {e:.1e}" for k, e in errors.items()))
    if not timing:
        return
    q0, v0, a0, t0 = q[0], v[0], a[0], tau[0]
    rows = [("mass matrix / crba", lambda: f.mass_matrix(q0), lambda: pin.crba(model, data, q0)),
            ("inverse dyn / rnea", lambda: f.inverse_dynamics(q0, v0, a0),
             lambda: pin.rnea(model, data, q0, v0, a0)),
            ("forward dyn / aba", lambda: f.forward_dynamics(q0, v0, t0),
             lambda: pin.aba(model, data, q0, v0, t0))]
    print("  per call (us): ours, Pinocchio, ratio pin/ours")
    for label, mine, theirs in rows:
        t_ours, t_pin = best(mine), best(theirs)
        print(f"    {label:<20} {t_ours * 1e6:9.1f} {t_pin * 1e6:9.1f} {t_pin / t_ours:7.2f}")
    big = 10_000
    Q = rng.uniform(-1, 1, (big, n))
    V, A, TAU = (rng.uniform(-1, 1, (big, n)) for _ in range(3))
    print(f"  batch of {big} (ms): ours one call, Pinocchio Python loop, ratio")
    for label, mine, theirs in [
            ("mass matrix", lambda: f.mass_matrix(Q),
             lambda: [pin.crba(model, data, x) for x in Q]),
            ("inverse dyn", lambda: f.inverse_dynamics(Q, V, A),
             lambda: [pin.rnea(model, data, x, y, z) for x, y, z in zip(Q, V, A, strict=True)]),
            ("forward dyn", lambda: f.forward_dynamics(Q, V, TAU),
             lambda: [pin.aba(model, data, x, y, z) for x, y, z in zip(Q, V, TAU, strict=True)])]:
        t_ours, t_pin = best(mine, 3, 1), best(theirs, 3, 1)
        print(f"    {label:<20} {t_ours * 1e3:9.1f} {t_pin * 1e3:9.1f} {t_pin / t_ours:7.2f}")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("robots", nargs="*", default=["ur5", "panda", "xarm7"])
    parser.add_argument("--backend", default="auto", choices=("auto", "c", "numpy"))
    parser.add_argument("--states", type=int, default=100)
    parser.add_argument("--accuracy-only", action="store_true", help="skip the timings")
    args = parser.parse_args()
    for name in args.robots:
        bench(name, args.backend, args.states, not args.accuracy_only)


if __name__ == "__main__":
    main()
