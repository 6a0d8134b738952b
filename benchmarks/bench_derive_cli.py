"""`lagrangian derive` end to end: sympy's n-link pendulum on a cart and the n-link pendulum, as
model files, through the command line in every format, with sympy's KanesMethod alongside.

Run:  python benchmarks/bench_derive_cli.py [--cart 1-10] [--chain 1-30] [--repeat 3]

Model files are written by benchmarks/model_files.py into a temporary folder (nothing is kept).
Every figure is the best of --repeat runs (default 3); wall times, with the CPU time (user +
system) of the process in brackets where a whole process is timed, since on a shared machine the
wall time also counts the time a process waits for a CPU:

- "CLI" columns: `python -m lagrangian derive FILE --format F > /dev/null` in a fresh process:
  interpreter start-up, imports, reading the file, the derivation, the symbolic accelerations
  (attempted under their budget), formatting and writing the output.
- "read", "derive", "text": the same steps after the imports, timed one by one in a fresh
  process: reading the file (which builds the unit registry), the derivation (mass matrix,
  forcing, generalized forces, constraint terms, the regularity check), and the text output
  (which includes the symbolic accelerations, attempted under their budget).
- "Kane": sympy.physics.mechanics.models.n_link_pendulum_on_cart(n) (KanesMethod, the same
  model, links from the upward vertical, a force on the cart) in a fresh process; "in-process"
  is the call alone (it forms kanes_equations, the mass matrix and forcing), "process" adds
  start-up and `import sympy.physics.mechanics`. Kane prints nothing; ours prints everything.
  "Kane call/derive" compares the derivations alone; "Kane proc/CLI text" whole processes.

Before timing, our accelerations M^-1 f (from the model file) are checked to equal Kane's
(mass_matrix_full, forcing_full with u = q_dot) at a random state for n = 1, 2 and 5.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

import model_files  # noqa: E402

FORMATS = ("text", "json", "latex")

_IN_PROCESS = r"""
import sys, time
from lagrangian.model.reader import read_model
from lagrangian.derivation.lagrange import derive
from lagrangian.output.derivation import derivation_text, derivation_document, derivation_latex
import json
path, fmt = sys.argv[1], sys.argv[2]
start = time.perf_counter()
model = read_model(path)
read = time.perf_counter()
eom = derive(model)
derived = time.perf_counter()
if fmt == "json":
    out = json.dumps(derivation_document(eom), indent=2)
elif fmt == "latex":
    out = derivation_latex(eom)
else:
    out = derivation_text(eom)
