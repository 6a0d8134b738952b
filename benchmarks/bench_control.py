"""Derivatives of the dynamics and the torque regressor against Pinocchio, on a URDF arm:
agreement, and speed per call and in batches of 10^4 states.

    python benchmarks/bench_control.py [panda|ur5|xarm7|solo12] [--states 10000]

Needs the bench extra (pin, example-robot-data). The Panda's finger joints are locked at 0.
solo12 is a floating base (a free flyer at the root, nq 19, nv 18; Pinocchio's
JointModelFreeFlyer): its derivatives only (the regressor of a floating base is not given yet).

- Per call: one state through ``dynamics().inverse_dynamics_derivatives`` (and
  ``forward_dynamics_derivatives``, ``regressor``) against ``computeRNEADerivatives``
  (``computeABADerivatives``, ``computeJointTorqueRegressor``) through Pinocchio's Python
  bindings: 200 calls from Python (argument checks and the output arrays included), ours and
  Pinocchio's taking turns, the best of 7 rounds each.
- Batch: one call on N states (ours: one C call, on up to LAGRANGIAN_THREADS threads, default
  the processors) against a Python loop of N Pinocchio calls, taking turns, best of 7 each (a
  shared machine's other work slows single rounds of either side).
- Batch CPU time: the same, timed by this process's CPU time (all threads summed), which a
  shared machine's other work disturbs less than the wall clock.
- Fresh-output floor: the best time to allocate and write once as many doubles as a batch's
  outputs hold (np.empty(...).fill(0)): what a batch returning freshly allocated arrays pays
  before its arithmetic, and Pinocchio's loop over it (batch_speedup_bound) the most such a
  batch can reach here. Ours pay it on their first call only: from the second, outputs of 4 MB
  and more reuse a block the module kept (batch_threads.c), so the timed batches (best of
  several) are past it.
- Keeping the results (pinocchio_loop_keeping_s, batch_speedup_keeping): Pinocchio's loop
  copying each state's results into arrays of the batch's shapes, against ours again, taking
  turns, best of 5: Pinocchio's functions return views of its one Data, so the plain loop
  leaves only the last state's numbers, where a batch returns every state's.
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

SOLO, SOLO_PATH = "solo12", "solo_description/robots/solo12.urdf"


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


def fresh_output_floor(outputs, repeat: int = 7) -> float:
    """The best seconds to allocate and write once as many fresh doubles as ``outputs`` hold:
    the least a batch returning new arrays can cost (its pages faulted in and zeroed by the
    kernel, then written), whatever its arithmetic; Pinocchio's loop over it bounds the batch
    speed-up any such implementation reaches on this machine."""
    size = sum(np.size(x) for x in (outputs if isinstance(outputs, tuple) else (outputs,)))
    best = float("inf")
    for _ in range(repeat):
        began = time.perf_counter()
        np.empty(size).fill(0.0)
        best = min(best, time.perf_counter() - began)
    return best


def keeping_loop(theirs, q, v, a, like):
    """A loop of Pinocchio's calls that keeps every state's results, copied into arrays of a
    batch's shapes (``like``: our outputs of one state): Pinocchio's Python functions return
    views of its one Data, so the plain loop's list holds the last state's numbers 10^4 times,
    where a batch returns 10^4 states' (Minv's lower triangle, which Pinocchio leaves unset,
    is not filled in)."""
    parts = like if isinstance(like, tuple) else (like,)
    outputs = [np.empty((len(q),) + x.shape[1:]) for x in parts]

    def loop():
        for k in range(len(q)):
            got = theirs(q[k], v[k], a[k])
            # computeRNEADerivatives gives M third, which ours does not return
            for out, x in zip(outputs, got if isinstance(got, tuple) else (got,), strict=False):
                out[k] = x
    return loop


def main() -> None:
    import pinocchio as pin

    parser = argparse.ArgumentParser()
    parser.add_argument("robot", nargs="?", default="panda", choices=sorted(ROBOTS) + [SOLO])
    parser.add_argument("--states", type=int, default=10_000)
    args = parser.parse_args()
    floating = args.robot == SOLO
    relative, lock = (SOLO_PATH, {}) if floating else ROBOTS[args.robot]
    path = robots_folder() / relative
    ours = lagrangian.load(path, lock=lock, floating_base=floating).dynamics()
    model = (pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer()) if floating
             else pin.buildModelFromUrdf(str(path)))
    if lock:
        model = pin.buildReducedModel(model, [model.getJointId(j) for j in lock],
                                      pin.neutral(model))
    data = model.createData()
    rng = np.random.default_rng(0)
    q = rng.uniform(-2, 2, (args.states, model.nq))
    v, a = rng.uniform(-2, 2, (2, args.states, model.nv))
    if floating:  # a unit quaternion, the joints in Pinocchio's order (ours: the URDF's)
        q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
        assert ours.coordinates[7:] == tuple(model.names[i] for i in range(2, model.njoints))
    pairs = {
        "rnea_derivatives": (lambda Q, V, A: ours.inverse_dynamics_derivatives(Q, V, A),
                             lambda Q, V, A: pin.computeRNEADerivatives(model, data, Q, V, A)),
        "aba_derivatives": (lambda Q, V, A: ours.forward_dynamics_derivatives(Q, V, A),
                            lambda Q, V, A: pin.computeABADerivatives(model, data, Q, V, A)),
        "regressor": (lambda Q, V, A: ours.regressor(Q, V, A),
                      lambda Q, V, A: pin.computeJointTorqueRegressor(model, data, Q, V, A)),
    }
    if floating:
        del pairs["regressor"]
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
            lambda t=theirs: [t(q[k], v[k], a[k]) for k in range(args.states)], 7)
        ours_cpu, pin_cpu = interleaved(
            lambda m=mine: m(q, v, a),
            lambda t=theirs: [t(q[k], v[k], a[k]) for k in range(args.states)], 3,
            time.process_time)
        floor = fresh_output_floor(mine(q, v, a))
        keeping = keeping_loop(theirs, q, v, a, mine(q[:1], v[:1], a[:1]))
        ours_again, pin_keeping = interleaved(lambda m=mine: m(q, v, a), keeping, 5)
        report[name] = {"ours_per_call_us": ours_call * 1e6, "pinocchio_per_call_us": pin_call * 1e6,
                        "ours_batch_s": ours_batch, "pinocchio_loop_s": pin_batch,
                        "ours_batch_cpu_s": ours_cpu, "pinocchio_loop_cpu_s": pin_cpu,
                        "per_call_speedup": pin_call / ours_call,
                        "batch_speedup": pin_batch / ours_batch,
                        "batch_cpu_speedup": pin_cpu / ours_cpu,
                        "fresh_output_s": floor,
                        "batch_speedup_bound": pin_batch / floor,
                        "pinocchio_loop_keeping_s": pin_keeping,
                        "batch_speedup_keeping": pin_keeping / ours_again}
    report["load_average_after"] = os.getloadavg()
    dq, dv = ours.inverse_dynamics_derivatives(q[:20], v[:20], a[:20])
    fq, fv, ftau = ours.forward_dynamics_derivatives(q[:20], v[:20], a[:20])
    Y = None if floating else ours.regressor(q[:20], v[:20], a[:20])
    worst = {"rnea_derivatives": 0.0, "aba_derivatives": 0.0, "regressor": 0.0}
    relative = 0.0  # the forward derivatives' worst difference over their largest entry
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
        largest = max(np.abs(data.ddq_dq).max(), np.abs(data.ddq_dv).max(), np.abs(minv).max())
        relative = max(relative, worst["aba_derivatives"] / largest)
        if Y is not None:
            worst["regressor"] = max(worst["regressor"], np.abs(
                Y[k] - pin.computeJointTorqueRegressor(model, data, q[k], v[k], a[k])).max())
    report["max_abs_difference"] = worst
    report["aba_derivatives_relative_difference"] = relative
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
