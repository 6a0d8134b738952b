"""Derivation of a spatial chain of n rigid bodies on revolute joints with alternating axes
(x, y, x, ...), ours against sympy.physics.mechanics KanesMethod (System / PinJoint API).

    python benchmarks/bench_spatial_chain.py [--sizes 1,2,3,4,5,6] [--limit 120]

Each timing is a fresh child process (best of one; the runs are long); before timing, the two
mass matrices and forcings are checked to agree at a random state for n = 2.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time

INERTIA = (0.1, 0.1, 0.02)


def ours(n: int):
    import lagrangian
    from lagrangian.model.builder import ModelBuilder

    b = ModelBuilder(f"{n}-body spatial chain")
    b.parameter("g", 9.81)
    b.set_gravity("g", (0, 0, -1))
    parent = None
    for i in range(n):
        b.coordinate(f"q{i}", "rad")
        b.parameter(f"m{i}", 1.0)
        joint = {"type": "revolute", "axis": "xy"[i % 2], "angle": f"q{i}"}
        if parent:
            joint["at"] = [0, 0, -1]
        b.add_rigid_body(f"link{i}", f"m{i}", list(INERTIA), parent=parent, joint=joint,
                         center=[0, 0, -0.5])
        parent = f"link{i}"
    eom = lagrangian.System(b.build_model()).equations_of_motion()
    return eom.mass_matrix, eom.forcing


def kane(n: int):
    import warnings

    import sympy as sp
    from sympy.physics.mechanics import (
        Inertia,
        PinJoint,
        ReferenceFrame,
        RigidBody,
        System,
        dynamicsymbols,
    )
    from sympy.utilities.exceptions import SymPyDeprecationWarning

    warnings.simplefilter("ignore", SymPyDeprecationWarning)  # parent_axis/child_axis
    g = sp.Symbol("g")
    ground = RigidBody("ground", frame=ReferenceFrame("N"))
    system = System.from_newtonian(ground)
    previous = ground
    for i in range(n):
        frame = ReferenceFrame(f"B{i}")
        body = RigidBody(f"link{i}", frame=frame, mass=sp.Symbol(f"m{i}"))
        body.inertia = Inertia.from_inertia_scalars(body.masscenter, frame, *INERTIA)
        q, u = dynamicsymbols(f"q{i} u{i}")
        axis = (previous.frame.x if i % 2 == 0 else previous.frame.y)
        child_axis = (frame.x if i % 2 == 0 else frame.y)
        parent_point = previous.masscenter if i == 0 else previous.masscenter.locatenew(
            f"J{i}", -0.5 * previous.frame.z)
        joint = PinJoint(f"J{i}", previous, body, coordinates=q, speeds=u,
                         parent_point=parent_point, child_point=0.5 * frame.z,
                         parent_axis=axis, child_axis=child_axis)
        system.add_joints(joint)
        previous = body
    system.apply_uniform_gravity(-g * ground.frame.z)
    system.validate_system()
    system.form_eoms()
    return system.mass_matrix, system.forcing


def check(n: int = 2) -> None:
    """The two derivations agree (M and f) at a random state."""
    import random

    import numpy as np
    import sympy as sp
    from sympy.physics.mechanics import dynamicsymbols

    (M, f), (K, k) = ours(n), kane(n)
    rng = random.Random(1)
    state = [rng.uniform(-2, 2) for _ in range(2 * n)]
    mine = {sp.Symbol(f"q{i}"): state[i] for i in range(n)}
    mine |= {sp.Symbol(f"q{i}_dot"): state[n + i] for i in range(n)}
    theirs = {dynamicsymbols(f"u{i}"): state[n + i] for i in range(n)}
    theirs |= {dynamicsymbols(f"q{i}"): state[i] for i in range(n)}
    constants = {sp.Symbol("g"): 9.81} | {sp.Symbol(f"m{i}"): 1.0 for i in range(n)}
    for a, b in ((M, K), (f, k)):
        a = np.array(a.xreplace(mine).xreplace(constants), dtype=float)
        b = np.array(b.xreplace(theirs).xreplace(constants), dtype=float)
        assert np.allclose(a, b, rtol=1e-9, atol=1e-9), (a, b)


def _child(which: str, n: int) -> None:
    # the imports are not part of the derivation's time
    import sympy.physics.mechanics  # noqa: F401

    import lagrangian  # noqa: F401

    start = time.perf_counter()
    (ours if which == "ours" else kane)(n)
    print(json.dumps({"seconds": time.perf_counter() - start}))


def _run(which: str, n: int, limit: float) -> float | None:
    try:
        out = subprocess.run([sys.executable, __file__, "--child", which, str(n)],
                             capture_output=True, text=True, timeout=limit, check=True).stdout
    except subprocess.TimeoutExpired:
        return None
    return json.loads(out.strip().splitlines()[-1])["seconds"]


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--sizes", default="1,2,3,4,5,6")
    parser.add_argument("--limit", type=float, default=120.0)
    parser.add_argument("--child", nargs=2)
    args = parser.parse_args()
    if args.child:
        _child(args.child[0], int(args.child[1]))
        return
    check(2)
    print("| n | ours (s) | KanesMethod (s) | Kane / ours |")
    print("|---|---|---|---|")
    for n in (int(s) for s in args.sizes.split(",")):
        a, b = _run("ours", n, args.limit), _run("kane", n, args.limit)
        ratio = f"{b / a:.2g}x" if a and b else ""
        print(f"| {n} | {_show(a, args.limit)} | {_show(b, args.limit)} | {ratio} |", flush=True)


def _show(seconds: float | None, limit: float) -> str:
    return f"{seconds:.3f}" if seconds is not None else f"> {limit:g}"


if __name__ == "__main__":
    main()