print(read - start, derived - read, time.perf_counter() - derived)
"""

_KANE = r"""
import sys, time
start = time.perf_counter()
from sympy.physics.mechanics.models import n_link_pendulum_on_cart
imported = time.perf_counter()
kane = n_link_pendulum_on_cart(int(sys.argv[1]), cart_force=True)
M, F = kane.mass_matrix, kane.forcing
print(time.perf_counter() - imported)
"""


def _best(times: list[float]) -> float:
    return min(times)


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def cli_time(path: Path, fmt: str, repeat: int) -> float:
    """Best wall time of the whole `derive` process; its CPU time goes to CPU_TIMES."""
    times, cpu = [], []
    for _ in range(repeat):
        before = _children_cpu()
        start = time.perf_counter()
        result = subprocess.run([sys.executable, "-m", "lagrangian", "derive", str(path),
                                 "--format", fmt], capture_output=True, check=False)
        times.append(time.perf_counter() - start)
        cpu.append(_children_cpu() - before)
        if result.returncode != 0 or not result.stdout:
            raise SystemExit(f"derive failed on {path} ({fmt}): {result.stderr.decode()}")
    CPU_TIMES[(str(path), fmt)] = min(cpu)
    return _best(times)


# (model file, format) -> best CPU time (user + system) of the derive process, seconds: on a
# shared machine it does not count the time the process waited for a CPU.
CPU_TIMES: dict[tuple[str, str], float] = {}


def in_process_times(path: Path, fmt: str, repeat: int) -> tuple[float, float, float]:
    """(read the file, derive, format) seconds after the imports, each the best of ``repeat``
    fresh processes (reading includes building the unit registry)."""
    runs = [[float(x) for x in subprocess.run(
        [sys.executable, "-c", _IN_PROCESS, str(path), fmt], capture_output=True, text=True,
        check=True).stdout.split()] for _ in range(repeat)]
    return tuple(min(run[k] for run in runs) for k in range(3))


def kane_times(n: int, repeat: int) -> tuple[float, float]:
    """(in-process call, whole process) seconds, best of ``repeat``."""
    calls, processes, cpu = [], [], []
    for _ in range(repeat):
        before = _children_cpu()
        start = time.perf_counter()
        out = subprocess.run([sys.executable, "-c", _KANE, str(n)], capture_output=True,
                             text=True, check=True).stdout
        processes.append(time.perf_counter() - start)
        cpu.append(_children_cpu() - before)
        calls.append(float(out))
    CPU_TIMES[("kane", str(n))] = min(cpu)
    return _best(calls), _best(processes)


def agree(n: int, folder: Path) -> bool:
    """Our q_ddot (from the model file) equals KanesMethod's u_dot at a random state."""
    import numpy as np
    import sympy as sp
    import sympy.physics.mechanics as me
    from sympy.physics.mechanics.models import n_link_pendulum_on_cart

    from lagrangian.derivation.lagrange import derive
    from lagrangian.model.reader import read_model

    path = folder / f"check_{n}.toml"
    path.write_text(model_files.n_link_pendulum_on_cart(n))
    eom = derive(read_model(path))
    kane = n_link_pendulum_on_cart(n, cart_force=True)
    rng = random.Random(n)
    ours, theirs = {}, {}
    for i in range(n + 1):
        q, u = rng.uniform(-2, 2), rng.uniform(-2, 2)
        ours.update({sp.Symbol(f"q{i}"): q, sp.Symbol(f"q{i}_dot"): u})
        theirs.update({me.dynamicsymbols(f"q{i}"): q, me.dynamicsymbols(f"u{i}"): u})
        mass = rng.uniform(0.5, 2)
        ours[sp.Symbol(f"m{i}")] = theirs[sp.Symbol(f"m{i}")] = mass
    for i in range(n):
        length = rng.uniform(0.5, 2)
        ours[sp.Symbol(f"l{i}")] = theirs[sp.Symbol(f"l{i}")] = length
    ours[sp.Symbol("g")] = theirs[sp.Symbol("g")] = 9.81
    ours[sp.Symbol("F")] = theirs[me.dynamicsymbols("F")] = 1.7
    ours[sp.Symbol("t")] = 0.0
    M = np.array(eom.mass_matrix.xreplace(ours).evalf(), dtype=float)
    f = np.array(eom.forcing.xreplace(ours).evalf(), dtype=float).ravel()
    K = np.array(kane.mass_matrix.subs(theirs).evalf(), dtype=float)
    g = np.array(kane.forcing.subs(theirs).evalf(), dtype=float).ravel()
    return bool(np.allclose(np.linalg.solve(M, f), np.linalg.solve(K, g), rtol=1e-9))


