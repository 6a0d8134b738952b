"""Compiled modules of this test folder go to a fresh cache, never the user's."""

import pytest


@pytest.fixture(scope="session", autouse=True)
def _numerics_cache(tmp_path_factory):
    import os

    previous = os.environ.get("LAGRANGIAN_CACHE")
    os.environ["LAGRANGIAN_CACHE"] = str(tmp_path_factory.mktemp("lagrangian-cache"))
    yield
    if previous is None:
        os.environ.pop("LAGRANGIAN_CACHE", None)
    else:
        os.environ["LAGRANGIAN_CACHE"] = previous
