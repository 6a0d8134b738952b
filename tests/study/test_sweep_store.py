"""Outputs never destroy (issue 21): a study's --out that holds anything but a study of ours is
refused in one line before any work, --resume keeps finished chunks, refuses a store it cannot
read with nothing deleted, and checks each chunk's identity before merging it."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.output.sweep import is_study, read_study

distributed = pytest.importorskip("dask.distributed")

VARY = {"k": np.linspace(1, 9, 9), "k_c": [0.5, 1.5]}


@pytest.fixture(scope="module")
def two_mass():
    return lagrangian.load("two_mass")


def tree(path):
    return sorted((str(p.relative_to(path)), p.read_bytes() if p.is_file() else None)
                  for p in path.rglob("*"))


def one_error_line(result, *words):
    assert result.code == 2, result.err
    assert result.err.count("\n") == 1 and result.err.startswith("error: "), result.err
    for word in words:
        assert word in result.err


@pytest.mark.parametrize("name", ["study.zarr", "study.nc"])
def test_an_existing_output_that_is_not_a_study_is_refused_and_kept(cli, tmp_path, name):
    out = tmp_path / name
    if name.endswith(".zarr"):
        out.mkdir()
        (out / "thesis.tex").write_text("years of work")
        (out / "data").mkdir()
        (out / "data" / "run.csv").write_text("1,2,3")
    else:
        out.write_text("not a study")
    before = tree(tmp_path)
    result = cli("sweep", "two_mass", "--vary", "k=1:2:2", "--compute", "modes", "--out", str(out))
    one_error_line(result, str(out), "not a study written by lagrangian")
    assert tree(tmp_path) == before


def test_a_link_as_output_is_refused(cli, tmp_path):
    target = tmp_path / "elsewhere"
    target.mkdir()
    (tmp_path / "study.zarr").symlink_to(target)
    result = cli("sweep", "two_mass", "--vary", "k=1:2:2", "--compute", "modes",
                 "--out", str(tmp_path / "study.zarr"))
    one_error_line(result, "symbolic link")


@pytest.mark.parametrize("name", ["study.zarr", "study.nc"])
def test_our_own_study_is_replaced_by_a_new_run(client, two_mass, tmp_path, name):
    """k varies: omega_1 = sqrt(k/m) with m = 1 (two_mass's value)."""
    out = tmp_path / name
    two_mass.sweep({"k": [1.0, 4.0]}, compute="modes", client=client, out=out)
    assert is_study(out)
    two_mass.sweep({"k": [9.0, 16.0]}, compute="modes", client=client, out=out)
    np.testing.assert_allclose(read_study(out)["frequency"].sel(mode=1), [3.0, 4.0], rtol=1e-12)
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]  # no temporary left behind


def interrupted(client, two_mass, tmp_path):
    """A study interrupted after some chunks: its output and its partial store."""
    out = tmp_path / "study.nc"

    def interrupt(done, total):
        if done >= 8:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        two_mass.sweep(VARY, compute="modes", client=client, chunk_size=4, out=out,
                       progress=interrupt)
    partial = tmp_path / "study.nc.partial"
    assert len(list(partial.glob("chunk-*.npz"))) >= 2
    return out, partial


def resume(client, two_mass, out):
    return two_mass.sweep(VARY, compute="modes", client=client, chunk_size=4, out=out,
                          resume=True)


def test_resume_without_a_readable_manifest_is_refused_and_nothing_deleted(client, two_mass,
                                                                           tmp_path):
    out, partial = interrupted(client, two_mass, tmp_path)
    (partial / "study.json").unlink()
    before = tree(partial)
    with pytest.raises(ModelError, match="missing or unreadable.*nothing was deleted"):
        resume(client, two_mass, out)
    assert tree(partial) == before
    (partial / "study.json").write_text("{not json")
    with pytest.raises(ModelError, match="missing or unreadable"):
        resume(client, two_mass, out)
    assert (partial / "study.json").read_text() == "{not json"


@pytest.mark.parametrize("damage", ["truncated", "not npz", "swapped", "edited", "pickled"])
def test_a_damaged_or_foreign_chunk_is_refused_before_merging(client, two_mass, tmp_path,
                                                               damage):
    out, partial = interrupted(client, two_mass, tmp_path)
    chunks = sorted(partial.glob("chunk-*.npz"))
    first, second = chunks[0], chunks[1]
    if damage == "truncated":
        first.write_bytes(first.read_bytes()[:100])
    elif damage == "not npz":
        first.write_text("hello")
    elif damage == "swapped":
        a, b = first.read_bytes(), second.read_bytes()
        first.write_bytes(b)
        second.write_bytes(a)
    elif damage == "edited":
        with np.load(first) as data:
            arrays = {k: data[k] for k in data.files}
        arrays["frequency"] = arrays["frequency"] * 2
        np.savez(first, **arrays)
    else:
        with np.load(first) as data:
            arrays = {k: data[k] for k in data.files}
        arrays["status"] = np.array(list(arrays["status"]), dtype=object)
        np.savez(first, **arrays)
    before = tree(partial)
    with pytest.raises(ModelError, match=r"chunk-\d+\.npz: .*nothing was merged or deleted"):
        resume(client, two_mass, out)
    assert tree(partial) == before


def test_resume_keeps_finished_chunks_and_equals_a_straight_run(client, two_mass, tmp_path):
    straight = two_mass.sweep(VARY, compute="modes", client=client, chunk_size=4)
    out, partial = interrupted(client, two_mass, tmp_path)
    kept = {p.name: p.read_bytes() for p in partial.glob("chunk-*.npz")}
    seen = []
    resumed = two_mass.sweep(VARY, compute="modes", client=client, chunk_size=4, out=out,
                             resume=True, progress=lambda done, total: seen.append(done))
    starts = [int(name.split("-")[1].split(".")[0]) for name in kept]
    assert seen[0] == sum(min(start + 4, 18) - start for start in starts)  # kept, not rerun
    assert resumed.equals(straight)
    assert not partial.exists()


def test_a_partial_store_with_foreign_files_is_not_replaced(client, two_mass, tmp_path):
    out, partial = interrupted(client, two_mass, tmp_path)
    (partial / "notes.txt").write_text("mine")
    with pytest.raises(ModelError, match="not a store of lagrangian"):
        two_mass.sweep(VARY, compute="modes", client=client, chunk_size=4, out=out)
    assert (partial / "notes.txt").read_text() == "mine"
    shutil.rmtree(partial)
