"""Floating-base robots (a free flyer under the root link) beside Pinocchio's
buildModelFromUrdf(path, JointModelFreeFlyer()): Solo12 (nv 18) and Talos reduced (nv 38),
generated C and numpy, per call of one state and per state of a batch of 1000.

    python benchmarks/bench_floating_base.py

Needs the bench extra (pin, example-robot-data). Each figure is the best of 5 rounds of 0.2 s of
calls (the functions measured in turn in one process); the load average is printed with them.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

import lagrangian

sys.path.insert(0, str(Path(__file__).parent))
from bench_urdf import load_average, robots_folder  # noqa: E402 (the sibling benchmark's)

ROBOTS = ("solo_description/robots/solo12.urdf", "talos_data/robots/talos_reduced.urdf")


def per_state(function, args, states: int) -> float:
    """Best microseconds per state of function(*args) over 5 rounds of 0.2 s."""
    function(*args)
    best = float("inf")
    for _ in range(5):
        start, calls = time.perf_counter(), 0
        while time.perf_counter() - start < 0.2:
            function(*args)
            calls += 1
        best = min(best, (time.perf_counter() - start) / calls / states * 1e6)
    return best


def main() -> None:
    import pinocchio as pin

    print(f"load average {load_average()}")
    for name in ROBOTS:
        path = robots_folder() / name
        model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
        data = model.createData()
        rng = np.random.default_rng(0)
        q = np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
                      for _ in range(1000)])
        v = rng.uniform(-1, 1, (1000, model.nv))
        # our joints in the URDF's order, Pinocchio's siblings by name: the same states
        order = [j.name for j in lagrangian.load(path, floating_base=True).dynamics(
            backend="numpy").tree.joints[1:]]
        iq = np.r_[np.arange(7), [model.idx_qs[model.getJointId(j)] for j in order]]
        iv = np.r_[np.arange(6), [model.idx_vs[model.getJointId(j)] for j in order]]
        q, v = q[:, iq], v[:, iv]
        print(f"{path.name}: nq {model.nq}, nv {model.nv}; microseconds per state")
        for backend in ("c", "numpy"):
            robot = lagrangian.load(path, floating_base=True).dynamics(backend=backend)
            for states in (1, 1000):
                Q, V = (q[0], v[0]) if states == 1 else (q, v)
                figures = [per_state(robot.mass_matrix, (Q,), states),
                           per_state(robot.bias_forces, (Q, V), states),
                           per_state(robot.forward_dynamics, (Q, V, V), states)]
                print(f"  {backend:5} {states:4} state(s): M {figures[0]:.3g}, "
                      f"bias {figures[1]:.3g}, forward {figures[2]:.3g}")
        q0, v0 = pin.randomConfiguration(model), np.zeros(model.nv)
        print(f"  pinocchio one call: crba {per_state(pin.crba, (model, data, q0), 1):.3g}, "
              f"rnea {per_state(pin.rnea, (model, data, q0, v0, v0), 1):.3g}, "
              f"aba {per_state(pin.aba, (model, data, q0, v0, v0), 1):.3g}")


if __name__ == "__main__":
    main()
