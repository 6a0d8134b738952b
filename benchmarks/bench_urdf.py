"""URDF arms against Pinocchio: relative error and speed of M, bias, gravity, inverse and
forward dynamics and energies, per call and in batches of 10^4 states, and the time from a URDF
file to compiled functions (cold and from the cache).

    python benchmarks/bench_urdf.py [ur5|panda|xarm7 ...] [--states 100] [--symbolic numpy|c]
    python benchmarks/bench_urdf.py --reach [ur5|panda|xarm7 ...]

``--reach`` times issue 23's functions instead, on the last moving link's frame: its placement
against forwardKinematics + updateFramePlacement, its Jacobian (LOCAL_WORLD_ALIGNED) against
computeFrameJacobian, the centre of mass and its Jacobian against centerOfMass and
jacobianCenterOfMass, C(q, v) against computeCoriolisMatrix, J_dot q_dot against
forwardKinematics(q, v, 0) + getFrameClassicalAcceleration (LOCAL_WORLD_ALIGNED), the
centroidal momentum matrix against ccrba, and inverse and forward dynamics with a wrench at that
frame against rnea and aba with f_ext (Pinocchio given its per-joint f_ext ready made; ours
taking the frame's wrench), per call and for 10^4 states (Pinocchio in a Python loop). First
the one compiled module of those functions (reach_c.engine: one per installation, every robot's
tables given at run time) built in a fresh process with an empty cache, then loaded from the
cache it filled, and a robot's tables read into it.

Needs the bench extra (pin, example-robot-data). The Panda's finger joints are locked at 0.
Default: ``arm.dynamics()``, the recursive algorithms in generated C (dynamics/recursive.py);
``--symbolic`` times the derived equations instead (numpy or C backend).

- Build: ``lagrangian.load(urdf, lock=...)`` then ``.dynamics()`` and a first call, in a fresh
  process (interpreter start and ``from lagrangian import load; import yourdfpy`` reported
  apart), first with an
  empty cache (cold: C generated and compiled), then again with the cache it filled (warm).
- Per call: one state through the Python API and through Pinocchio's Python bindings (crba,
  rnea, aba), interleaved in one process, best of 7 runs of 2000 calls.
- Batch: one call on 10^4 states (ours) against a Python loop of 10^4 Pinocchio calls (best
  of 7 each, alternating).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
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

BUILD = """
import json, sys, time
t0 = time.perf_counter()
import yourdfpy
from lagrangian import load  # the API layer (sympy, scipy): the library's fixed start-up
t1 = time.perf_counter()
arm = load(sys.argv[1], lock=json.loads(sys.argv[2]))
f = arm.dynamics()
n = f.n
f.forward_dynamics([0.1] * n, [0.0] * n, [0.0] * n)
t2 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "build": t2 - t1, "kind": type(f).__name__}))
"""


ENGINE = """
import json, sys, time
from lagrangian import load
arm = load(sys.argv[1], lock=json.loads(sys.argv[2])).dynamics(backend="numpy")
from lagrangian.dynamics.engine.reach_c import ReachKernel, engine
t0 = time.perf_counter()
module = engine()
t1 = time.perf_counter()
ReachKernel(module, arm.tree, True)
t2 = time.perf_counter()
print(json.dumps({"engine": t1 - t0, "tables": t2 - t1}))
"""


def robots_folder() -> Path:
    import pinocchio

    for parent in Path(pinocchio.__file__).resolve().parents:
        candidate = parent / "share/example-robot-data/robots"
        if candidate.is_dir():
            return candidate
    sys.exit("example-robot-data not found (pip install example-robot-data)")


def load_average() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def best(function, repeat=7, number=2000, clock=time.perf_counter) -> float:
    times = []
    for _ in range(repeat):
        start = clock()
        for _ in range(number):
            function()
        times.append((clock() - start) / number)
    return min(times)


def side_by_side(mine, theirs, repeat=7, number=2000,
                 clock=time.perf_counter) -> tuple[float, float]:
    """Best per-call times, the two measured in alternation (the same load for both)."""
    ours, pins = [], []
    for _ in range(repeat):
        ours.append(best(mine, 1, number, clock))
        pins.append(best(theirs, 1, number, clock))
    return min(ours), min(pins)


def relative(ours, theirs) -> float:
    ours, theirs = np.asarray(ours), np.asarray(theirs)
    return float(np.max(np.abs(ours - theirs)) / max(np.max(np.abs(theirs)), 1e-300))


def build_times(path: Path, lock: dict) -> tuple[dict, dict]:
    """A fresh process with an empty cache (cold), then another with the cache it filled."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, LAGRANGIAN_CACHE=cache)
        runs = []
        for _ in range(2):
            done = subprocess.run([sys.executable, "-c", BUILD, str(path), json.dumps(lock)],
                                  env=env, capture_output=True, text=True, check=True)
            runs.append(json.loads(done.stdout.strip().splitlines()[-1]))
    return runs[0], runs[1]