def sizes(text: str) -> list[int]:
    if "-" in text:
        low, high = (int(x) for x in text.split("-"))
        return list(range(low, high + 1))
    return [int(x) for x in text.split(",") if x]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cart", default="1-10", help="n of the pendulum on a cart")
    parser.add_argument("--chain", default="1-30", help="n of the plain n-link pendulum")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", help="also write the measurements to this file")
    parser.add_argument("--markdown", help="also write the tables of docs/benchmarks.md here")
    args = parser.parse_args()
    results: dict[str, list] = {"cart": [], "chain": []}
    print(f"python {sys.version.split()[0]}, {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.2f} at start")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for n in (1, 2, 5):
            print(f"check n={n}: our accelerations equal KanesMethod's: {agree(n, folder)}")
        print("\nn-link pendulum on a cart (sympy n_link_pendulum_on_cart)")
        header = (f"{'n':>3} | {'CLI text':>8} {'CLI json':>8} {'CLI latex':>9} | "
                  f"{'read':>6} {'derive':>7} {'text':>6} | {'Kane call':>9} {'Kane proc':>9} | "
                  f"{'Kane call/derive':>16} {'Kane proc/CLI text':>18}")
        print(header + "\n" + "-" * len(header))
        for n in sizes(args.cart):
            path = folder / f"cart_{n}.toml"
            path.write_text(model_files.n_link_pendulum_on_cart(n))
            cli = {fmt: cli_time(path, fmt, args.repeat) for fmt in FORMATS}
            read, derived, text = in_process_times(path, "text", args.repeat)
            call, process = kane_times(n, args.repeat)
            cpu = {fmt: CPU_TIMES[(str(path), fmt)] for fmt in FORMATS}
            results["cart"].append({"n": n, "cli": cli, "cli_cpu": cpu, "read": read,
                                    "derive": derived, "format_text": text, "kane_call": call,
                                    "kane_process": process,
                                    "kane_process_cpu": CPU_TIMES[("kane", str(n))]})
            print(f"{n:>3} | {cli['text']:>8.2f} {cli['json']:>8.2f} {cli['latex']:>9.2f} | "
                  f"{read:>6.3f} {derived:>7.3f} {text:>6.3f} | {call:>9.3f} {process:>9.2f} | "
                  f"{call / derived:>15.1f}x {process / cli['text']:>17.2f}x", flush=True)
        print("\nn-link pendulum")
        header = (f"{'n':>3} | {'CLI text':>8} {'CLI json':>8} {'CLI latex':>9} | "
                  f"{'read':>6} {'derive':>7} {'text':>6}")
        print(header + "\n" + "-" * len(header))
        for n in sizes(args.chain):
            path = folder / f"chain_{n}.toml"
            path.write_text(model_files.n_link_pendulum(n))
            cli = {fmt: cli_time(path, fmt, args.repeat) for fmt in FORMATS}
            read, derived, text = in_process_times(path, "text", args.repeat)
            cpu = {fmt: CPU_TIMES[(str(path), fmt)] for fmt in FORMATS}
            results["chain"].append({"n": n, "cli": cli, "cli_cpu": cpu, "read": read,
                                     "derive": derived, "format_text": text})
            print(f"{n:>3} | {cli['text']:>8.2f} {cli['json']:>8.2f} {cli['latex']:>9.2f} | "
                  f"{read:>6.3f} {derived:>7.3f} {text:>6.3f}", flush=True)
    print(f"\nload average {os.getloadavg()[0]:.2f} at the end")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))
    if args.markdown:
        Path(args.markdown).write_text(markdown(results))


def markdown(results: dict) -> str:
    """The two tables of docs/benchmarks.md."""
    def pair(row, fmt):
        return f"{row['cli'][fmt]:.2f} ({row['cli_cpu'][fmt]:.2f})"

    lines = ["| n | CLI text, s: wall (CPU) | CLI JSON | CLI LaTeX | read / derive / text "
             "in-process (s) | KanesMethod call (s) | KanesMethod process: wall (CPU) "
             "| Kane call ÷ our derive | Kane process ÷ our CLI text (CPU) |", "|---" * 9 + "|"]
    for row in results["cart"]:
        lines.append(f"| {row['n']} | {pair(row, 'text')} | {pair(row, 'json')} "
                     f"| {pair(row, 'latex')} "
                     f"| {row['read']:.3f} / {row['derive']:.3f} / {row['format_text']:.3f} "
                     f"| {row['kane_call']:.3f} "
                     f"| {row['kane_process']:.2f} ({row['kane_process_cpu']:.2f}) "
                     f"| {row['kane_call'] / row['derive']:.0f}× "
                     f"| {row['kane_process_cpu'] / row['cli_cpu']['text']:.1f}× |")
    lines += ["", "| n | CLI text, s: wall (CPU) | CLI JSON | CLI LaTeX "
              "| read / derive / text in-process (s) |", "|---" * 5 + "|"]
    for row in results["chain"]:
        lines.append(f"| {row['n']} | {pair(row, 'text')} | {pair(row, 'json')} "
                     f"| {pair(row, 'latex')} "
                     f"| {row['read']:.3f} / {row['derive']:.3f} / {row['format_text']:.3f} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
