"""Where example-robot-data's URDFs are: installed beside Pinocchio (its wheels' cmeel prefix),
for the tests that compare with Pinocchio; a test skips where either is missing."""

from __future__ import annotations

from pathlib import Path

import pytest


def robots(pin=None) -> Path:
    """The robots/ folder of example-robot-data (``pin``: the pinocchio module, if imported)."""
    pin = pin or pytest.importorskip("pinocchio")
    for parent in Path(pin.__file__).resolve().parents:
        candidate = parent / "share/example-robot-data/robots"
        if candidate.is_dir():
            return candidate
    pytest.skip("example-robot-data is not installed")
