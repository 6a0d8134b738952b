"""Steady motion in parameter studies (issue 21): compute='speeds' gives the eigenvalues of the
reduced equations about the model's [steady] motion at each point, equal to System.speed_sweep,
with the benchmark bicycle's self-stable range; a study of a parameter the equations do not
contain is refused (alone) or warned about (beside others)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import ModelError

distributed = pytest.importorskip("dask.distributed")

# The benchmark bicycle's weave and capsize speeds (Basu-Mandal, Chatterjee and Papadopoulos
# 2007, to 14 digits; Meijaard et al. 2007 give 4.292 and 6.024)
WEAVE, CAPSIZE = 4.29238253634111, 6.02426201538837


@pytest.fixture(scope="module")
def bicycle():
    return lagrangian.load("whipple_bicycle")


def test_speeds_study_equals_the_speed_sweep_and_the_benchmark(client, bicycle):
    speeds = np.linspace(0.0, 10.0, 41)
    ds = bicycle.sweep({"v": speeds}, compute="speeds", client=client)
    assert (ds["status"] == "ok").all()
    form = bicycle.speed_form()
    eigenvalues = ds["eigenvalue_real"].values + 1j * ds["eigenvalue_imag"].values
    for i, v in enumerate(speeds):
        np.testing.assert_allclose(eigenvalues[i], form.eigenvalues(v), rtol=1e-9, atol=1e-9)
    stable = ds["stable"].values == 1
    np.testing.assert_array_equal(stable, (speeds > WEAVE) & (speeds < CAPSIZE))


def test_a_second_parameter_refits_the_form(client, bicycle):
    """Heavier rider, other eigenvalues: each point equals the single-point API."""
    ds = bicycle.sweep({"v": [3.0, 5.0], "mB": [85.0, 100.0]}, compute="speeds", client=client)
    for j, mass in enumerate([85.0, 100.0]):
        form = bicycle.with_parameters(mB=mass).speed_form()
        for i, v in enumerate([3.0, 5.0]):
            point = ds.isel(v=i, mB=j)
            np.testing.assert_allclose(point["eigenvalue_real"] + 1j * point["eigenvalue_imag"],
                                       form.eigenvalues(v), rtol=1e-9, atol=1e-9)


def test_varying_only_a_parameter_the_equations_lack_is_refused(bicycle):
    with pytest.raises(ModelError, match="'v' does not appear in the equations.*speeds"):
        bicycle.sweep({"v": [1.0, 2.0]}, compute="modes")


def test_a_parameter_the_equations_lack_beside_others_is_a_warning(cli, tmp_path):
    """k is in the equations, c is declared but used nowhere: one warning line, in JSON too."""
    model = tmp_path / "spring.toml"
    model.write_text('[coordinates]\nx = { initial = 0.1 }\n[parameters]\nm = 1.0\nk = 4.0\n'
                     'c = 0.5\n[energy]\nT = "m*x_dot^2/2"\nV = "k*x^2/2"\n')
    result = cli("sweep", str(model), "--vary", "k=1,4", "--vary", "c=1,2", "--workers", "1",
                 "--json")
    assert result.code == 0, result.err
    assert result.err == ("warning: 'c' does not appear in the equations of motion: its values "
                          "change nothing\n")
    summary = json.loads(result.out)
    assert summary["warnings"] == [result.err[len("warning: "):].strip()]
    assert summary["frequency"] == {"min": 1.0, "max": 2.0}  # omega = sqrt(k/m)
    alone = cli("sweep", str(model), "--vary", "c=1,2")
    assert alone.code == 2 and "'c' does not appear" in alone.err


def test_speeds_on_a_model_without_steady_motion_is_one_line(cli):
    result = cli("sweep", "two_mass", "--compute", "speeds", "--vary", "k=1,2")
    assert result.code == 2 and result.err.count("\n") == 1
    assert "[steady]" in result.err
