"""Grading a class: 30 answer files to the double pendulum checked in one run (derived once,
compared many), end to end in a fresh process, against the loop a teacher writes otherwise
(one `lagrangian check` per file).

    python benchmarks/bench_check_class.py            # the class run, best of 3
    python benchmarks/bench_check_class.py --loop     # also 30 separate runs, one per file
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

ROOT = Path(__file__).resolve().parents[1]

T = ("1/2*(m1 + m2)*l1^2*theta1_dot^2 + m2*l1*l2*theta1_dot*theta2_dot*cos(theta1 - theta2)"
     " + 1/2*m2*l2^2*theta2_dot^2")
V = "-(m1 + m2)*g*l1*cos(theta1) - m2*g*l2*cos(theta2)"
EQ1 = ("(m1 + m2)*l1^2*theta1_ddot + m2*l1*l2*theta2_ddot*cos(theta1 - theta2)"
       " + m2*l1*l2*theta2_dot^2*sin(theta1 - theta2) + (m1 + m2)*g*l1*sin(theta1) = 0")
EQ2 = ("m2*l2^2*theta2_ddot + m2*l1*l2*theta1_ddot*cos(theta1 - theta2)"
       " - m2*l1*l2*theta1_dot^2*sin(theta1 - theta2) + m2*g*l2*sin(theta2) = 0")
# What a class hands in: right answers written several ways, the seed's mistakes, a typo, and
# files that cannot be read.
VARIANTS = {
    "right": (T, V, EQ1, EQ2),
    "right_unicode": (T.replace("theta1_dot", "θ̇₁"), V.replace("*", "·"), EQ1, EQ2),
    "right_other_datum": (T, V + " + 5*m1*g*l1", EQ1, EQ2),
    "right_divided": (T, V, EQ1, "l2*theta2_ddot + l1*theta1_ddot*cos(theta1 - theta2)"
                      " - l1*theta1_dot^2*sin(theta1 - theta2) + g*sin(theta2) = 0"),
    "potential_sign": (T, V.replace("-(m1", "(m1").replace(" - m2", " + m2"), EQ1, EQ2),
    "forgot_half": (T.replace("1/2*", ""), V, EQ1, EQ2),
    "typo": (T, V.replace("g*l1", "g*L1"), EQ1, EQ2),
    "wrong_sign_in_equation": (T, V, EQ1.replace("+ (m1 + m2)*g", "- (m1 + m2)*g"), EQ2),
}


def answer_text(t: str, v: str, e1: str, e2: str) -> str:
    return f'[energy]\nT = "{t}"\nV = "{v}"\n[equations]\ntheta1 = "{e1}"\ntheta2 = "{e2}"\n'


def write_class(folder: Path, size: int = 30) -> list[Path]:
    names = list(VARIANTS)
    paths = []
    for i in range(size):
        path = folder / f"student_{i + 1:02d}.toml"
        if i % 15 == 14:  # two files in 30 cannot be read
            path.write_text('[energy]\nV = "m*g*(h"\n', encoding="utf-8")
        else:
            path.write_text(answer_text(*VARIANTS[names[i % len(names)]]), encoding="utf-8")
        paths.append(path)
    return paths


def run(arguments: list[str]) -> tuple[float, subprocess.CompletedProcess]:
    environment = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    began = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "lagrangian", *arguments], capture_output=True,
                          text=True, env=environment, check=False)
    return time.perf_counter() - began, done


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--loop", action="store_true", help="also time one run per file")
    parser.add_argument("--repeat", type=int, default=3)
    options = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        paths = write_class(Path(folder))
        times = []
        for _ in range(options.repeat):
            seconds, done = run(["check", "double_pendulum", folder, "--json"])
            times.append(seconds)
        counts = json.loads(done.stdout)["counts"]
        print(f"class run, 30 answer files to the double pendulum, end to end: "
              f"best {min(times):.2f} s of {options.repeat} (exit {done.returncode}; {counts})")
        import lagrangian

        system = lagrangian.load("double_pendulum")
        began = time.perf_counter()
        system.equations_of_motion()
        derived = time.perf_counter() - began
        began = time.perf_counter()
        system.check_many(folder)
        print(f"in process: derive {derived:.2f} s, then 30 checks {time.perf_counter() - began:.2f} s")
        if options.loop:
            began = time.perf_counter()
            for path in paths:
                run(["check", "double_pendulum", str(path), "--json"])
            print(f"one `lagrangian check` per file (30 runs): {time.perf_counter() - began:.2f} s")


if __name__ == "__main__":
    main()
