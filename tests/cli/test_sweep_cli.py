"""`lagrangian sweep`: a study on a running (in-process) Dask scheduler, its files and summary,
and one-line errors naming the flag for bad input."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from lagrangian.output.sweep import read_study

distributed = pytest.importorskip("dask.distributed")


@pytest.fixture(scope="module")
def scheduler():
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=2,
                            dashboard_address=":0") as client:
        yield client.scheduler.address


def test_modes_study_written_and_summarized(cli, scheduler, tmp_path):
    """Two masses: omega1 = sqrt(k/m), over k = 10..100 N/m (46 values) and m = 1, 2, 5 kg."""
    out, plot = tmp_path / "study.nc", tmp_path / "study.png"
    code, stdout, err = cli("sweep", "two_mass", "--vary", "k=10:100:46", "--vary", "m=1,2,5kg",
                            "--compute", "modes", "--out", str(out), "--plot", str(plot),
                            "--json", "--scheduler", scheduler)
    assert code == 0, err
    summary = json.loads(stdout)
    assert summary["dimensions"] == {"k": 46, "m": 3}
    assert summary["ok"] == 138 and summary["missing"] == {}
    assert summary["frequency"]["min"] == pytest.approx(math.sqrt(10 / 5))
    ds = read_study(out)
    np.testing.assert_allclose(ds["frequency"].sel(mode=1, m=2.0),
                               np.sqrt(np.linspace(10, 100, 46) / 2), rtol=1e-12)
    assert plot.stat().st_size > 1000
    assert not (tmp_path / "study.nc.partial").exists()


def test_equilibria_with_units_and_zarr(cli, scheduler, tmp_path):
    out = tmp_path / "pitchfork.zarr"
    code, stdout, err = cli("sweep", "bead_on_hoop", "--vary", "Omega=2:8:4", "--compute",
                            "equilibria", "--out", str(out), "--scheduler", scheduler)
    assert code == 0, err
    assert "equilibria of 'Bead on a rotating hoop' over Omega 4" in stdout
    ds = read_study(out)
    critical = math.sqrt(9.81 / 0.5)
    np.testing.assert_array_equal(ds["count"], [2 if w < critical else 4
                                                for w in np.linspace(2, 8, 4)])


def test_ensemble(cli, scheduler, tmp_path):
    out = tmp_path / "ensemble.nc"
    code, stdout, err = cli("sweep", "double_pendulum", "--compute", "simulate", "--t-end", "1",
                            "--sample", "theta1=normal(0.3,0.01)", "--members", "4",
                            "--vary", "theta2=0deg,10deg", "--out", str(out), "--json",
                            "--scheduler", scheduler, "--trajectories", "--time-samples", "11")
    assert code == 0, err
    ds = read_study(out)
    assert ds["trajectory"].shape == (2, 4, 11, 4)
    np.testing.assert_allclose(ds["theta2"], [0, math.radians(10)])
    assert float(ds["invariant_drift"].max()) < 1e-6
    assert json.loads(stdout)["ok"] == 8


@pytest.mark.parametrize("args, flag", [
    (["--vary", "kk=1,2"], "--vary"),
    (["--vary", "k=1:2"], "--vary k"),
    (["--vary", "k=1:2:two"], "--vary k"),
    (["--vary", "k=1:2:0"], "--vary k"),
    (["--vary", "k=1,,2"], "--vary k"),
    (["--vary", "k=1kg:2:3"], "--vary k"),
    (["--vary", "k"], "--vary"),
    (["--vary", "k=1,2", "--out", "study.csv"], "--out"),
    (["--vary", "k=1,2", "--plot", "study.jpg"], "--plot"),
    (["--vary", "k=1,2", "--resume"], "--resume"),
    (["--vary", "k=1,2", "--compute", "spectrum"], "--compute"),
    (["--compute", "simulate", "--sample", "x1=gauss(0,1)", "--members", "3", "--t-end", "1"],
     "--sample x1"),
    (["--compute", "simulate", "--sample", "x1=normal(0,1)", "--t-end", "1"], "--members"),
    (["--compute", "simulate", "--vary", "x1=0,1"], "--t-end"),
    (["--compute", "simulate", "--vary", "x1=0,1", "--t-end", "-1"], "--t-end"),
    (["--compute", "simulate", "--vary", "x1=0,1", "--t-end", "1", "--method", "Euler"],
     "--method"),
    ([], "--vary"),
    (["--vary", "k=1,2", "--scheduler", "notanaddress"], "--scheduler"),
])
def test_bad_input_one_line_naming_the_flag(cli, args, flag, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, stdout, err = cli("sweep", "two_mass", *args)
    assert code == 2, (stdout, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert flag in lines[0], lines[0]
    assert "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_the_old_samples_flag_still_sets_the_members_with_one_deprecation_line(cli):
    """--samples meant ensemble members in sweep and time samples in simulate: now --members."""
    code, stdout, err = cli("sweep", "two_mass", "--compute", "simulate", "--t-end", "0.1",
                            "--sample", "x1=normal(0,0.01)", "--samples", "2", "--json",
                            "--workers", "1")
    assert code == 0, err
    assert err.startswith("warning: --samples of a sweep is now --members")
    assert json.loads(stdout)["dimensions"] == {"member": 2}
