"""Derivatives of the dynamics and the torque regressor against Pinocchio, on a URDF arm:
agreement, and speed per call and in batches of 10^4 states.

    python benchmarks/bench_control.py [panda|ur5|xarm7] [--states 10000]

Needs the bench extra (pin, example-robot-data). The Panda's finger joints are locked at 0.

- Per call: one state through ``dynamics().inverse_dynamics_derivatives`` (and
  ``forward_dynamics_derivatives``, ``regressor``) against ``computeRNEADerivatives``
  (``computeABADerivatives``, ``computeJointTorqueRegressor``) through Pinocchio's Python
  bindings, best of 5 runs of 200 calls, interleaved in one process.
- Batch: one call on N states (ours) against a Python loop of N Pinocchio calls, best of 3.
- Agreement: the largest absolute difference over 20 random states.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
from bench_urdf import ROBOTS, robots_folder

import lagrangian


def best(function, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        began = time.perf_counter()
        function()
        times.append(time.perf_counter() - began)
    return min(times)


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
    report = {"robot": args.robot, "states": args.states}
    for name, (mine, theirs) in pairs.items():
        ours_call = best(lambda m=mine: [m(q[k], v[k], a[k]) for k in range(200)], 5) / 200
        pin_call = best(lambda t=theirs: [t(q[k], v[k], a[k]) for k in range(200)], 5) / 200
        ours_batch = best(lambda m=mine: m(q, v, a), 3)
        pin_batch = best(lambda t=theirs: [t(q[k], v[k], a[k]) for k in range(args.states)], 3)
        report[name] = {"ours_per_call_us": ours_call * 1e6, "pinocchio_per_call_us": pin_call * 1e6,
                        "ours_batch_s": ours_batch, "pinocchio_loop_s": pin_batch,
                        "per_call_speedup": pin_call / ours_call,
                        "batch_speedup": pin_batch / ours_batch}
    dq, dv = ours.inverse_dynamics_derivatives(q[:20], v[:20], a[:20])
    Y = ours.regressor(q[:20], v[:20], a[:20])
    worst = {"rnea_derivatives": 0.0, "regressor": 0.0}
    for k in range(20):
        pq, pv, _ = pin.computeRNEADerivatives(model, data, q[k], v[k], a[k])
        worst["rnea_derivatives"] = max(worst["rnea_derivatives"], np.abs(dq[k] - pq).max(),
                                        np.abs(dv[k] - pv).max())
        worst["regressor"] = max(worst["regressor"], np.abs(
            Y[k] - pin.computeJointTorqueRegressor(model, data, q[k], v[k], a[k])).max())
    report["max_abs_difference"] = worst
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
