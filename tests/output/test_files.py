"""Outputs are written atomically, with ordinary permissions, never over an input file."""

import os
import stat

import pytest

from lagrangian.output.files import atomic_write


def test_atomic_write_replaces_and_keeps_ordinary_permissions(tmp_path):
    target = tmp_path / "out" / "run.csv"
    atomic_write(target, "a,b\n")
    atomic_write(target, "c,d\n")
    assert target.read_text() == "c,d\n"
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~umask
    assert [p.name for p in target.parent.iterdir()] == ["run.csv"]  # no temporary left


def test_atomic_write_refuses_to_overwrite_an_input(tmp_path):
    model = tmp_path / "model.toml"
    model.write_text("name = 'x'\n")
    with pytest.raises(FileExistsError, match="refusing to overwrite an input file"):
        atomic_write(model, "oops", protect=(model,))
    assert model.read_text() == "name = 'x'\n"
