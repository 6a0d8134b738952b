"""Steady motion at the command line (issue 21): a steady top solved into its z-x-z singularity
is one error line, never 'stable'; `equilibria` of a model with a [steady] table says that its
equilibria are at rest and where the steady motion is studied; a modes sweep of it is about
that motion."""

from __future__ import annotations

import json

import pytest


def test_a_steady_top_solved_into_gimbal_lock_is_one_line(cli):
    """theta not given: the steady solver finds the sleeping top at theta = 0, where the z-x-z
    angles lose a rate; that is refused by name."""
    result = cli("modes", "heavy_top", "--steady", "psi_dot=60,phi_dot=0")
    assert result.code == 2
    assert result.err.count("\n") == 1 and result.err.startswith("error: ")
    assert "gimbal lock" in result.err
    for theta in ("1e-7", "0"):
        result = cli("modes", "heavy_top", "--about", f"theta={theta}", "--steady", "psi_dot=60")
        assert result.code == 2 and "gimbal lock" in result.err and "stable" not in result.out


def test_equilibria_of_a_steady_motion_model_point_to_its_steady_motion(cli):
    """The bicycle at rest, upright, falls over (unstable); its [steady] motion is named."""
    result = cli("equilibria", "whipple_bicycle")
    assert result.code == 0, result.err
    upright = [line for line in result.out.splitlines() if "phi = 0" in line and "delta = 0,"
               in line]
    assert upright and upright[0].endswith("unstable")
    assert "[steady] table names a steady motion" in result.out
    document = json.loads(cli("equilibria", "whipple_bicycle", "--json").out)
    assert set(document) == {"equilibria"}  # the JSON contract is unchanged


def test_a_modes_sweep_of_the_bicycle_is_self_stable_at_its_steady_speed(cli):
    distributed = pytest.importorskip("dask.distributed")
    # a scheduler in this process: its worker uses this process's derivation of the bicycle,
    # where a worker process of its own derives it again (3-4 s)
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=1,
                            dashboard_address=":0") as client:
        result = cli("sweep", "whipple_bicycle", "--vary", "rR=0.3", "--scheduler",
                     client.scheduler.address, "--json")
    assert result.code == 0, result.err
    summary = json.loads(result.out)
    assert summary["ok"] == 1 and summary["stable_points"] == 1
