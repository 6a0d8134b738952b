"""Derivatives of the dynamics and the torque regressor against Pinocchio, on a URDF arm:
agreement, and speed per call and in batches of 10^4 states.

    python benchmarks/bench_control.py [panda|ur5|xarm7|solo12|chain200|tree100] [--states N]
    python benchmarks/bench_control.py --build

Needs the bench extra (pin, example-robot-data). The Panda's finger joints are locked at 0.
solo12 is a floating base (a free flyer at the root, nq 19, nv 18; Pinocchio's
JointModelFreeFlyer): its derivatives only (the regressor of a floating base is not given yet).
chain200 is a 200-joint serial chain (fixed base), tree100 a free flyer with four limbs of two
fingers each (96 joints, nv 102), both written here as URDF: their derivatives only, 64 states
by default (a state's three outputs are 0.9 MB on the chain), the per-call rounds over as many.
One compiled module serves every robot: --build times its build in an empty cache (a fresh
process), paid once per installation; each robot then pays for its tables only (tables_s).

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
CHAIN, TREE = "chain200", "tree100"
_INERTIA = ('<inertia ixx="0.002" ixy="0.0001" ixz="0" iyy="0.0021" iyz="0.00005" '
            'izz="0.0005"/>')


def _link(name: str, mass: float) -> str:
    return (f'<link name="{name}"><inertial><origin xyz="0.01 -0.005 0.03"/>'
            f'<mass value="{mass}"/>{_INERTIA}</inertial></link>')


def _joint(name: str, parent: str, child: str, index: int, origin: str) -> str:
    """Revolute about x, y, z in turn; in a tree (rpy in ``origin``) every fifth a slide."""
    slides = index % 5 == 2 and "rpy" in origin
    axis = "0.6 0 0.8" if slides else ("1 0 0", "0 1 0", "0 0 1")[index % 3]
    return (f'<joint name="{name}" type="{"prismatic" if slides else "revolute"}">'
            f'<parent link="{parent}"/><child link="{child}"/><origin {origin}/>'
            f'<axis xyz="{axis}"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')


def chain_urdf(n: int = 200) -> str:
    """n revolute joints 0.1 m apart, 0.5 kg links."""
    parts = ['<?xml version="1.0"?><robot name="chain"><link name="l0"/>']
    for i in range(1, n + 1):
        parts += [_link(f"l{i}", 0.5), _joint(f"j{i}", f"l{i - 1}", f"l{i}", i,
                                              f'xyz="0 0 {0 if i == 1 else -0.1}"')]
    return "".join(parts) + "</robot>"


def tree_urdf(limbs: int = 4, arm: int = 12, finger: int = 6) -> str:
    """A trunk with ``limbs`` limbs, each ``arm`` joints then two fingers of ``finger``, depth
    first (Pinocchio's order)."""
    parts, count = ['<?xml version="1.0"?><robot name="tree">', _link("trunk", 5.0)], 0
    origin = 'xyz="0.02 0.01 0.06" rpy="0.1 0 -0.2"'
    for limb in range(limbs):
        parent = "trunk"
        for k in range(arm):
            parts += [_link(f"l{limb}_{k}", 0.3),
                      _joint(f"j{limb}_{k}", parent, f"l{limb}_{k}", count, origin)]
            parent, count = f"l{limb}_{k}", count + 1
        for side in range(2):
            tip = parent
            for k in range(finger):
                child = f"l{limb}_{side}_{k}"
                parts += [_link(child, 0.1),
                          _joint(f"j{limb}_{side}_{k}", tip, child, count, origin)]
                tip, count = child, count + 1
    return "".join(parts) + "</robot>"


def build_time() -> float:
    """Seconds to build the one derivatives module in an empty cache, in a fresh process."""
    import subprocess
    import sys
    import tempfile

    code = ("import time; from lagrangian.dynamics.engine.derivatives_c import engine; "
            "t = time.perf_counter(); assert engine() is not None; "
            "print(time.perf_counter() - t)")
    with tempfile.TemporaryDirectory() as cache:
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             check=True, env={**os.environ, "LAGRANGIAN_CACHE": cache})
    return float(out.stdout.split()[-1])


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
    parser.add_argument("robot", nargs="?", default="panda",
                        choices=sorted(ROBOTS) + [SOLO, CHAIN, TREE])
    parser.add_argument("--states", type=int, default=None)
    parser.add_argument("--build", action="store_true",
                        help="time the derivatives module's build in an empty cache, alone")
    args = parser.parse_args()
    if args.build:
        print(json.dumps({"derivatives_module_build_s": build_time()}))
        return
    large = args.robot in (CHAIN, TREE)
    args.states = args.states or (64 if large else 10_000)
    floating = args.robot in (SOLO, TREE)
    lock = {}
    if large:
        import tempfile

        xml = chain_urdf() if args.robot == CHAIN else tree_urdf()
        path = os.path.join(tempfile.mkdtemp(), f"{args.robot}.urdf")
        with open(path, "w") as f:
            f.write(xml)
        model = (pin.buildModelFromXML(xml, pin.JointModelFreeFlyer()) if floating
                 else pin.buildModelFromXML(xml))
    else:
        relative, lock = (SOLO_PATH, {}) if floating else ROBOTS[args.robot]
        path = robots_folder() / relative
        model = (pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer()) if floating
                 else pin.buildModelFromUrdf(str(path)))
    ours = lagrangian.load(path, lock=lock, floating_base=floating).dynamics()
    if lock:
        model = pin.buildReducedModel(model, [model.getJointId(j) for j in lock],
                                      pin.neutral(model))
    data = model.createData()
    rng = np.random.default_rng(0)
    spread = 0.5 if large else 2.0  # a long chain's M is ill-conditioned far from straight
    q = rng.uniform(-spread, spread, (args.states, model.nq))
    v, a = rng.uniform(-spread, spread, (2, args.states, model.nv))
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
    if floating or large:
        del pairs["regressor"]
    from lagrangian.dynamics.engine.derivatives_c import derivatives_module

    ours.forward_dynamics_derivatives(q[0], v[0], a[0])  # the module loaded, not timed below
    began = time.perf_counter()
    derivatives_module(ours.tree)
    report = {"robot": args.robot, "nv": model.nv, "states": args.states,
              "cpus": os.cpu_count(), "tables_s": time.perf_counter() - began,
              "threads": os.environ.get("LAGRANGIAN_THREADS", "processors"),
              "load_average_before": os.getloadavg()}
    calls = min(200, args.states)
    for name, (mine, theirs) in pairs.items():
        mine(q[:8], v[:8], a[:8])  # compiled (and cached) before the clock starts
        ours_call, pin_call = (t / calls for t in interleaved(
            lambda m=mine: [m(q[k], v[k], a[k]) for k in range(calls)],
            lambda t=theirs: [t(q[k], v[k], a[k]) for k in range(calls)], 7))
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
        report[name] = {"ours_per_call_us": ours_call * 1e6,
                        "pinocchio_per_call_us": pin_call * 1e6,
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
    Y = None if floating or large else ours.regressor(q[:20], v[:20], a[:20])
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
