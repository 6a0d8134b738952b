"""Running a study on Dask: chunks as tasks on a dask.distributed cluster, results kept as they
finish so that an interrupted study can be resumed.

By default a LocalCluster with one single-threaded worker process per core is started and
closed around the study; ``scheduler`` (an address, tcp://host:8786) uses a running cluster, so a
study can go to many machines; ``client`` uses a dask Client the caller owns (tests run an
in-process one). Each finished chunk is written to a directory of per-chunk files beside the
output (``<out>.partial``) before the next is awaited; tasks are retried by the scheduler when
a worker dies. Dask is imported only here, when a study runs.
"""

from __future__ import annotations

import logging
import os
import uuid
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..analysis.study import NOT_COMPUTED, Study, layout
from ..analysis.sweep import ENSEMBLE_NATIVE, evaluate_chunk
from ..errors import ModelError
from ..output.sweep import check_study_path, require_study_packages, study_dataset, write_study
from .store import PartialStore

# Tasks of a chunk whose worker died are run again this many times before the study gives up.
RETRIES = 3

# Dask starts workers with MALLOC_TRIM_THRESHOLD_=65536, which also turns off glibc's adaptive
# mmap threshold: every temporary array of a chunk (hundreds of kB) is then a fresh mmap with
# its page faults, and a chunk costs twice the CPU. Our workers keep such memory for reuse.
WORKER_ENVIRONMENT = {
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": 256 * 2**20,
    "distributed.nanny.pre-spawn-environ.MALLOC_MMAP_THRESHOLD_": 32 * 2**20,
}


def chunk_task(study: Study, start: int, stop: int) -> dict[str, np.ndarray]:
    """What runs on a worker: one chunk's arrays (the compiled functions are cached per process)."""
    return evaluate_chunk(study, start, stop)


def with_compiled_module(study: Study) -> Study:
    """For an ensemble: build the model's C module once here, into the on-disk cache keyed by
    the equations (no C generated on a hit), so the workers load it instead of building it."""
    if study.compute != "simulate":
        return study
    from ..compile import compiled
    from ..compile.codegen import CodegenError, generate
    from ..compile.functions import equations_key

    if not compiled.available():
        return study
    key = equations_key(study.eom)
    try:
        # the module with the vector kernel, built for this processor (its own cache name)
        compiled.load_keyed(key, lambda: generate(study.eom, vector=True),
                            native=ENSEMBLE_NATIVE)
    except (CodegenError, compiled.BackendUnavailable):
        return study
    return replace(study, compiled_key=key)


def assemble(study: Study, pieces: dict[int, dict[str, np.ndarray]]):
    """The flat arrays of all points from the chunks done; points not done are NaN with status
    'not computed'. Extra dimensions that differ by chunk (the equilibrium count) are padded."""
    extra = {}
    for arrays in pieces.values():
        for name, array in arrays.items():
            shape = np.shape(array)[1:]
            extra[name] = tuple(max(a, b) for a, b in zip(extra.get(name, shape), shape,
                                                            strict=True))
    names = layout(study)
    out = {}
    for name in names:
        shape = extra.get(name)
        if shape is None:  # nothing finished: the sizes the study would have had
            shape = _default_extra(study, names[name][0])
        out[name] = np.full((study.size, *shape), np.nan)
    out["status"] = np.full(study.size, NOT_COMPUTED, dtype=object)
    for start, arrays in pieces.items():
        for name, array in arrays.items():
            array = np.asarray(array)
            index = (slice(start, start + len(array)), *(slice(0, s) for s in array.shape[1:]))
            out[name][index] = array
    return out


def _default_extra(study: Study, dims: tuple[str, ...]) -> tuple[int, ...]:
    n = len(study.model.coordinates)
    steady = study.model.steady_motion
    sizes = {"mode": n, "coordinate": n, "equilibrium": 1, "state": 2 * n,
             "eigenvalue": 2 * len(steady.keep) if steady is not None else 0,
             "time": study.simulation.samples if study.simulation else 1}
    return tuple(sizes[d] for d in dims)


