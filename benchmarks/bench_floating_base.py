"""Floating-base robots (a free flyer under the root link) beside Pinocchio's
buildModelFromUrdf(path, JointModelFreeFlyer()): Solo12 (nv 18), ANYmal (nv 18) and Talos
reduced (nv 38), generated C and numpy, per call of one state and per state of a batch of 1000;
then forward dynamics side by side with Pinocchio's aba, interleaved: one call from Python, and a
batch of 10^4 states (one call of ours against a Python loop of aba over the same states); then
M, bias and inverse dynamics the same way against crba, nonLinearEffects and rnea.

    python benchmarks/bench_floating_base.py [--robots solo12,anymal,talos_reduced]

Needs the bench extra (pin, example-robot-data). Each figure of the table is the best of 5 rounds
of 0.2 s of calls (the functions measured in turn in one process); the side-by-side figures are
the best of 7 rounds, ours and Pinocchio's taking turns within each round. The load average is
printed before and after.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

import lagrangian

sys.path.insert(0, str(Path(__file__).parent))
from bench_urdf import load_average, robots_folder  # noqa: E402 (the sibling benchmark's)

ROBOTS = {"solo12": "solo_description/robots/solo12.urdf",
          "anymal": "anymal_b_simple_description/robots/anymal.urdf",
          "talos_reduced": "talos_data/robots/talos_reduced.urdf"}
BATCH = 10_000  # states of the side-by-side batch


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


def side_by_side(functions: dict, states: int, rounds: int = 7, seconds: float = 0.2) -> dict:
    """Best microseconds per state of each function (called with no arguments, ``states``
    states a call), the functions taking turns within each of ``rounds`` rounds."""
    best = dict.fromkeys(functions, float("inf"))
    for function in functions.values():
        function()
    for _ in range(rounds):
        for name, function in functions.items():
            start, calls = time.perf_counter(), 0
            while time.perf_counter() - start < seconds:
                function()
                calls += 1
            best[name] = min(best[name], (time.perf_counter() - start) / calls / states * 1e6)
    return best


def forward_side_by_side(robot, model, ours_states, pinocchio_states) -> None:
    """Ours (the Python method, and the module's function alone) against pin.aba on the same
    states (q, v, tau) in each one's layout: one state per call, then BATCH states (one call
    against a Python loop of aba)."""
    import pinocchio as pin

    data = model.createData()
    # the module's function and its last argument, the backend's tables: the parameters'
    # values (unrolled module), or the tree's prepared description (the engine, Talos's)
    module = robot.module
    P = robot.recursions.tables
    q, v, tau = ours_states
    q0, v0, t0 = q[0], v[0], tau[0]
    qp, vp, tp = pinocchio_states

    def loop(function, *inputs):
        """a Python loop of a Pinocchio function over the BATCH states"""
        def run():
            for k in range(BATCH):
                function(model, data, *(x[k] for x in inputs))
        return run

    one = side_by_side({"ours": lambda: robot.forward_dynamics(q0, v0, t0),
                        "module": lambda: module.forward_dynamics(q0, v0, t0, P),
                        "aba": lambda: pin.aba(model, data, qp[0], vp[0], tp[0])}, 1)
    many = side_by_side({"ours": lambda: robot.forward_dynamics(q, v, tau),
                         "aba loop": loop(pin.aba, qp, vp, tp)}, BATCH, rounds=5)
    # the other functions' batches the same way (Pinocchio's crba fills M's upper triangle only)
    others = side_by_side({"M": lambda: robot.mass_matrix(q), "crba": loop(pin.crba, qp),
                           "bias": lambda: robot.bias_forces(q, v),
                           "nonLinearEffects": loop(pin.nonLinearEffects, qp, vp),
                           "ID": lambda: robot.inverse_dynamics(q, v, tau),
                           "rnea": loop(pin.rnea, qp, vp, tp)}, BATCH, rounds=5)
    print(f"  forward dynamics, one call: ours {one['ours']:.3g} (the module's function alone "
          f"{one['module']:.3g}), aba {one['aba']:.3g}: {one['aba'] / one['ours']:.2f}x")
    print(f"  forward dynamics, {BATCH} states: ours {many['ours']:.3g} per state, a Python "
          f"loop of aba {many['aba loop']:.3g}: {many['aba loop'] / many['ours']:.1f}x")
    print(f"  {BATCH} states, ours / a Python loop of Pinocchio's per state: " + ", ".join(
        f"{ours} {others[ours]:.3g} / {theirs} {others[theirs]:.3g} "
        f"({others[theirs] / others[ours]:.1f}x)"
        for ours, theirs in (("M", "crba"), ("bias", "nonLinearEffects"), ("ID", "rnea"))))


def main() -> None:
    import argparse

    import pinocchio as pin

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", default=",".join(ROBOTS),
                        help=f"comma-separated, of {', '.join(ROBOTS)}")
    names = parser.parse_args().robots.split(",")
    print(f"load average {load_average()}")
    for key in names:
        name = ROBOTS[key]
        path = robots_folder() / name
        model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
        data = model.createData()
        rng = np.random.default_rng(0)
        q = np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
                      for _ in range(BATCH)])
        v = rng.uniform(-1, 1, (BATCH, model.nv))
        tau = rng.uniform(-1, 1, (BATCH, model.nv))
        pinocchio_states = q, v, tau
        # our joints in the URDF's order, Pinocchio's siblings by name: the same states
        order = [j.name for j in lagrangian.load(path, floating_base=True).dynamics(
            backend="numpy").tree.joints[1:]]
        iq = np.r_[np.arange(7), [model.idx_qs[model.getJointId(j)] for j in order]]
        iv = np.r_[np.arange(6), [model.idx_vs[model.getJointId(j)] for j in order]]
        # C-ordered, as a user's arrays are (a column selection is Fortran-ordered: converted
        # on every call)
        q, v, tau = (np.ascontiguousarray(x) for x in (q[:, iq], v[:, iv], tau[:, iv]))
        print(f"{path.name}: nq {model.nq}, nv {model.nv}; microseconds per state")
        for backend in ("c", "numpy"):
            robot = lagrangian.load(path, floating_base=True).dynamics(backend=backend)
            for states in (1, 1000):
                Q, V = (q[0], v[0]) if states == 1 else (q[:states], v[:states])
                figures = [per_state(robot.mass_matrix, (Q,), states),
                           per_state(robot.bias_forces, (Q, V), states),
                           per_state(robot.forward_dynamics, (Q, V, V), states)]
                print(f"  {backend:5} {states:4} state(s): M {figures[0]:.3g}, "
                      f"bias {figures[1]:.3g}, forward {figures[2]:.3g}")
        q0, v0 = pin.randomConfiguration(model), np.zeros(model.nv)
        print(f"  pinocchio one call: crba {per_state(pin.crba, (model, data, q0), 1):.3g}, "
              f"rnea {per_state(pin.rnea, (model, data, q0, v0, v0), 1):.3g}, "
              f"aba {per_state(pin.aba, (model, data, q0, v0, v0), 1):.3g}")
        robot = lagrangian.load(path, floating_base=True).dynamics(backend="c")
        forward_side_by_side(robot, model, (q, v, tau), pinocchio_states)
    print(f"load average {load_average()}")


if __name__ == "__main__":
    main()
