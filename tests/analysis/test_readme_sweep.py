"""The sweep section (docs/getting-started/studies.md) shows real output: its commands re-run on
an in-process Dask scheduler print what the page shows, and its Python example runs."""

from __future__ import annotations

import re
import shlex

import pytest

import docs_blocks

distributed = pytest.importorskip("dask.distributed")


def section() -> str:
    return docs_blocks.block("sweep", "getting-started/studies.md")


def commands() -> list[tuple[list[str], str]]:
    """(arguments, the output shown) of each `$ lagrangian sweep ...` line."""
    found = []
    for block in re.findall(r"```console\n(.*?)```", section(), re.S):
        for piece in re.split(r"^\$ ", block, flags=re.M)[1:]:
            line, _, output = piece.partition("\n")
            found.append((shlex.split(line)[1:], output))
    return found


@pytest.fixture(scope="module")
def client():
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=2,
                            dashboard_address=":0") as c:
        yield c


@pytest.mark.parametrize("index", [pytest.param(0, marks=pytest.mark.slow), 1,
                                   pytest.param(2, marks=pytest.mark.slow)])
def test_console_output_is_current(cli, client, index, tmp_path, monkeypatch):
    args, shown = commands()[index]
    monkeypatch.chdir(tmp_path)
    code, out, err = cli(*args, "--scheduler", client.scheduler.address)
    assert code == 0, err
    assert_same_output(out, shown)


NUMBER = re.compile(r"[-+]?\d+(?:\.\d*)?(?:e[-+]?\d+)?")


def assert_same_output(out: str, shown: str) -> None:
    """The words exactly, the numbers to 4 significant digits: the ensembles' module is built
    for the processor (fused multiply-adds where it has them), so a chaotic member's last
    digits depend on the machine."""
    assert NUMBER.split(out) == NUMBER.split(shown), out
    for a, b in zip(NUMBER.findall(out), NUMBER.findall(shown), strict=True):
        assert float(a) == pytest.approx(float(b), rel=1e-4), out


def test_python_example_runs(client, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code = re.findall(r"```python\n(.*?)```", section(), re.S)[0]
    # The docs' script starts a local cluster; here it runs on the test's in-process one.
    code = code.replace('compute="modes")', 'compute="modes", client=client)')
    exec(compile(code, "sweep", "exec"), {"client": client, "__name__": "__main__"})  # noqa: S102
    assert "[2.23606798 2.44948974 2.64575131]" in capsys.readouterr().out
    assert (tmp_path / "study.nc").exists()