def run_study(
    study: Study,
    *,
    out: str | Path | None = None,
    resume: bool = False,
    scheduler: str | None = None,
    client=None,
    workers: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    protect: tuple[Path, ...] = (),
):
    """Run every chunk of ``study`` on Dask and return its Dataset (written to ``out`` if given).

    ``progress(points_done, points_total)`` is called as chunks finish. On KeyboardInterrupt
    what finished is written to ``out`` (status 'not computed' elsewhere) and kept in
    ``<out>.partial``; ``resume=True`` continues from there.
    """
    require_study_packages(out)
    if out is not None:
        check_study_path(out)
    check_workers(workers)
    study = with_compiled_module(study)
    store = None
    done: set[int] = set()
    if out is not None:
        out = Path(out)
        store = PartialStore(out.with_name(out.name + ".partial"), study)
        done = store.open(resume)
    elif resume:
        raise ModelError("resume needs the output path the study writes to", field="resume")
    pieces: dict[int, dict[str, np.ndarray]] = {start: store.read(start) for start in done} \
        if store else {}
    todo = [(a, b) for a, b in study.chunks if a not in done]
    finished = sum(b - a for a, b in study.chunks if a in done)
    if progress is not None:
        progress(finished, study.size)
    try:
        if todo:
            with _cluster(scheduler, client, workers) as dask_client:
                finished = _run_chunks(dask_client, study, todo, pieces, store, finished,
                                       progress)
    except KeyboardInterrupt:
        if out is not None:
            done_points = sum(len(p["status"]) for p in pieces.values())
            write_study(study_dataset(study, assemble(study, pieces), done_points), out,
                        protect=protect)
        raise
    dataset = study_dataset(study, assemble(study, pieces))
    if out is not None:
        write_study(dataset, out, protect=protect)
        store.remove()
    return dataset


def _run_chunks(client, study, todo, pieces, store, finished, progress) -> int:
    from dask.distributed import as_completed

    # Keys new for each run (hash=False for the scattered study too): a study run again or
    # resumed must not meet the data and tasks the last run is still releasing.
    shared = client.scatter(study, broadcast=True, hash=False)
    run = uuid.uuid4().hex[:8]
    futures = {}
    for start, stop in todo:
        future = client.submit(chunk_task, shared, start, stop, pure=False, retries=RETRIES,
                               key=f"lagrangian-chunk-{start}-{run}")
        futures[future] = start
    try:
        for future in as_completed(list(futures)):
            arrays = future.result()
            start = futures[future]
            pieces[start] = arrays
            if store is not None:
                store.write(start, arrays)
            finished += len(arrays["status"])
            if progress is not None:
                progress(finished, study.size)
    finally:
        for future in futures:
            if not future.done():
                future.cancel()
    return finished


# A local cluster's worker processes: more than a few per core only add start-up time and memory.
WORKERS_PER_CORE = 4


def check_workers(workers: int | None) -> None:
    """Refuse a local cluster of fewer than 1 or more than WORKERS_PER_CORE workers per core."""
    if workers is None:
        return
    most = WORKERS_PER_CORE * (os.cpu_count() or 1)
    if not 1 <= int(workers) <= most:
        raise ModelError(f"{workers} workers: give 1 to {most} ({WORKERS_PER_CORE} per core "
                         "of this machine)", field="workers")


class _cluster:
    """The dask Client to use: the caller's, one connected to ``scheduler``, or a LocalCluster
    started here (one single-threaded worker process per core) and closed afterwards."""

    def __init__(self, scheduler, client, workers):
        self.scheduler, self.client, self.workers = scheduler, client, workers
        self.owned = []

    def __enter__(self):
        if self.client is not None:
            return self.client
        from dask.distributed import Client, LocalCluster

        if self.scheduler:
            scheme = self.scheduler.split("://", 1)[0] if "://" in self.scheduler else "tcp"
            if scheme not in ("tcp", "tls", "inproc"):  # inproc: a scheduler in this process
                raise ModelError(f"the scheduler address must be tcp://HOST:PORT or "
                                 f"tls://HOST:PORT, not {scheme}://", field="scheduler")
            try:
                client = Client(self.scheduler, timeout="10s")
            except Exception as exc:  # noqa: BLE001 - unreachable, no address, TLS without certificates
                reason = " ".join(str(exc).split())[:200] or type(exc).__name__
                raise ModelError(f"cannot reach the Dask scheduler at {self.scheduler}: {reason}",
                                 field="scheduler") from None
            self.owned = [client]
            return client
        import dask

        workers = self.workers or os.cpu_count() or 1
        with dask.config.set(WORKER_ENVIRONMENT):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=":0", silence_logs=logging.ERROR)
        client = Client(cluster)
        self.owned = [client, cluster]
        return client

    def __exit__(self, *exc):
        for thing in self.owned:
            thing.close()
        return False
