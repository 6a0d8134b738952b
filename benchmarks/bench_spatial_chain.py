"""Derivation of a spatial chain of n rigid bodies on revolute joints with alternating axes
(x, y, x, ...), ours against sympy.physics.mechanics KanesMethod (System / PinJoint API), and
the time of one call of our compiled right-hand side.

    python benchmarks/bench_spatial_chain.py [--sizes 1,...,10] [--limit 300]

Each derivation is timed in a fresh child process, imports excluded (best of one; the runs are
long); KanesMethod is stopped at --limit seconds and not run for larger n once it was. In our
child, after the derivation: ``System.numeric(backend="c")`` (C generated and compiled into an
empty cache) and then ``rhs(t, y)`` timed from Python with timeit (best of 5 x 20000 calls).
Before timing, the two mass matrices and forcings are checked to agree at random states for
n = 4 (whose last body goes through the Jacobian form).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import timeit

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
    system = lagrangian.System(b.build_model())
    eom = system.equations_of_motion()
    return eom.mass_matrix, eom.forcing, system


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


def check(n: int = 4) -> None:
    """The two derivations agree (M and f) at random states."""
    import random

    import numpy as np
    import sympy as sp
    from sympy.physics.mechanics import dynamicsymbols

    (M, f, _), (K, k) = ours(n), kane(n)
    rng = random.Random(1)
    for _ in range(3):
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
    # the imports are not part of the derivation's time (lagrangian imports lazily: its api,
    # numpy and scipy are loaded here too)
    import numpy as np
    import sympy.physics.mechanics  # noqa: F401

    import lagrangian
    import lagrangian.model.builder  # noqa: F401

    lagrangian.System  # noqa: B018

    start = time.perf_counter()
    found = (ours if which == "ours" else kane)(n)
    report = {"seconds": time.perf_counter() - start}
    if which == "ours":
        system = found[2]
        with tempfile.TemporaryDirectory() as cache:
            os.environ["LAGRANGIAN_CACHE"] = cache  # generate and compile, no cached module
            start = time.perf_counter()
            numeric = system.numeric(backend="c")
            report["compile"] = time.perf_counter() - start
            y = np.random.default_rng(0).uniform(-1.0, 1.0, 2 * n)
            rhs = numeric.rhs
            rhs(0.0, y)
            calls = 20000
            best = min(timeit.repeat(lambda: rhs(0.0, y), number=calls, repeat=5)) / calls
            report["rhs_us"] = best * 1e6
    print(json.dumps(report))


def _run(which: str, n: int, limit: float) -> dict | None:
    try:
        out = subprocess.run([sys.executable, __file__, "--child", which, str(n)],
                             capture_output=True, text=True, timeout=limit, check=True).stdout
    except subprocess.TimeoutExpired:
        return None
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--sizes", default="1,2,3,4,5,6,7,8,9,10")
    parser.add_argument("--limit", type=float, default=300.0)
    parser.add_argument("--child", nargs=2)
    args = parser.parse_args()
    if args.child:
        _child(args.child[0], int(args.child[1]))
        return
    check(4)
    print(f"load average at start: {os.getloadavg()[0]:.2f}")
    print("| n | ours (s) | KanesMethod (s) | Kane / ours | C build (s) | rhs call (µs) |")
    print("|---|---|---|---|---|---|")
    kane_stopped = False
    for n in (int(s) for s in args.sizes.split(",")):
        mine = _run("ours", n, 600.0)
        theirs = None if kane_stopped else _run("kane", n, args.limit)
        kane_stopped = theirs is None
        a, b = mine["seconds"], theirs["seconds"] if theirs else None
        ratio = f"{b / a:.3g}x" if b else f"> {args.limit / a:.3g}x"
        print(f"| {n} | {a:.3f} | {_show(b, args.limit)} | {ratio} | {mine['compile']:.1f} "
              f"| {mine['rhs_us']:.2f} |", flush=True)
    print(f"load average at end: {os.getloadavg()[0]:.2f}")


def _show(seconds: float | None, limit: float) -> str:
    return f"{seconds:.3f}" if seconds is not None else f"> {limit:g}"


if __name__ == "__main__":
    main()
