"""Simulation speed: lagrangian's compiled numerics against sympy.physics.mechanics and PyDy.

Run:  pip install -e ".[bench]" && python benchmarks/bench_simulate.py [--quick]

Side by side in one process, on the n-link planar pendulum (point masses on massless rods,
absolute angles, m_i = l_i = 1, g = 9.81):
  1. the per-call right-hand side y' = rhs(t, y) for n = 2, 5, 10:
     ours (generated C, and our numpy fallback) vs sympy.physics.mechanics KanesMethod +
     lambdify(cse=True) + numpy.linalg.solve vs PyDy generate_ode_function(generator="cython");
  2. a 10 s double-pendulum run at rtol = atol = 1e-10 (DOP853), end to end: wall time,
     right-hand-side calls and relative energy drift max |E - E0| / |E0|;
  3. a batch of 10,000 double-pendulum states in one call vs 10,000 single calls.
PyDy's rhs returns the same array object on every call; solve_ivp then integrates a wrong
system, so it is wrapped with .copy() (the unwrapped run is shown too, to document the trap).
"""

from __future__ import annotations

import argparse
import sys
import time
import timeit
from pathlib import Path

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

import lagrangian  # noqa: F401
from lagrangian.simulation.compiled_loop import integrate_fast

sys.path.insert(0, str(Path(__file__).parent))
from n_link import build_lagrangian  # noqa: E402  (the same model as bench_derive)

G = 9.81


def kane_model(n: int):
    """(M, F, q, u, constants) of the n-link pendulum by sympy.physics.mechanics.KanesMethod."""
    import sympy.physics.mechanics as me

    q = me.dynamicsymbols(f"q1:{n + 1}")
    u = me.dynamicsymbols(f"u1:{n + 1}")
    g = sp.Symbol("g")
    masses = sp.symbols(f"m1:{n + 1}")
    lengths = sp.symbols(f"l1:{n + 1}")
    frame = me.ReferenceFrame("N")
    point = me.Point("O")
    point.set_vel(frame, 0)
    particles, loads = [], []
    for i in range(n):
        # absolute angle q_i from the downward vertical; velocity through u_i = q_i'
        frame_i = frame.orientnew(f"A{i + 1}", "Axis", (q[i], frame.z))
        frame_i.set_ang_vel(frame, u[i] * frame.z)
        nxt = point.locatenew(f"P{i + 1}", -lengths[i] * frame_i.y)
        nxt.v2pt_theory(point, frame, frame_i)
        particles.append(me.Particle(f"bob{i + 1}", nxt, masses[i]))
        loads.append((nxt, -masses[i] * g * frame.y))
        point = nxt
    kdes = [u[i] - q[i].diff(me.dynamicsymbols._t) for i in range(n)]
    kane = me.KanesMethod(frame, q_ind=q, u_ind=u, kd_eqs=kdes)
    kane.kanes_equations(particles, loads)
    constants = [g, *masses, *lengths]
    return kane.mass_matrix, kane.forcing, q, u, constants


def constant_values(n: int) -> np.ndarray:
    return np.array([G] + [1.0] * n + [1.0] * n)


def lambdify_rhs(n: int):
    """sympy.physics.mechanics + lambdify(cse=True) + numpy.linalg.solve."""
    M, F, q, u, constants = kane_model(n)
    qs, us = sp.symbols(f"q1:{n + 1}"), sp.symbols(f"u1:{n + 1}")
    plain = dict(zip([*q, *u], [*qs, *us], strict=True))
    args = [*qs, *us, *constants]
    mass = sp.lambdify(args, M.xreplace(plain), modules="numpy", cse=True)
    forcing = sp.lambdify(args, F.xreplace(plain), modules="numpy", cse=True)
    p = constant_values(n)

    def rhs(t, y):
        values = (*y, *p)
        return np.concatenate([y[n:], np.linalg.solve(mass(*values), forcing(*values).ravel())])

    return rhs


def pydy_rhs(n: int):
    """PyDy's generate_ode_function with the cython backend: f(x, t, p), odeint order."""
    from pydy.codegen.ode_function_generators import generate_ode_function

    M, F, q, u, constants = kane_model(n)
    return generate_ode_function(F, q, u, constants, mass_matrix=M, coordinate_derivatives=sp.Matrix(u),
                                 generator="cython", constants_arg_type="array"), constant_values(n)


def per_call_us(fn, *args, repeat: int = 5) -> float:
    """Best-of-repeat wall time of one call, in microseconds."""
    names = [f"a{i}" for i in range(len(args))]
    timer = timeit.Timer(f"fn({', '.join(names)})", globals={"fn": fn, **dict(zip(names, args, strict=True))})
    number, _ = timer.autorange()
    return min(timer.repeat(repeat=repeat, number=number)) / number * 1e6


