"""`lagrangian sweep --lock NAME=VALUE` and System.sweep on a locked URDF arm: the locked model
reaches the Dask workers, so the study equals the single-point modes of the locked model."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import lagrangian
from lagrangian.output.sweep import read_study

distributed = pytest.importorskip("dask.distributed")

ELBOW = 0.3
GRAVITY = [1.62, 3.71, 9.81]


def locked_growth_rate(g: float) -> float:
    """The two-link arm (example) with its elbow locked is one rigid body about the shoulder:
    I = M11(elbow) = 2.54 + 1.2 cos(elbow) kg m^2, first moment |2 kg 0.5 m + 1.5 kg (1 m +
    0.4 m e^(i elbow))|; upright it falls away at the rate sqrt(g |h| / I) (1/s)."""
    moment = abs(2.0 * 0.5 + 1.5 * 1.0 + 1.5 * 0.4 * complex(math.cos(ELBOW), math.sin(ELBOW)))
    return math.sqrt(g * moment / (2.54 + 1.2 * math.cos(ELBOW)))


@pytest.fixture(scope="module")
def scheduler():
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=2,
                            dashboard_address=":0") as client:
        yield client


def single_point_growth(g: float) -> float:
    arm = lagrangian.load("two_link_arm", lock={"elbow": ELBOW}).with_parameters(g=g)
    modes = arm.modes()
    assert len(modes.modes) == 1
    return modes.modes[0].growth_rate


def test_sweep_with_a_locked_elbow_equals_the_locked_modes(cli, scheduler, tmp_path):
    out = tmp_path / "locked.nc"
    code, stdout, err = cli("sweep", "two_link_arm", "--lock", f"elbow={ELBOW}", "--vary",
                            "g=" + ",".join(map(str, GRAVITY)), "--compute", "modes",
                            "--out", str(out), "--json", "--scheduler",
                            scheduler.scheduler.address)
    assert code == 0, err
    assert json.loads(stdout)["dimensions"] == {"g": 3}
    ds = read_study(out)
    assert ds.sizes["mode"] == 1  # one coordinate left: the shoulder
    growth = ds["growth_rate"].sel(mode=1).values
    np.testing.assert_allclose(growth, [single_point_growth(g) for g in GRAVITY], rtol=1e-9)
    np.testing.assert_allclose(growth, [locked_growth_rate(g) for g in GRAVITY], rtol=1e-9)


def test_system_sweep_of_a_locked_arm(scheduler):
    arm = lagrangian.load("two_link_arm", lock={"elbow": ELBOW})
    ds = arm.sweep({"g": GRAVITY}, "modes", client=scheduler)
    np.testing.assert_allclose(ds["growth_rate"].sel(mode=1).values,
                               [locked_growth_rate(g) for g in GRAVITY], rtol=1e-9)


def test_sweep_bad_lock_is_one_line(cli):
    code, _, err = cli("sweep", "two_link_arm", "--lock", "elbw=0.1", "--vary", "g=1,2")
    assert code == 2
    assert err.strip().count("\n") == 0 and "did you mean 'elbow'" in err
    code, _, err = cli("sweep", "pendulum", "--lock", "x=1", "--vary", "g=1,2")
    assert code == 2 and "only a URDF model has joints to lock" in err