def engine_build(name: str) -> None:
    """The reach functions' one module: its build with an empty cache, its load from the
    cache, and ``name``'s tables read into it, each in a fresh process."""
    relpath, lock = ROBOTS[name]
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, LAGRANGIAN_CACHE=cache)
        runs = [json.loads(subprocess.run(
            [sys.executable, "-c", ENGINE, str(robots_folder() / relpath), json.dumps(lock)],
            env=env, capture_output=True, text=True, check=True).stdout.strip().splitlines()[-1])
            for _ in range(2)]
    print(f"reach engine (one module for every robot): built in {runs[0]['engine']:.2f} s "
          f"(empty cache), loaded in {runs[1]['engine'] * 1e3:.1f} ms (from the cache); "
          f"{name}'s tables read in {runs[1]['tables'] * 1e3:.2f} ms")


def bench(name: str, symbolic: str | None, states: int, timing: bool = True) -> None:
    import pinocchio as pin

    relpath, lock = ROBOTS[name]
    path = robots_folder() / relpath
    arm = lagrangian.load(path, lock=lock)
    if symbolic:
        from lagrangian.dynamics.joint_space import Dynamics

        start = time.perf_counter()
        f = Dynamics(arm.numeric(backend=symbolic))
        print(f"\n{name}: derived equations, {symbolic} backend, derive + build "
              f"{time.perf_counter() - start:.1f} s")
    else:
        f = arm.dynamics()
        cold, warm = build_times(path, lock)
        print(f"\n{name}: {cold['kind']}; URDF -> compiled functions: cold {cold['build']:.2f} s, "
              f"from the cache {warm['build']:.2f} s (fresh processes; importing lagrangian.load "
              f"and yourdfpy {warm['import']:.2f} s apart); load average {load_average()}")
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
    print(f"  n = {n}; max relative error vs Pinocchio over {states} states: "
          + ", ".join(f"{k} {e:.1e}" for k, e in errors.items()))
    if not timing:
        return
    q0, v0, a0, t0 = q[0].copy(), v[0].copy(), a[0].copy(), tau[0].copy()
    rows = [("mass matrix / crba", lambda: f.mass_matrix(q0), lambda: pin.crba(model, data, q0)),
            ("inverse dyn / rnea", lambda: f.inverse_dynamics(q0, v0, a0),
             lambda: pin.rnea(model, data, q0, v0, a0)),
            ("forward dyn / aba", lambda: f.forward_dynamics(q0, v0, t0),
             lambda: pin.aba(model, data, q0, v0, t0))]
    print(f"  per call (us): ours, Pinocchio, ratio pin/ours; load average {load_average()}")
    number = 2000 if not symbolic else 20
    for label, mine, theirs in rows:
        t_ours, t_pin = side_by_side(mine, theirs, number=number)
        print(f"    {label:<20} {t_ours * 1e6:9.2f} {t_pin * 1e6:9.2f} {t_pin / t_ours:7.2f}")
    big = 10_000
    Q = rng.uniform(-1, 1, (big, n))
    V, A, TAU = (rng.uniform(-1, 1, (big, n)) for _ in range(3))
    print(f"  batch of {big} (ms): ours one call, Pinocchio Python loop, ratio; the same by "
          f"CPU time (this process's, threads summed); load average {load_average()}")
    for label, mine, theirs in [
            ("mass matrix", lambda: f.mass_matrix(Q),
             lambda: [pin.crba(model, data, x) for x in Q]),
            ("inverse dyn", lambda: f.inverse_dynamics(Q, V, A),
             lambda: [pin.rnea(model, data, x, y, z) for x, y, z in zip(Q, V, A, strict=True)]),
            ("forward dyn", lambda: f.forward_dynamics(Q, V, TAU),
             lambda: [pin.aba(model, data, x, y, z) for x, y, z in zip(Q, V, TAU, strict=True)])]:
        t_ours, t_pin = side_by_side(mine, theirs, 7, 1)
        print(f"    {label:<20} {t_ours * 1e3:9.2f} {t_pin * 1e3:9.2f} {t_pin / t_ours:7.1f}")


