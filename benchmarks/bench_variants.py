"""Robot variants after one robot has run: the time from ``lagrangian.load`` to a first forward
dynamics, forward-dynamics derivatives and frame Jacobian, and how many compiled modules each
variant writes into the cache (issue "One engine for every robot").

    python benchmarks/bench_variants.py [--kernel auto|compact|unrolled]

One fresh process with an empty cache (LAGRANGIAN_CACHE in a temporary folder): the Panda
runs first (the engine's one-time builds, reported apart), then each variant in turn, timed
from its load (its tables included) to its last answer. ``--kernel auto`` (the same as
``compact``) is what a user gets: every function on the one engine; ``--kernel unrolled`` puts
M, ID and FD on each tree's own unrolled module (compiled per tree). Needs the bench extra
(pin, example-robot-data) for the URDFs.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np


def robots() -> Path:
    import pinocchio

    for parent in Path(pinocchio.__file__).resolve().parents:
        candidate = parent / "share/example-robot-data/robots"
        if candidate.is_dir():
            return candidate
    raise SystemExit("example-robot-data is not installed (pip install '.[bench]')")


def floating_tree(folder: Path, limbs: int = 4, links: int = 24) -> Path:
    """A 100-joint floating tree: a torso with ``limbs`` chains of ``links`` revolute links."""
    parts = ['<robot name="hydra"><link name="torso"><inertial><mass value="10"/>'
             '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>']
    for limb in range(limbs):
        parent = "torso"
        for k in range(links):
            name = f"l{limb}_{k}"
            axis = ("1 0 0", "0 1 0", "0 0 1")[k % 3]
            origin = f"{0.1 * np.cos(limb)} {0.1 * np.sin(limb)} 0" if k == 0 else "0 0 0.1"
            parts.append(f'<link name="{name}"><inertial><origin xyz="0 0 0.05"/>'
                         '<mass value="0.5"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" '
                         'iyz="0" izz="0.01"/></inertial></link>'
                         f'<joint name="j{name}" type="revolute"><parent link="{parent}"/>'
                         f'<child link="{name}"/><origin xyz="{origin}"/><axis xyz="{axis}"/>'
                         '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')
            parent = name
    parts.append("</robot>")
    path = folder / "hydra.urdf"
    path.write_text("".join(parts))
    return path


def first_answers(lagrangian, path, kernel: str, **options) -> tuple[float, int]:
    """Seconds from load to FD, FD derivatives and the last link's frame Jacobian; nv."""
    start = time.perf_counter()
    robot = lagrangian.load(path, **options)
    dynamics = robot.dynamics(kernel=kernel)
    rng = np.random.default_rng(0)
    q = rng.uniform(-0.5, 0.5, dynamics.nq)
    if dynamics.nq != dynamics.nv:
        q[3:7] = (0.0, 0.0, 0.0, 1.0)
    v, tau = rng.uniform(-0.5, 0.5, (2, dynamics.nv))
    dynamics.forward_dynamics(q, v, tau)
    dynamics.forward_dynamics_derivatives(q, v, tau)
    dynamics.jacobian(q, dynamics.frames[-1])
    return time.perf_counter() - start, dynamics.nv


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--kernel", default="auto", choices=("auto", "compact", "unrolled"))
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp())
    cache = folder / "cache"
    os.environ["LAGRANGIAN_CACHE"] = str(cache)
    import lagrangian

    root = robots()
    panda = root / "panda_description/urdf/panda.urdf"
    fingers = {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}

    def modules() -> int:
        return len(list(cache.glob("*.so")))

    seconds, _ = first_answers(lagrangian, panda, args.kernel, lock=fingers)
    print(f"Panda first (the engine's one-time builds included): {seconds:.2f} s, "
          f"{modules()} modules")
    variants = [
        ("Panda, a finger locked", panda, {"lock": {"panda_finger_joint1": 0.02}}),
        ("Panda, 1.5 kg payload", panda, {"lock": fingers,
                                          "payload": {"panda_hand": (1.5, (0, 0, 0.1))}}),
        ("Panda, floating base", panda, {"lock": fingers, "floating_base": True}),
        ("Panda, tilted gravity", panda, {"lock": fingers, "gravity": (1.0, 0.0, -9.76)}),
        ("UR5", root / "ur_description/urdf/ur5_robot.urdf", {}),
        ("Solo12, floating base", root / "solo_description/robots/solo12.urdf",
         {"floating_base": True}),
        ("100-joint floating tree", floating_tree(folder), {"floating_base": True}),
    ]
    print(f"{'variant':<26} {'nv':>4} {'load to answers':>16} {'new modules':>12}")
    for name, path, options in variants:
        before = modules()
        seconds, nv = first_answers(lagrangian, path, args.kernel, **options)
        print(f"{name:<26} {nv:>4} {seconds:>14.2f} s {modules() - before:>12}")


if __name__ == "__main__":
    main()
