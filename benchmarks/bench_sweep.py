"""Parameter studies and ensembles on Dask: wall times, scaling and the gain over a plain loop.

Run:  python benchmarks/bench_sweep.py [--quick]

  1. a 10^5-point modes sweep of the two-mass system (examples/two_mass.toml), twice: over
     k x k_c (1000 x 100: every point searches its own equilibrium) and over k x m (1000 x 100:
     the masses do not enter the forces at rest, so the search runs once per k); each timed
     end to end through System.sweep with its default LocalCluster (2 worker processes here,
     started and closed inside the timing) and again on a cluster already running;
  2. 10^4 ten-second double-pendulum simulations (DOP853, rtol = atol = 1e-9, 201 samples,
     theta1 ~ uniform(-1, 1), theta2 ~ uniform(-1, 1)): end to end with the default cluster;
  3. the speed-up from one worker process to two (clusters already running; the 10^5-point
     k x k_c sweep, 2,000 and 10^4 ensemble members, and the marginal cost per member);
  4. the time per point against a plain Python loop of the single-point API:
     system.with_parameters(k=..., k_c=...).modes() and
     system.simulate(10, initial={...}) per member. For ensembles three figures per member:
     end to end (the 10^4-member study of 2 with the default cluster's start and close), on
     the running 2-worker cluster (10^4 members), and marginal there ((t(10^4) - t(2000)) /
     8000: what one more member costs once the study's fixed costs are paid); and the CPU per
     member of one 1000-member chunk in this process (evaluate_chunk: the C ensemble loop).
Times are wall-clock seconds, best of ``--repeat`` runs (1 by default: the cluster start-up is
part of what a user waits for), with the CPU seconds every process of the run used (this one,
the workers it started, and for a running cluster its workers, from psutil): on a machine
shared with other work the CPU time is the steadier figure. The load average is printed before
and after. See docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import logging
import os
import resource
import time

import numpy as np

import lagrangian


def _cluster(workers: int):
    """A running cluster set up as System.sweep sets up its own (study/engine.py)."""
    import dask
    from dask.distributed import Client, LocalCluster

    from lagrangian.study.engine import WORKER_ENVIRONMENT

    with dask.config.set(WORKER_ENVIRONMENT):
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=":0", silence_logs=logging.ERROR)
    return Client(cluster), cluster


CPU = {"last": 0.0}


def _cpu_here() -> float:
    """CPU seconds of this process and of its children that have ended (a default cluster)."""
    total = 0.0
    for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN):
        usage = resource.getrusage(who)
        total += usage.ru_utime + usage.ru_stime
    return total


def _cpu_workers(client) -> float:
    if client is None:
        return 0.0

    def used() -> float:
        import psutil

        times = psutil.Process().cpu_times()
        return times.user + times.system

    return sum(client.run(used).values())


def _timed(function, repeat: int = 1, client=None) -> float:
    """Best wall time of ``repeat`` runs; CPU["last"]: the CPU seconds of the last run."""
    best = float("inf")
    for _ in range(repeat):
        cpu, workers = _cpu_here(), _cpu_workers(client)
        began = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - began)
        CPU["last"] = _cpu_here() - cpu + _cpu_workers(client) - workers
    return best


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true", help="10x fewer points")
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    scale = 10 if args.quick else 1
    two_mass = lagrangian.load("two_mass")
    pendulum = lagrangian.load("double_pendulum")
    k = np.linspace(10, 100, 1000 // scale)
    second = np.linspace(1, 10, 100)
    points = len(k) * len(second)
    members = 10_000 // scale
    ensemble = {"sample": {"theta1": "uniform(-1, 1)", "theta2": "uniform(-1, 1)"},
                "members": members, "t_end": 10.0, "samples": 201}
    rows = []
    print(f"cores: {os.cpu_count()}, load average before: {os.getloadavg()}")

    # 4 first: a plain Python loop of the single-point API, as a user's fresh script runs it
    # (before this process has started and gathered any cluster)
    loop_rows = []
    loop_points = 50
    values = list(zip(np.linspace(10, 100, loop_points), np.linspace(1, 10, loop_points),
                      strict=True))
    t_modes = _timed(lambda: [two_mass.with_parameters(k=float(a), k_c=float(b)).modes()
                              for a, b in values])
    cpu_modes = CPU["last"]
    rng = np.random.default_rng(0)
    starts = rng.uniform(-1, 1, (loop_points, 2))
    pendulum.simulate(10.0, samples=201)  # compile once, as the sweep does
    t_sim = _timed(lambda: [pendulum.simulate(10.0, samples=201, initial={
        "theta1": float(a), "theta2": float(b)}) for a, b in starts])
    cpu_sim = CPU["last"]
    lengths = rng.uniform(0.9, 1.1, loop_points)
    t_sim_p = _timed(lambda: [pendulum.with_parameters(l1=float(a)).simulate(10.0, samples=201)
                              for a in lengths])
    cpu_sim_p = CPU["last"]
    loop_rows.append((f"loop of System.with_parameters(...).modes(), {loop_points} points",
                      t_modes, loop_points, cpu_modes))
    loop_rows.append((f"loop of System.simulate(10 s), {loop_points} members", t_sim,
                      loop_points, cpu_sim))
    loop_rows.append((f"loop of System.with_parameters(l1=...).simulate(10 s), {loop_points} "
                      "members", t_sim_p, loop_points, cpu_sim_p))

    # 1-2: end to end, the default cluster started and closed by System.sweep
    t = _timed(lambda: two_mass.sweep({"k": k, "k_c": second}, compute="modes"), args.repeat)
    rows.append((f"modes, two_mass, k x k_c = {points:,} points, default cluster", t, points,
                 CPU["last"]))
    t = _timed(lambda: two_mass.sweep({"k": k, "m": second}, compute="modes"), args.repeat)
    rows.append((f"modes, two_mass, k x m = {points:,} points, default cluster", t, points,
                 CPU["last"]))
    t = _timed(lambda: pendulum.sweep(compute="simulate", **ensemble), args.repeat)
    rows.append((f"simulate, double pendulum, {members:,} x 10 s, default cluster", t, members,
                 CPU["last"]))

    # 3: clusters already running: one worker, then two
    few = {**ensemble, "members": 2000 // scale}
    scaling, marginal = {}, {}
    for workers in (1, 2):
        client, cluster = _cluster(workers)
        try:
            # warm every worker (one chunk per point here, so each worker gets some): a warm-up
            # of one chunk would leave the second worker to build its functions inside the timing
            two_mass.sweep({"k": k[:4], "k_c": second[:4]}, client=client, chunk_size=1)
            pendulum.sweep(compute="simulate", client=client, chunk_size=1,
                           **{**few, "members": 8})
            a = _timed(lambda c=client: two_mass.sweep({"k": k, "k_c": second}, client=c),
                       args.repeat, client)
            cpu_a = CPU["last"]
            b = _timed(lambda c=client: pendulum.sweep(compute="simulate", client=c, **few),
                       args.repeat, client)
            cpu_b = CPU["last"]
            big = _timed(lambda c=client: pendulum.sweep(compute="simulate", client=c,
                                                         **ensemble), args.repeat, client)
            cpu_big = CPU["last"]
            marginal[workers] = (big - b) / (members - few["members"])
        finally:
            client.close()
            cluster.close()
        scaling[workers] = (a, b, big, marginal[workers])
        rows.append((f"modes, k x k_c = {points:,} points, running cluster of {workers}", a,
                     points, cpu_a))
        rows.append((f"simulate, {few['members']:,} x 10 s, running cluster of {workers}", b,
                     few["members"], cpu_b))
        rows.append((f"simulate, {members:,} x 10 s, running cluster of {workers}", big,
                     members, cpu_big))

    # one chunk of the ensemble in this process: the C loop and the chunk's bookkeeping
    from lagrangian.analysis.study import SimulationOptions, make_study
    from lagrangian.analysis.sweep import evaluate_chunk
    from lagrangian.study.engine import with_compiled_module

    study = with_compiled_module(make_study(
        pendulum._equations, "simulate", {}, sample=ensemble["sample"], members=1000,
        simulation=SimulationOptions(10.0, samples=201), chunk_size=1000))
    evaluate_chunk(study, 0, 8)
    t_chunk = _timed(lambda: evaluate_chunk(study, 0, 1000), 3)
    rows.append(("one 1000-member chunk in this process (evaluate_chunk)", t_chunk, 1000,
                 CPU["last"]))

    rows += loop_rows
    print()
    print("| what | wall (s) | wall per point (ms) | CPU (s) | CPU per point (ms) |")
    print("|---|---:|---:|---:|---:|")
    for what, seconds, count, cpu in rows:
        print(f"| {what} | {seconds:.2f} | {1e3 * seconds / count:.3f} | {cpu:.1f} | "
              f"{1e3 * cpu / count:.3f} |")
    print()
    print(f"load average after: {os.getloadavg()}")
    for label, index in (("modes 10^5 (k x k_c)", 0), (f"simulate {few['members']:,}", 1),
                         (f"simulate {members:,}", 2), ("simulate, marginal per member", 3)):
        one, two = scaling[1][index], scaling[2][index]
        print(f"speed-up 1 -> 2 workers, {label}: {one / two:.2f}x")
    per_point_sweep = rows[0][1] / rows[0][2]
    print(f"modes per point: loop {1e3 * t_modes / loop_points:.2f} ms, sweep "
          f"{1e3 * per_point_sweep:.4f} ms end to end: "
          f"{(t_modes / loop_points) / per_point_sweep:.0f}x")
    loop, loop_p = t_sim / loop_points, t_sim_p / loop_points
    print(f"simulate per member, loop of simulate(10): {1e3 * loop:.3f} ms; with a parameter "
          f"changed per member: {1e3 * loop_p:.3f} ms")
    running = next(r for r in rows
                   if r[0] == f"simulate, {members:,} x 10 s, running cluster of 2")
    for label, per_member in (("end to end (default cluster)", rows[2][1] / rows[2][2]),
                              ("running cluster of 2", running[1] / running[2]),
                              ("marginal on the running cluster", marginal[2])):
        print(f"  ensemble {label}: {1e3 * per_member:.4f} ms per member: "
              f"{loop / per_member:.1f}x the loop, {loop_p / per_member:.1f}x with a parameter")


if __name__ == "__main__":
    main()
