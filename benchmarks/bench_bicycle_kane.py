"""sympy's KanesMethod on the Whipple bicycle beside lagrangian's Lagrange derivation of the
built-in example whipple_bicycle.

    python benchmarks/bench_bicycle_kane.py [--limit 600]

The Kane model is sympy's own benchmark bicycle, built exactly as sympy's test suite builds it
(sympy/physics/mechanics/tests/test_kane3.py, test_bicycle, sympy 1.14: yaw, roll, pitch and
steer coordinates, the contact positions and wheel angles left out as ignorable, six speeds,
three velocity constraints and the front contact's height; Meijaard et al. 2007's parameters).
In a child process, limited to ``--limit`` seconds in all, it times (1) building the frames,
points and bodies, (2) ``KanesMethod(...).kanes_equations`` (fr + fr* = 0, the dependent speeds
eliminated by Cramer's rule), (3) ``KM.linearize(A_and_B=True)`` about upright rolling at speed
v, symbolic in v and in the parameters, (4) putting in the benchmark's values.

lagrangian's side, in the parent and never while the child runs: reading the model file
(8 coordinates), deriving M, f, Phi_q, gamma and compiling them to C in an empty cache, timed
as benchmarks/bench_bicycle.py times them; after the child, the lean-steer form
M q_ddot + v C1 q_dot + (g K0 + v^2 K2) q = 0 (system.speed_form). Kane's lean-steer A(v) is
compared with lagrangian's and with the benchmark's M, C1, K0, K2 (Meijaard et al. 2007,
Table 2): the same model. Wall and CPU times are printed with the load average: the machine
is shared, so read the ratios, the CPU ones first.
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

SPEEDS = (0.0, 1.0, 2.0, 4.0, 5.0, 6.0, 10.0)
# Meijaard et al. 2007, Table 2 (the benchmark's M, C1, K0, K2; lean phi, steer delta).
BENCHMARK_M = [[80.81722, 2.31941332208709], [2.31941332208709, 0.29784188199686]]
BENCHMARK_C1 = [[0.0, 33.86641391492494], [-0.85035641456978, 1.68540397397560]]
BENCHMARK_K0 = [[-80.95, -2.59951685249872], [-2.59951685249872, -0.80329488458618]]
BENCHMARK_K2 = [[0.0, 76.59734589573222], [0.0, 2.65431523794604]]
GRAVITY = 9.81


def _load() -> str:
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f}"


def _emit(record: dict) -> None:
    print(json.dumps(record), flush=True)


def kane_child() -> None:
    """Build and derive the bicycle with KanesMethod; one JSON line per finished stage."""
    wall, cpu = time.perf_counter(), time.process_time()

    def stage(name: str) -> None:
        nonlocal wall, cpu
        _emit({"stage": name, "wall": time.perf_counter() - wall,
               "cpu": time.process_time() - cpu})
        wall, cpu = time.perf_counter(), time.process_time()

    # From here to kanes_equations: sympy's test_kane3.py (test_bicycle), unchanged but for
    # comments; it was ported from Autolev, hence the names.
    from sympy import Matrix, acos, cos, pi, sin, sqrt, symbols
    from sympy.physics.mechanics import (
        KanesMethod,
        Point,
        ReferenceFrame,
        RigidBody,
        dot,
        dynamicsymbols,
        inertia,
    )

    q1, q2, q4, q5 = dynamicsymbols('q1 q2 q4 q5')
    q1d, q2d, q4d, q5d = dynamicsymbols('q1 q2 q4 q5', 1)
    u1, u2, u3, u4, u5, u6 = dynamicsymbols('u1 u2 u3 u4 u5 u6')
    WFrad, WRrad, htangle, forkoffset = symbols('WFrad WRrad htangle forkoffset')
    forklength, framelength, forkcg1 = symbols('forklength framelength forkcg1')
    forkcg3, framecg1, framecg3, Iwr11 = symbols('forkcg3 framecg1 framecg3 Iwr11')
    Iwr22, Iwf11, Iwf22, Iframe11 = symbols('Iwr22 Iwf11 Iwf22 Iframe11')
    Iframe22, Iframe33, Iframe31, Ifork11 = symbols('Iframe22 Iframe33 Iframe31 Ifork11')
    Ifork22, Ifork33, Ifork31, g = symbols('Ifork22 Ifork33 Ifork31 g')
    mframe, mfork, mwf, mwr = symbols('mframe mfork mwf mwr')

    N = ReferenceFrame('N')
    Y = N.orientnew('Y', 'Axis', [q1, N.z])
    R = Y.orientnew('R', 'Axis', [q2, Y.x])
    Frame = R.orientnew('Frame', 'Axis', [q4 + htangle, R.y])
    WR = ReferenceFrame('WR')
    TempFrame = Frame.orientnew('TempFrame', 'Axis', [-htangle, Frame.y])
    Fork = Frame.orientnew('Fork', 'Axis', [q5, Frame.x])
    TempFork = Fork.orientnew('TempFork', 'Axis', [-htangle, Fork.y])
    WF = ReferenceFrame('WF')

    WR_cont = Point('WR_cont')
    WR_mc = WR_cont.locatenew('WR_mc', WRrad * R.z)
    Steer = WR_mc.locatenew('Steer', framelength * Frame.z)
    Frame_mc = WR_mc.locatenew('Frame_mc', - framecg1 * Frame.x + framecg3 * Frame.z)
    Fork_mc = Steer.locatenew('Fork_mc', - forkcg1 * Fork.x + forkcg3 * Fork.z)
    WF_mc = Steer.locatenew('WF_mc', forklength * Fork.x + forkoffset * Fork.z)
    WF_cont = WF_mc.locatenew('WF_cont', WFrad * (dot(Fork.y, Y.z) * Fork.y -
                                                  Y.z).normalize())

    Y.set_ang_vel(N, u1 * Y.z)
    R.set_ang_vel(Y, u2 * R.x)
    WR.set_ang_vel(Frame, u3 * Frame.y)
    Frame.set_ang_vel(R, u4 * Frame.y)
    Fork.set_ang_vel(Frame, u5 * Fork.x)
    WF.set_ang_vel(Fork, u6 * Fork.y)

    WR_cont.set_vel(N, 0)
    WR_mc.v2pt_theory(WR_cont, N, WR)
    Steer.v2pt_theory(WR_mc, N, Frame)
    Frame_mc.v2pt_theory(WR_mc, N, Frame)
    Fork_mc.v2pt_theory(Steer, N, Fork)
    WF_mc.v2pt_theory(Steer, N, Fork)
    WF_cont.v2pt_theory(WF_mc, N, WF)

    Frame_I = (inertia(TempFrame, Iframe11, Iframe22, Iframe33, 0, 0, Iframe31), Frame_mc)
    Fork_I = (inertia(TempFork, Ifork11, Ifork22, Ifork33, 0, 0, Ifork31), Fork_mc)
    WR_I = (inertia(Frame, Iwr11, Iwr22, Iwr11), WR_mc)
    WF_I = (inertia(Fork, Iwf11, Iwf22, Iwf11), WF_mc)
    BodyFrame = RigidBody('BodyFrame', Frame_mc, Frame, mframe, Frame_I)
    BodyFork = RigidBody('BodyFork', Fork_mc, Fork, mfork, Fork_I)
    BodyWR = RigidBody('BodyWR', WR_mc, WR, mwr, WR_I)
    BodyWF = RigidBody('BodyWF', WF_mc, WF, mwf, WF_I)

    kd = [q1d - u1, q2d - u2, q4d - u4, q5d - u5]
    conlist_speed = [WF_cont.vel(N) & Y.x, WF_cont.vel(N) & Y.y, WF_cont.vel(N) & Y.z]
    conlist_coord = [WF_cont.pos_from(WR_cont) & Y.z]
    FL = [(Frame_mc, -mframe * g * Y.z),
          (Fork_mc, -mfork * g * Y.z),
          (WF_mc, -mwf * g * Y.z),
          (WR_mc, -mwr * g * Y.z)]
    BL = [BodyFrame, BodyFork, BodyWR, BodyWF]
    stage("build frames, points, bodies, constraints")

    KM = KanesMethod(N, q_ind=[q1, q2, q5], q_dependent=[q4],
                     configuration_constraints=conlist_coord,
                     u_ind=[u2, u3, u5], u_dependent=[u1, u4, u6],
                     velocity_constraints=conlist_speed, kd_eqs=kd,
                     constraint_solver="CRAMER")
    KM.kanes_equations(BL, FL)
    stage("kanes_equations")

    v = symbols('v')
    op_point = {u1.diff(): 0, u2.diff(): 0, u3.diff(): 0, u4.diff(): 0, u5.diff(): 0,
                u6.diff(): 0, u1: 0, u2: 0, u3: v / 0.3, u4: 0, u5: 0, u6: v / 0.35,
                q1: 0, q2: 0, q4: 0, q5: 0}
    A, B, _ = KM.linearize(A_and_B=True, op_point=op_point, linear_solver="CRAMER")
    stage("linearize (A and B, symbolic)")

    # test_kane3.py's parameter values: the benchmark's, in its frames.
    PaperRadRear = 0.3
    PaperRadFront = 0.35
    HTA = (pi / 2 - pi / 10).evalf()
    TrailPaper = 0.08
    rake = (-(TrailPaper * sin(HTA) - (PaperRadFront * cos(HTA)))).evalf()
    PaperWb = 1.02
    PaperFrameCgX = 0.3
    PaperFrameCgZ = 0.9
    PaperForkCgX = 0.9
    PaperForkCgZ = 0.7
    FrameLength = (PaperWb * sin(HTA) - (rake - (PaperRadFront - PaperRadRear) * cos(HTA))
                   ).evalf()
    FrameCGNorm = ((PaperFrameCgZ - PaperRadRear - (PaperFrameCgX / sin(HTA)) * cos(HTA))
                   * sin(HTA)).evalf()
    FrameCGPar = (PaperFrameCgX / sin(HTA) + (PaperFrameCgZ - PaperRadRear - PaperFrameCgX
                                               / sin(HTA) * cos(HTA)) * cos(HTA)).evalf()
    tempa = (PaperForkCgZ - PaperRadFront)
    tempb = (PaperWb - PaperForkCgX)
    tempc = (sqrt(tempa**2 + tempb**2)).evalf()
    PaperForkL = (PaperWb * cos(HTA) - (PaperRadFront - PaperRadRear) * sin(HTA)).evalf()
    ForkCGNorm = (rake + (tempc * sin(pi / 2 - HTA - acos(tempa / tempc)))).evalf()
    ForkCGPar = (tempc * cos((pi / 2 - HTA) - acos(tempa / tempc)) - PaperForkL).evalf()
    val_dict = {WFrad: PaperRadFront, WRrad: PaperRadRear, htangle: HTA, forkoffset: rake,
                forklength: PaperForkL, framelength: FrameLength, forkcg1: ForkCGPar,
                forkcg3: ForkCGNorm, framecg1: FrameCGNorm, framecg3: FrameCGPar,
                Iwr11: 0.0603, Iwr22: 0.12, Iwf11: 0.1405, Iwf22: 0.28, Ifork11: 0.05892,
                Ifork22: 0.06, Ifork33: 0.00708, Ifork31: 0.00756, Iframe11: 9.2,
                Iframe22: 11, Iframe33: 2.8, Iframe31: -2.4, mfork: 4, mframe: 85, mwf: 3,
                mwr: 2, g: 9.81, q1: 0, q2: 0, q4: 0, q5: 0, u1: 0, u2: 0,
                u3: v / PaperRadRear, u4: 0, u5: 0, u6: v / PaperRadFront}
    # Independent states [q1, q2, q5, u2, u3, u5]: lean q2, steer q5 and their rates.
    A = Matrix(A.xreplace(val_dict).evalf()).extract([1, 2, 3, 5], [1, 2, 3, 5])
    stage("substitute the benchmark's values")
    _emit({"A": {str(speed): [[float(entry) for entry in A.subs(v, speed).evalf().row(i)]
                              for i in range(4)] for speed in SPEEDS}})


def benchmark_state_matrix(speed: float):
    """A(v) of x = [phi, delta, phi_dot, delta_dot] from the benchmark's M, C1, K0, K2."""
    import numpy as np

    M, C1 = np.array(BENCHMARK_M), np.array(BENCHMARK_C1)
    K = GRAVITY * np.array(BENCHMARK_K0) + speed**2 * np.array(BENCHMARK_K2)
    inverse = np.linalg.inv(M)
    return np.block([[np.zeros((2, 2)), np.eye(2)], [-inverse @ K, -inverse @ (speed * C1)]])