def best_of(fn, repeat: int):
    best, out = np.inf, None
    for _ in range(repeat):
        start = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - start)
    return best, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="n = 2 and 5 only, fewer repeats")
    parser.add_argument("--no-pydy", action="store_true", help="skip PyDy (not installed)")
    options = parser.parse_args()
    sizes = (2, 5) if options.quick else (2, 5, 10)
    repeat = 3 if options.quick else 7
    rng = np.random.default_rng(0)

    print("## Per-call right-hand side, n-link pendulum (best of repeats, microseconds)\n")
    print("| n | ours C (µs) | ours numpy | lambdify + solve | PyDy cython | vs lambdify | vs PyDy |"
          " build C first / cached (s) | max |Δ| vs anchors |")
    print("|---|---|---|---|---|---|---|---|---|")
    for n in sizes:
        system = build_lagrangian(n)
        eom = system.equations_of_motion()
        start = time.perf_counter()
        ours = system.numeric(backend="c")
        first = time.perf_counter() - start
        start = time.perf_counter()
        system.numeric(backend="c")  # in-memory module; the disk cache is exercised by tests
        cached = time.perf_counter() - start
        del eom
        ours_np = system.numeric(backend="numpy")
        anchor = lambdify_rhs(n)
        y = np.concatenate([rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)])
        reference = anchor(0.0, y)
        row = {"c": per_call_us(ours.rhs, 0.0, y), "np": per_call_us(ours_np.rhs, 0.0, y),
               "lam": per_call_us(anchor, 0.0, y)}
        diff = max(np.max(np.abs(ours.rhs(0.0, y) - reference)),
                   np.max(np.abs(ours_np.rhs(0.0, y) - reference)))
        pydy_text, ratio_pydy = "—", "—"
        if not options.no_pydy:
            pydy_f, p = pydy_rhs(n)
            row["pydy"] = per_call_us(pydy_f, y, 0.0, p)
            diff = max(diff, np.max(np.abs(pydy_f(y, 0.0, p) - reference)))
            pydy_text, ratio_pydy = f"{row['pydy']:.2f}", f"{row['pydy'] / row['c']:.1f}×"
        print(f"| {n} | {row['c']:.3f} | {row['np']:.2f} | {row['lam']:.2f} | {pydy_text} | "
              f"{row['lam'] / row['c']:.1f}× | {ratio_pydy} | {first:.2f} / {cached:.3f} | {diff:.1e} |",
              flush=True)

    print("\n## 10 s double pendulum, DOP853, rtol = atol = 1e-10, y0 = [0.1, 0.2, 0, 0]"
          " (best of repeats)\n")
    system = build_lagrangian(2)
    ours = system.numeric(backend="c")
    y0 = np.array([0.1, 0.2, 0.0, 0.0])
    tol = dict(rtol=1e-10, atol=1e-10)

    def drift(states):
        energy = ours.energy(states[:, :2], states[:, 2:])
        return float(np.max(np.abs(energy - energy[0])) / abs(energy[0]))

    def scipy_run(rhs):
        result = solve_ivp(rhs, (0.0, 10.0), y0, method="DOP853", **tol)
        return result.nfev, result.y.T, result.success

    runs = {}
    wall, result = best_of(lambda: integrate_fast(ours, (0.0, 10.0), y0, **tol), repeat * 3)
    runs["ours: integrate_fast (DOP853 in C)"] = (wall, result.nfev, drift(result.y))

    def from_scratch():  # derivation + C generation (the compiled module is already cached)
        fresh = build_lagrangian(2).numeric(backend="c")
        return integrate_fast(fresh, (0.0, 10.0), y0, **tol)

    wall, result = best_of(from_scratch, 3)
    runs["ours: derive + generate C (module cached) + integrate_fast"] = (wall, result.nfev,
                                                                        drift(result.y))
    wall, (nfev, states, _) = best_of(lambda: scipy_run(ours.rhs), repeat)
    runs["ours: C rhs through scipy solve_ivp"] = (wall, nfev, drift(states))
    anchor = lambdify_rhs(2)
    wall, (nfev, states, _) = best_of(lambda: scipy_run(anchor), repeat)
    runs["sympy.physics.mechanics + lambdify + solve, solve_ivp"] = (wall, nfev, drift(states))
    if not options.no_pydy:
        pydy_f, p = pydy_rhs(2)
        wall, (nfev, states, _) = best_of(lambda: scipy_run(lambda t, x: pydy_f(x, t, p).copy()), repeat)
        runs["PyDy cython (.copy()), solve_ivp"] = (wall, nfev, drift(states))
        wall, (nfev, states, _) = best_of(lambda: scipy_run(lambda t, x: pydy_f(x, t, p)), repeat)
        runs["PyDy cython WITHOUT .copy() (wrong system)"] = (wall, nfev, drift(states))
    ours_wall = runs["ours: integrate_fast (DOP853 in C)"][0]
    print("| run | wall (ms) | rhs calls | energy drift | time ÷ integrate_fast |")
    print("|---|---|---|---|---|")
    for name, (wall, nfev, energy_drift) in runs.items():
        print(f"| {name} | {wall * 1e3:.3f} | {nfev} | {energy_drift:.1e} | {wall / ours_wall:.1f}× |")

    print("\n## Batch: 10,000 double-pendulum states in one call vs 10,000 single calls\n")
    Q, V = rng.uniform(-np.pi, np.pi, (10_000, 2)), rng.uniform(-3, 3, (10_000, 2))
    print("| function | one batched call (ms) | 10,000 single calls (ms) | ratio |")
    print("|---|---|---|---|")
    for name in ("accelerations_and_multipliers", "mass_matrix", "energy"):
        fn = getattr(ours, name)
        batched, values = best_of(lambda fn=fn: fn(Q, V), repeat * 3)
        singles, loop = best_of(lambda fn=fn: [fn(Q[i], V[i]) for i in range(len(Q))], 3)
        assert np.allclose(np.asarray(values if name != "accelerations_and_multipliers" else values[0]),
                           np.asarray([v if name != "accelerations_and_multipliers" else v[0] for v in loop]))
        print(f"| {name} | {batched * 1e3:.3f} | {singles * 1e3:.1f} | {singles / batched:.0f}× |")


if __name__ == "__main__":
    main()
