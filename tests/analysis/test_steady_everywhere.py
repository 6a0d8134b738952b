"""Steady motion everywhere it belongs (issue 21): a modes study of a model with a [steady]
table is taken about that motion, as `lagrangian modes` takes it; the weave and capsize speeds
of the benchmark's published matrices are their sign changes (CLI: tests/cli/test_steady_cli.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import lagrangian
from lagrangian.analysis.speed_form import SpeedForm, speed_sweep

pytest.importorskip("dask.distributed")

# Meijaard, Papadopoulos, Ruina and Schwab (2007), the benchmark's lean-steer matrices (eq. A1
# values) and its weave and capsize speeds (to 14 digits, Basu-Mandal et al. 2007)
PUBLISHED = {
    "M": [[80.81722, 2.31941332208709], [2.31941332208709, 0.29784188199686]],
    "C1": [[0.0, 33.86641391492494], [-0.85035641456978, 1.68540397397560]],
    "K0": [[-80.95, -2.59951685249872], [-2.59951685249872, -0.80329488458618]],
    "K2": [[0.0, 76.59734589573222], [0.0, 2.65431523794604]],
}
WEAVE, CAPSIZE = 4.29238253634111, 6.02426201538837
# Table 2 at v = 5 m/s: capsize, weave, castor
AT_5 = [-0.32286642900409, -0.77534188219585 + 4.46486771378823j, -14.07838969279822]


def test_the_published_matrices_cross_at_the_published_speeds():
    """The crossing search on M, C1, K0, K2 as printed in the paper (no derivation involved)."""
    zero = np.zeros((2, 2))
    form = SpeedForm(("phi", "delta"), "v", 9.81, *(np.array(PUBLISHED[k]) for k in
                                                    ("M", "C1", "K0", "K2")), zero, zero, 0.0)
    sweep = speed_sweep(form, np.linspace(0.0, 10.0, 101))
    assert sweep.speed_of("oscillatory", stabilizing=True) == pytest.approx(WEAVE, rel=1e-12)
    assert sweep.speed_of("real", stabilizing=False) == pytest.approx(CAPSIZE, rel=1e-12)
    (stable,) = sweep.stable
    assert stable == pytest.approx((WEAVE, CAPSIZE), rel=1e-12)


def test_a_modes_study_of_the_bicycle_is_about_its_steady_motion(client):
    """At its [steady] speed of 5 m/s the benchmark bicycle is self-stable, with Table 2's
    weave (a complex pair) and capsize-castor (two real) eigenvalues; at rest it is not."""
    bicycle = lagrangian.load("whipple_bicycle")
    ds = bicycle.sweep({"rR": [0.3]}, compute="modes", client=client)
    assert (ds["status"] == "ok").all()
    point = ds.isel(rR=0)
    assert point["stable"] == 1
    frequency = point["frequency"].values
    growth = point["growth_rate"].values
    weave = AT_5[1]
    k = int(np.nanargmax(frequency))
    assert frequency[k] == pytest.approx(abs(weave), rel=1e-9)
    assert growth[k] == pytest.approx(weave.real, rel=1e-9)
    # capsize and castor, two real eigenvalues paired: the slower one sets the growth
    assert np.any(np.isclose(growth, AT_5[0], rtol=1e-9))
    assert np.any(np.isclose(frequency, math.sqrt(AT_5[0] * AT_5[2]), rtol=1e-9))
    # the same as `lagrangian modes whipple_bicycle` (its [steady] table)
    single = bicycle.modes()
    np.testing.assert_allclose(np.sort(frequency[np.isfinite(frequency)]),
                               np.sort([m.frequency for m in single.modes]), rtol=1e-9, atol=1e-9)