def _clock() -> tuple[float, float]:
    return time.perf_counter(), time.process_time()


def _since(start: tuple[float, float]) -> tuple[float, float]:
    return time.perf_counter() - start[0], time.process_time() - start[1]


def ours():
    """lagrangian: model file to equations and to compiled functions, (wall, CPU) each, and
    the loaded system."""
    os.environ["LAGRANGIAN_CACHE"] = tempfile.mkdtemp(prefix="bench-bicycle-kane-")
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from bench_bicycle import _timed

    import lagrangian

    start = _clock()
    system = _timed("read the model file (4 bodies, 2 contacts)",
                    lambda: lagrangian.load("whipple_bicycle"))
    _timed("derive M, f, Phi_q, gamma (Lagrange)", system.equations_of_motion)
    derived = _since(start)
    _timed("compile (C, empty cache)", lambda: system.numeric(backend="c"))
    compiled = _since(start)
    return derived, compiled, system


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limit", type=float, default=600.0,
                        help="seconds the KanesMethod child may run in all")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    arguments = parser.parse_args()
    if arguments.child:
        kane_child()
        return

    import numpy as np

    print(f"lagrangian (Lagrange's method with multipliers); {_load()}")
    derived, compiled, system = ours()

    print(f"\nsympy KanesMethod (test_kane3.py's bicycle), limit {arguments.limit:.0f} s; "
          f"{_load()}", flush=True)
    with tempfile.TemporaryFile("w+") as log:
        start = time.perf_counter()
        child = subprocess.Popen([sys.executable, __file__, "--child"], stdout=log,
                                 stderr=subprocess.STDOUT)
        try:
            child.wait(timeout=arguments.limit)
            finished = True
        except subprocess.TimeoutExpired:
            child.kill()
            child.wait()
            finished = False
        elapsed = time.perf_counter() - start
        log.seek(0)
        lines = log.read().splitlines()
    print(f"{_load()} at the end")
    stages, matrices = {}, None
    for line in lines:
        try:
            record = json.loads(line)
        except json.JSONDecodeError:
            print(f"    child: {line}")
            continue
        if "stage" in record:
            stages[record["stage"]] = record
            print(f"{record['stage']:<48} {record['wall']:8.3f} s wall {record['cpu']:8.3f} s CPU")
        else:
            matrices = record["A"]
    if not finished:
        print(f"KanesMethod did not finish in {arguments.limit:.0f} s "
              f"(stages above finished; killed at {elapsed:.0f} s)")
    rows = [("model to equations", derived, ["build frames, points, bodies, constraints",
                                             "kanes_equations"])]
    rows.append(("model to compiled functions", compiled, None))
    if matrices is not None:
        print(f"\nlagrangian's lean-steer form, for the same A(v); {_load()}")
        start = _clock()
        rates = {"x_dot": "v", "thetaR_dot": "-v/rR", "thetaF_dot": "-v/rF"}
        form = system.speed_form(rates, "v", ["phi", "delta"])
        rows.append(("linearization, symbolic in v", _since(start),
                     ["linearize (A and B, symbolic)", "substitute the benchmark's values"]))
    print(f"\n{'(s; wall / CPU)':<30}{'lagrangian':>16}{'KanesMethod':>18}{'ratio (wall, CPU)':>20}")
    for label, (wall, cpu), parts in rows:
        mine = f"{wall:7.2f} / {cpu:6.2f}"
        if parts is None:
            print(f"{label:<30}{mine:>16}{'(no compile here)':>18}")
        elif all(part in stages for part in parts):
            kane_wall = sum(stages[part]["wall"] for part in parts)
            kane_cpu = sum(stages[part]["cpu"] for part in parts)
            print(f"{label:<30}{mine:>16}{f'{kane_wall:7.2f} / {kane_cpu:6.2f}':>18}"
                  f"{f'{kane_wall / wall:6.1f}, {kane_cpu / cpu:6.1f}':>20}")
        else:
            print(f"{label:<30}{mine:>16}{'did not finish':>18}")
    if matrices is not None:
        worst_benchmark = worst_ours = 0.0
        for speed, rows_of_a in matrices.items():
            kane_a = np.array(rows_of_a)
            for reference, name in ((benchmark_state_matrix(float(speed)), "benchmark"),
                                    (form.state_matrix(float(speed)), "ours")):
                difference = float(np.max(np.abs(kane_a - reference)) / np.max(np.abs(reference)))
                if name == "benchmark":
                    worst_benchmark = max(worst_benchmark, difference)
                else:
                    worst_ours = max(worst_ours, difference)
        print(f"Kane's lean-steer A(v) at v = {', '.join(matrices)} m/s, largest difference "
              f"(relative): {worst_ours:.1e} from lagrangian's, {worst_benchmark:.1e} from the "
              "benchmark's M, C1, K0, K2")

if __name__ == "__main__":
    main()
