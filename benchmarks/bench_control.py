"""Derivatives of the dynamics and the torque regressor against Pinocchio, on a URDF arm:
agreement, and speed per call and in batches of 10^4 states.

    python benchmarks/bench_control.py [panda|ur5|xarm7] [--states 10000]

Needs the bench extra (pin, example-robot-data). The Panda's finger joints are locked at 0.

- Per call: one state through ``dynamics().inverse_dynamics_derivatives`` (and
  ``forward_dynamics_derivatives``, ``regressor``) against ``computeRNEADerivatives``
  (``computeABADerivatives``, ``computeJointTorqueRegressor``) through Pinocchio's Python
  bindings: 200 calls from Python (argument checks and the output arrays included), ours and
  Pinocchio's taking turns, the best of 7 rounds each.
- Batch: one call on N states (ours: one C call, on up to LAGRANGIAN_THREADS threads, default
  the processors) against a Python loop of N Pinocchio calls, taking turns, best of 3 each.
- Batch CPU time: the same, timed by this process's CPU time (all threads summed), which a
  shared machine's other work disturbs less than the wall clock.
- Agreement: the largest absolute difference over 20 random states.
- The machine's load average before and after, and its processor count, are printed with the
  figures: on a shared machine both sides slow down, not always alike.
"""

from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np
from bench_urdf import ROBOTS, robots_folder

import lagrangian


def interleaved(first, second, repeat: int, clock=time.perf_counter) -> tuple[float, float]:
    """The best time of each of two functions over ``repeat`` rounds, taking turns (``clock``:
    wall time, or time.process_time: this process's CPU time, all its threads summed)."""
    times: tuple[list[float], list[float]] = ([], [])
    for _ in range(repeat):
        for function, out in ((first, times[0]), (second, times[1])):
            began = clock()
            function()
            out.append(clock() - began)
    return min(times[0]), min(times[1])


def main() -> None:
    import pinocchio as pin

    parser = argparse.ArgumentParser()
    parser.add_argument("robot", nargs="?", default="panda", choices=sorted(ROBOTS))
    parser.add_argument("--states", type=int, default=10_000)
    args = parser.parse_args()
    relative, lock = ROBOTS[args.robot]
    path = robots_folder() / relative
    ours = lagrangian.load(path, lock=lock).dynamics()
    model = pin.buildModelFromUrdf(str(path))
    if lock:
        model = pin.buildReducedModel(model, [model.getJointId(j) for j in lock],
                                      pin.neutral(model))
    data = model.createData()
    n = model.nq
    rng = np.random.default_rng(0)
    q, v, a = rng.uniform(-2, 2, (3, args.states, n))
    pairs = {
        "rnea_derivatives": (lambda Q, V, A: ours.inverse_dynamics_derivatives(Q, V, A),
                             lambda Q, V, A: pin.computeRNEADerivatives(model, data, Q, V, A)),
        "aba_derivatives": (lambda Q, V, A: ours.forward_dynamics_derivatives(Q, V, A),
                            lambda Q, V, A: pin.computeABADerivatives(model, data, Q, V, A)),
        "regressor": (lambda Q, V, A: ours.regressor(Q, V, A),
                      lambda Q, V, A: pin.computeJointTorqueRegressor(model, data, Q, V, A)),
    }
    report = {"robot": args.robot, "states": args.states, "cpus": os.cpu_count(),
              "threads": os.environ.get("LAGRANGIAN_THREADS", "processors"),
              "load_average_before": os.getloadavg()}
    for name, (mine, theirs) in pairs.items():
        mine(q[:8], v[:8], a[:8])  # compiled (and cached) before the clock starts
        ours_call, pin_call = (t / 200 for t in interleaved(
            lambda m=mine: [m(q[k], v[k], a[k]) for k in range(200)],
            lambda t=theirs: [t(q[k], v[k], a[k]) for k in range(200)], 7))
        ours_batch, pin_batch = interleaved(
            lambda m=mine: m(q, v, a),
            lambda t=theirs: [t(q[k], v[k], a[k]) for k in range(args.states)], 3)
        ours_cpu, pin_cpu = interleaved(
            lambda m=mine: m(q, v, a),
            lambda t=theirs: [t(q[k], v[k], a[k]) for k in range(args.states)], 3,
            time.process_time)
        report[name] = {"ours_per_call_us": ours_call * 1e6, "pinocchio_per_call_us": pin_call * 1e6,
                        "ours_batch_s": ours_batch, "pinocchio_loop_s": pin_batch,
                        "ours_batch_cpu_s": ours_cpu, "pinocchio_loop_cpu_s": pin_cpu,
                        "per_call_speedup": pin_call / ours_call,
                        "batch_speedup": pin_batch / ours_batch,
                        "batch_cpu_speedup": pin_cpu / ours_cpu}
    report["load_average_after"] = os.getloadavg()
    dq, dv = ours.inverse_dynamics_derivatives(q[:20], v[:20], a[:20])
    fq, fv, ftau = ours.forward_dynamics_derivatives(q[:20], v[:20], a[:20])
    Y = ours.regressor(q[:20], v[:20], a[:20])
    worst = {"rnea_derivatives": 0.0, "aba_derivatives": 0.0, "regressor": 0.0}
    for k in range(20):
        pq, pv, _ = pin.computeRNEADerivatives(model, data, q[k], v[k], a[k])
        worst["rnea_derivatives"] = max(worst["rnea_derivatives"], np.abs(dq[k] - pq).max(),
                                        np.abs(dv[k] - pv).max())
        pin.computeABADerivatives(model, data, q[k], v[k], a[k])
        minv = np.triu(data.Minv) + np.triu(data.Minv, 1).T
        worst["aba_derivatives"] = max(worst["aba_derivatives"],
                                       np.abs(fq[k] - data.ddq_dq).max(),
                                       np.abs(fv[k] - data.ddq_dv).max(),
                                       np.abs(ftau[k] - minv).max())
        worst["regressor"] = max(worst["regressor"], np.abs(
            Y[k] - pin.computeJointTorqueRegressor(model, data, q[k], v[k], a[k])).max())
    report["max_abs_difference"] = worst
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
