"""A floating base's frame placement and Jacobian, centre of mass and its Jacobian, C(q, v),
J_dot v, centroidal momentum matrix and inverse dynamics with a wrench at a foot, ours (the
compiled reach kernel) beside Pinocchio's free flyer (forwardKinematics with
updateFramePlacement, computeFrameJacobian, centerOfMass, jacobianCenterOfMass,
computeCoriolisMatrix, getFrameClassicalAcceleration, ccrba, rnea with f_ext), per Python call
of one state and for a batch of 10^4 states against a Python loop of Pinocchio calls.

    python benchmarks/bench_floating_reach.py [--robots solo12,anymal,talos_reduced]

Needs the bench extra (pin, example-robot-data). Each per-call figure (one state, its arrays
bound beforehand on both sides) is the best of 7 rounds of 300 calls, ours and Pinocchio's
rounds alternating in one process; each batch figure the best of 5, alternating too (one call of
ours on 10^4 states, on as many threads as processors or LAGRANGIAN_THREADS allow; a loop of
10^4 Pinocchio calls), then the same by CPU time (time.process_time: this process's, both
threads summed), which the machine's other work disturbs less; then the fresh-output floor
(bench_control.fresh_output_floor: allocating and writing once as many doubles as the batch
returns) and the bound it puts on a batch returning freshly allocated arrays (ours reuse a kept
block from their second call: batch_threads.c). The load
average is printed before and after, and the threads a batch may take.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

import lagrangian

sys.path.insert(0, str(Path(__file__).parent))
from bench_control import fresh_output_floor  # noqa: E402 (the sibling benchmarks')
from bench_urdf import load_average, robots_folder  # noqa: E402

ROBOTS = {"solo12": ("solo_description/robots/solo12.urdf", "FL_FOOT"),
          "anymal": ("anymal_b_simple_description/robots/anymal.urdf", "LF_FOOT"),
          "talos_reduced": ("talos_data/robots/talos_reduced.urdf", "left_sole_link")}
DEFAULT = "solo12,talos_reduced"


def best(function, calls: int, rounds: int, clock=time.perf_counter) -> float:
    """Best seconds per call of function() over ``rounds`` rounds of ``calls`` calls."""
    out = float("inf")
    for _ in range(rounds):
        start = clock()
        for _ in range(calls):
            function()
        out = min(out, (clock() - start) / calls)
    return out


def interleaved(ours, theirs, calls: int = 300, rounds: int = 7,
                clock=time.perf_counter) -> tuple[float, float]:
    """Best seconds per call of each, their rounds alternating."""
    ours(), theirs()
    a = b = float("inf")
    for _ in range(rounds):
        a = min(a, best(ours, calls, 1, clock))
        b = min(b, best(theirs, calls, 1, clock))
    return a, b


def measure(ours, theirs, Q, V, A, states, count: int) -> tuple[float, ...]:
    """Seconds: one call of ours and of Pinocchio's (interleaved; each its first state's arrays
    bound beforehand), 10^4 states in one call of ours and in a loop of Pinocchio's (``states``:
    its q, v, a in its own order), by the wall clock and by CPU time."""
    q, v, a = states
    state, first = (Q[0], V[0], A[0]), (q[0], v[0], a[0])
    one_ours, one_theirs = interleaved(lambda: ours(*state), lambda: theirs(*first))
    batch = (lambda: ours(Q, V, A), lambda: [theirs(q[k], v[k], a[k]) for k in range(count)])
    wall = interleaved(*batch, 1, 5)
    cpu = interleaved(*batch, 1, 5, time.process_time)
    return one_ours, one_theirs, *wall, *cpu, fresh_output_floor(ours(Q, V, A))


def bench_robot(name: str, foot: str, count: int = 10_000) -> None:
    import pinocchio as pin

    path = robots_folder() / name
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = model.createData()
    robot = lagrangian.load(path, floating_base=True).dynamics(backend="c")
    order = [j.name for j in robot.tree.joints[1:]]  # ours in the URDF's order
    iq = np.r_[np.arange(7), [model.idx_qs[model.getJointId(j)] for j in order]]
    iv = np.r_[np.arange(6), [model.idx_vs[model.getJointId(j)] for j in order]]
    rng = np.random.default_rng(0)
    q = np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
                  for _ in range(count)])
    v, a = rng.uniform(-1, 1, (2, count, model.nv))
    Q, V, A = (np.ascontiguousarray(x) for x in (q[:, iq], v[:, iv], a[:, iv]))
    frame = model.getFrameId(foot)
    joint = model.frames[frame].parentJoint
    wrench = np.array([0.0, 0.0, 50.0, 0.0, 0.0, 0.0])  # 50 N up at the foot, world axes
    f_ext = {foot: wrench}
    # the same wrench as Pinocchio's f_ext (the joint's axes, about its origin), at state 0
    pin.framesForwardKinematics(model, data, q[0])
    forces = pin.StdVec_Force()
    for _ in range(model.njoints):
        forces.append(pin.Force.Zero())
    placement = data.oMi[joint]
    arm = data.oMf[frame].translation - placement.translation
    forces[joint] = pin.Force(placement.rotation.T @ wrench[:3],
                              placement.rotation.T @ np.cross(arm, wrench[:3]))

    def drift(qk, vk, ak):
        pin.forwardKinematics(model, data, qk, vk, 0 * vk)
        pin.updateFramePlacement(model, data, frame)
        return pin.getFrameClassicalAcceleration(model, data, frame,
                                                 pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)

    world = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED

    def placement(qk, vk, ak):
        pin.forwardKinematics(model, data, qk)
        return pin.updateFramePlacement(model, data, frame)

    cases = {
        "placement": (lambda x, y, z: robot.placement(x, foot), placement),
        "jacobian": (lambda x, y, z: robot.jacobian(x, foot, "local_world_aligned"),
                     lambda x, y, z: pin.computeFrameJacobian(model, data, x, frame, world)),
        "center_of_mass": (lambda x, y, z: robot.center_of_mass(x),
                           lambda x, y, z: pin.centerOfMass(model, data, x)),
        "center_of_mass_jacobian": (lambda x, y, z: robot.center_of_mass_jacobian(x),
                                    lambda x, y, z: pin.jacobianCenterOfMass(model, data, x)),
        "coriolis_matrix": (lambda x, y, z: robot.coriolis_matrix(x, y),
                            lambda x, y, z: pin.computeCoriolisMatrix(model, data, x, y)),
        "jacobian_dot_times_v": (lambda x, y, z: robot.jacobian_dot_times_v(x, y, foot), drift),
        "centroidal_momentum_matrix": (lambda x, y, z: robot.centroidal_momentum_matrix(x),
                                       lambda x, y, z: pin.ccrba(model, data, x, y)),
        "inverse_dynamics f_ext": (lambda x, y, z: robot.inverse_dynamics(x, y, z, f_ext=f_ext),
                                   lambda x, y, z: pin.rnea(model, data, x, y, z, forces)),
    }
    print(f"{path.name}: nq {model.nq}, nv {model.nv}")
    print("  function: one call ours / Pinocchio us (ratio Pinocchio/ours); "
          "10^4 states ours / Pinocchio loop ms (ratio); the same by CPU time")
    for label, (ours, theirs) in cases.items():
        one_ours, one_theirs, batch_ours, batch_theirs, cpu_ours, cpu_theirs, floor = measure(
            ours, theirs, Q, V, A, (q, v, a), count)
        print(f"  {label}: {one_ours * 1e6:.2f} / {one_theirs * 1e6:.2f} "
              f"({one_theirs / one_ours:.2f}x); {batch_ours * 1e3:.1f} / "
              f"{batch_theirs * 1e3:.1f} ({batch_theirs / batch_ours:.1f}x); CPU "
              f"{cpu_ours * 1e3:.1f} / {cpu_theirs * 1e3:.1f} ({cpu_theirs / cpu_ours:.1f}x); "
              f"fresh output {floor * 1e3:.1f} ms (bound {batch_theirs / floor:.0f}x)")


def main() -> None:
    import argparse

    parser = argparse.ArgumentParser()
    parser.add_argument("--robots", default=DEFAULT,
                        help=f"comma-separated, of {', '.join(ROBOTS)} (default {DEFAULT})")
    names = parser.parse_args().robots.split(",")
    unknown = [name for name in names if name not in ROBOTS]
    if unknown:
        parser.error(f"unknown robot {unknown[0]!r}; use {', '.join(ROBOTS)}")
    threads = max(1, min(os.cpu_count() or 1, int(os.environ.get("LAGRANGIAN_THREADS") or 8), 8))
    print(f"load average {load_average()}; a batch on up to {threads} threads "
          f"({os.cpu_count()} processors)")
    for name in names:
        bench_robot(*ROBOTS[name])
    print(f"load average {load_average()}")


if __name__ == "__main__":
    main()
