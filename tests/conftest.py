"""Shared helpers: run the CLI in-process and capture output and exit status."""

from __future__ import annotations

import pytest

from lagrangian.cli import main


class CliResult:
    """Exit status and captured output of one CLI run; unpacks as (code, out, err)."""

    def __init__(self, code: int, out: str, err: str):
        self.code, self.out, self.err = code, out, err

    def __iter__(self):
        return iter((self.code, self.out, self.err))


@pytest.fixture
def cli(capsys):
    def run(*args: str) -> CliResult:
        try:
            main(list(args))
            code = 0
        except SystemExit as exc:
            code = int(exc.code or 0)
        captured = capsys.readouterr()
        return CliResult(code, captured.out, captured.err)

    return run


@pytest.fixture(scope="session", autouse=True)
def _compiled_module_cache(tmp_path_factory):
    """Compiled C modules of the test run go to a fresh cache, never the user's: one for the
    whole run, shared by pytest-xdist's workers (compiled.py locks each build, so a module is
    compiled once and the other worker loads it)."""
    import os

    previous = os.environ.get("LAGRANGIAN_CACHE")
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        cache = tmp_path_factory.mktemp("lagrangian-cache")
    else:  # the workers' base folders share the run's parent
        cache = tmp_path_factory.getbasetemp().parent / "lagrangian-cache"
        cache.mkdir(mode=0o700, exist_ok=True)
    os.environ["LAGRANGIAN_CACHE"] = str(cache)
    yield
    if previous is None:
        os.environ.pop("LAGRANGIAN_CACHE", None)
    else:
        os.environ["LAGRANGIAN_CACHE"] = previous


@pytest.fixture(scope="module")
def client():
    """An in-process Dask cluster (one worker, two threads) for the studies of one module."""
    distributed = pytest.importorskip("dask.distributed")
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=2,
                            dashboard_address=":0") as c:
        yield c