def _frame_id(model, name):
    import pinocchio as pin

    for kind in (pin.FrameType.BODY, pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT):
        if model.existFrame(name, kind):
            return model.getFrameId(name, kind)
    raise KeyError(name)


def bench_reach(name: str, states: int, timing: bool = True) -> None:
    """Issue 23: J_dot q_dot, A_g, wrenches in ID and FD, against Pinocchio."""
    import pinocchio as pin

    relpath, lock = ROBOTS[name]
    path = robots_folder() / relpath
    f = lagrangian.load(path, lock=lock).dynamics()
    model = pin.buildModelFromUrdf(str(path))
    if lock:
        model = pin.buildReducedModel(model, [model.getJointId(j) for j in lock],
                                      pin.neutral(model))
    data = model.createData()
    n = f.n
    # the last link that moves (a link frame Pinocchio has too): the tool, not a fixed base
    moving = {x.name for x in f.tree.frames if x.body >= 0}
    frame = next(x for x in reversed(f.frames)
                 if x in moving and model.existFrame(x, pin.FrameType.BODY))
    fid = _frame_id(model, frame)
    joint = model.frames[fid].parentJoint
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    rng = np.random.default_rng(0)
    q, v, a, tau = (rng.uniform(-1, 1, (states, n)) for _ in range(4))
    w = rng.uniform(-5, 5, 6)

    def f_ext(qk):
        pin.forwardKinematics(model, data, qk)
        pin.updateFramePlacements(model, data)
        R, o = data.oMi[joint].rotation, data.oMi[joint].translation
        p = data.oMf[fid].translation
        forces = [pin.Force.Zero() for _ in range(model.njoints)]
        forces[joint] = pin.Force(R.T @ w[:3], R.T @ (w[3:] + np.cross(p - o, w[:3])))
        return forces

    def drift(qk, vk):
        pin.forwardKinematics(model, data, qk, vk, np.zeros(n))
        return pin.getFrameClassicalAcceleration(model, data, fid, lwa).vector

    def placement(qk):
        pin.forwardKinematics(model, data, qk)
        return pin.updateFramePlacement(model, data, fid).homogeneous

    wrench = {frame: w}
    ours = {"placement": f.placement(q, frame), "jacobian": f.jacobian(q, frame),
            "CoM": f.center_of_mass(q), "CoM J": f.center_of_mass_jacobian(q),
            "C": f.coriolis_matrix(q, v),
            "Jdot v": f.jacobian_dot_times_v(q, v, frame), "A_g": f.centroidal_momentum_matrix(q),
            "ID f_ext": f.inverse_dynamics(q, v, a, f_ext=wrench),
            "FD f_ext": f.forward_dynamics(q, v, tau, f_ext=wrench)}
    errors = dict.fromkeys(ours, 0.0)
    for k in range(states):
        forces = f_ext(q[k])
        theirs = {"placement": placement(q[k]),
                  "jacobian": pin.computeFrameJacobian(model, data, q[k], fid, lwa),
                  "CoM": pin.centerOfMass(model, data, q[k]).copy(),
                  "CoM J": pin.jacobianCenterOfMass(model, data, q[k]).copy(),
                  "C": pin.computeCoriolisMatrix(model, data, q[k], v[k]).copy(),
                  "Jdot v": drift(q[k], v[k]), "A_g": pin.ccrba(model, data, q[k], v[k]).copy(),
                  "ID f_ext": pin.rnea(model, data, q[k], v[k], a[k], forces),
                  "FD f_ext": pin.aba(model, data, q[k], v[k], tau[k], forces)}
        for key in errors:
            errors[key] = max(errors[key], relative(ours[key][k], theirs[key]))
    print(f"\n{name} (n = {n}), frame {frame}: max relative error vs Pinocchio over {states} "
          "states: " + ", ".join(f"{k} {e:.1e}" for k, e in errors.items()))
    if not timing:
        return
    q0, v0, a0, t0 = q[0].copy(), v[0].copy(), a[0].copy(), tau[0].copy()
    forces0 = f_ext(q0)
    rows = [("placement", lambda: f.placement(q0, frame), lambda: placement(q0)),
            ("jacobian / computeFrameJ", lambda: f.jacobian(q0, frame),
             lambda: pin.computeFrameJacobian(model, data, q0, fid, lwa)),
            ("CoM / centerOfMass", lambda: f.center_of_mass(q0),
             lambda: pin.centerOfMass(model, data, q0)),
            ("CoM J / jacobianCoM", lambda: f.center_of_mass_jacobian(q0),
             lambda: pin.jacobianCenterOfMass(model, data, q0)),
            ("C / computeCoriolisM", lambda: f.coriolis_matrix(q0, v0),
             lambda: pin.computeCoriolisMatrix(model, data, q0, v0)),
            ("Jdot v / classical acc", lambda: f.jacobian_dot_times_v(q0, v0, frame),
             lambda: drift(q0, v0)),
            ("A_g / ccrba", lambda: f.centroidal_momentum_matrix(q0),
             lambda: pin.ccrba(model, data, q0, v0)),
            ("ID f_ext / rnea f_ext", lambda: f.inverse_dynamics(q0, v0, a0, f_ext=wrench),
             lambda: pin.rnea(model, data, q0, v0, a0, forces0)),
            ("FD f_ext / aba f_ext", lambda: f.forward_dynamics(q0, v0, t0, f_ext=wrench),
             lambda: pin.aba(model, data, q0, v0, t0, forces0))]
    print(f"  per call (us): ours, Pinocchio, ratio pin/ours; load average {load_average()}")
    for label, mine, theirs in rows:
        t_ours, t_pin = side_by_side(mine, theirs, number=500)
        print(f"    {label:<24} {t_ours * 1e6:9.2f} {t_pin * 1e6:9.2f} {t_pin / t_ours:7.2f}")
    big = 10_000
    Q, V, A = (rng.uniform(-1, 1, (big, n)) for _ in range(3))
    print(f"  batch of {big} (ms): ours one call, Pinocchio Python loop, ratio; the same by "
          f"CPU time (this process's, threads summed); load average {load_average()}")
    for label, mine, theirs in [
            ("placement", lambda: f.placement(Q, frame), lambda: [placement(x) for x in Q]),
            ("jacobian", lambda: f.jacobian(Q, frame),
             lambda: [pin.computeFrameJacobian(model, data, x, fid, lwa) for x in Q]),
            ("CoM", lambda: f.center_of_mass(Q),
             lambda: [pin.centerOfMass(model, data, x) for x in Q]),
            ("CoM J", lambda: f.center_of_mass_jacobian(Q),
             lambda: [pin.jacobianCenterOfMass(model, data, x) for x in Q]),
            ("C", lambda: f.coriolis_matrix(Q, V),
             lambda: [pin.computeCoriolisMatrix(model, data, x, y) for x, y in zip(Q, V, strict=True)]),
            ("Jdot v", lambda: f.jacobian_dot_times_v(Q, V, frame),
             lambda: [drift(x, y) for x, y in zip(Q, V, strict=True)]),
            ("A_g", lambda: f.centroidal_momentum_matrix(Q),
             lambda: [pin.ccrba(model, data, x, y) for x, y in zip(Q, V, strict=True)]),
            ("ID f_ext", lambda: f.inverse_dynamics(Q, V, A, f_ext=wrench),
             lambda: [pin.rnea(model, data, x, y, z, forces0)
                      for x, y, z in zip(Q, V, A, strict=True)]),
            ("FD f_ext", lambda: f.forward_dynamics(Q, V, A, f_ext=wrench),
             lambda: [pin.aba(model, data, x, y, z, forces0)
                      for x, y, z in zip(Q, V, A, strict=True)])]:
        t_ours, t_pin = side_by_side(mine, theirs, 3, 1)
        c_ours, c_pin = side_by_side(mine, theirs, 3, 1, time.process_time)
        print(f"    {label:<24} {t_ours * 1e3:9.2f} {t_pin * 1e3:9.2f} {t_pin / t_ours:7.1f}"
              f"   CPU {c_ours * 1e3:7.2f} {c_pin * 1e3:8.2f} {c_pin / c_ours:6.1f}")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("robots", nargs="*", default=["ur5", "panda", "xarm7"])
    parser.add_argument("--symbolic", choices=("c", "numpy"),
                        help="time the derived equations with this backend instead")
    parser.add_argument("--states", type=int, default=100)
    parser.add_argument("--accuracy-only", action="store_true", help="skip the timings")
    parser.add_argument("--reach", action="store_true",
                        help="time J_dot q_dot, A_g and wrenches (issue 23) instead")
    args = parser.parse_args()
    if args.reach and args.robots:
        engine_build(args.robots[0])
    for name in args.robots:
        if args.reach:
            bench_reach(name, args.states, not args.accuracy_only)
        else:
            bench(name, args.symbolic, args.states, not args.accuracy_only)


if __name__ == "__main__":
    main()
