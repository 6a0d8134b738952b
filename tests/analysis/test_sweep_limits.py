"""Bounded cost with a clear message (issue 21): a study's size, the product of its axes
included, its memory and its worker count are checked before any work, and a scheduler address
that Dask cannot use is one line."""

from __future__ import annotations

import pytest


def one_error_line(result, *words):
    assert result.code == 2, result.err
    assert result.err.count("\n") == 1 and result.err.startswith("error: "), result.err
    for word in words:
        assert word in result.err, result.err


def test_the_product_of_the_axes_is_capped_before_any_work(cli):
    result = cli("sweep", "double_pendulum", "--compute", "simulate", "--t-end", "1",
                 "--vary", "m1=1:2:10000", "--vary", "m2=1:2:10000", "--vary", "l1=1:2:100")
    one_error_line(result, "10000 x 10000 x 100", "at most 10,000,000")


def test_a_trajectory_study_too_big_for_memory_is_refused_before_any_work(cli):
    result = cli("sweep", "double_pendulum", "--compute", "simulate", "--t-end", "1",
                 "--vary", "m1=1:2:1000", "--vary", "m2=1:2:1000", "--trajectories")
    one_error_line(result, "GiB", "fewer time samples")


def test_one_axis_over_the_cap_is_refused_before_its_values_exist(cli):
    one_error_line(cli("sweep", "two_mass", "--vary", "k=1:2:100000000000"), "at most")


@pytest.mark.parametrize("workers", ["0", "1000"])
def test_workers_are_bounded(cli, workers):
    one_error_line(cli("sweep", "two_mass", "--vary", "k=1:2:2", "--workers", workers),
                   "--workers")


@pytest.mark.parametrize("address", ["ucx://127.0.0.1:1", "ws://127.0.0.1:1", "tls://127.0.0.1:1"])
def test_a_scheduler_address_dask_cannot_use_is_one_line(cli, address):
    one_error_line(cli("sweep", "two_mass", "--vary", "k=1:2:2", "--scheduler", address),
                   "--scheduler")
