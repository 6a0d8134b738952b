"""Trust at the seams: every input file is size- and kind-checked before it is read, and a class
folder gives only its own regular files, each name shown escaped (one row, one line)."""

from __future__ import annotations

import csv
import io
import json
import os
import subprocess
import sys
import threading
import time
import tracemalloc

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lagrangian.errors import ModelError
from lagrangian.model.examples import example_path
from lagrangian.model.reader import MAX_TEXT_FILE_BYTES, read_model, read_text_file

RIGHT = '[energy]\nV = "-m*g*L*cos(theta)"\n'
posix_only = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs and symlinks")


def within(seconds, work):
    """work()'s exception (or None), failing the test if it has not ended in ``seconds``."""
    outcome = []

    def run():
        try:
            work()
            outcome.append(None)
        except Exception as exc:  # noqa: BLE001 - the test looks at it
            outcome.append(exc)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(seconds)
    assert outcome, f"still running after {seconds} s"
    return outcome[0]


@pytest.fixture
def huge(tmp_path):
    path = tmp_path / "huge.toml"
    with open(path, "wb") as f:
        f.truncate(3 * 2**30)  # sparse: no disk
    return path


def test_a_file_over_the_limit_is_refused_before_it_is_read(huge):
    tracemalloc.start()
    start = time.perf_counter()
    with pytest.raises(ModelError) as caught:
        read_model(huge)
    elapsed = time.perf_counter() - start
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    message = str(caught.value)
    assert message.startswith(str(huge)) and "3 GiB" in message and "16 MiB" in message
    assert "\n" not in message and elapsed < 1 and peak < 2**20


def test_a_file_at_the_limit_is_read(tmp_path):
    path = tmp_path / "at_limit.toml"
    with open(path, "wb") as f:
        f.truncate(MAX_TEXT_FILE_BYTES)
    assert len(read_text_file(path)) == MAX_TEXT_FILE_BYTES


@posix_only
def test_a_fifo_a_device_and_a_folder_are_refused_without_waiting(tmp_path):
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    folder = tmp_path / "folder.toml"
    folder.mkdir()
    for path, kind in ((fifo, "FIFO"), ("/dev/zero", "device"), (folder, "directory")):
        error = within(5, lambda path=path: read_text_file(path))
        assert isinstance(error, ModelError)
        assert str(error).startswith(str(path)) and "not a regular file" in str(error)
        assert kind in str(error)


@posix_only
def test_a_link_is_refused_only_when_links_are_not_followed(tmp_path):
    (tmp_path / "real.toml").write_text(RIGHT)
    (tmp_path / "link.toml").symlink_to(tmp_path / "real.toml")
    assert read_text_file(tmp_path / "link.toml") == RIGHT
    with pytest.raises(ModelError, match="symbolic link"):
        read_text_file(tmp_path / "link.toml", follow_symlinks=False)


def test_newlines_are_read_as_before(tmp_path):
    (tmp_path / "crlf.toml").write_bytes(b'a = 1\r\nb = 2\rc = 3\n')
    assert read_text_file(tmp_path / "crlf.toml") == (tmp_path / "crlf.toml").read_text()


def test_check_refuses_a_huge_answer_file_in_one_line_at_once(cli, huge):
    cli("check", "pendulum", "nothere.toml")  # imports warm, as in a fresh process's start
    start = time.perf_counter()
    code, out, err = cli("check", "pendulum", str(huge))
    assert time.perf_counter() - start < 1
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("error: ") and "3 GiB" in err
    code, out, _ = cli("check", "pendulum", str(huge), "--json")
    assert code == 2 and json.loads(out)["verdict"] == "unreadable"


@posix_only
@pytest.mark.parametrize("kind", ["fifo", "device"])
def test_check_refuses_a_fifo_or_a_device_as_the_answer_or_the_model(tmp_path, kind):
    if kind == "fifo":
        path = tmp_path / "answer.toml"
        os.mkfifo(path)
    else:
        path = "/dev/zero"
    model = tmp_path / "model.toml"
    model.write_text(example_path("pendulum").read_text())
    for args in ((str(model), str(path)), (str(path), str(model))):
        done = subprocess.run([sys.executable, "-m", "lagrangian", "check", *args],
                              capture_output=True, text=True, timeout=60)
        assert done.returncode == 2 and done.stdout == ""
        assert done.stderr.count("\n") == 1 and "not a regular file" in done.stderr


@pytest.fixture
def klass(tmp_path):
    """A class folder: a good answer, a link to the key (outside), a link to a TOML holding a
    secret, a name with a newline; the key itself is right, so grading it would pass."""
    if not hasattr(os, "mkfifo"):
        pytest.skip("needs FIFOs and symlinks")
    (tmp_path / "model.toml").write_text(example_path("pendulum").read_text())
    (tmp_path / "key.toml").write_text(RIGHT)
    (tmp_path / "secrets.toml").write_text('API_TOKEN = "s3cr3t-value"\n')
    folder = tmp_path / "class"
    folder.mkdir()
    (folder / "good.toml").write_text(RIGHT)
    (folder / "key.toml").symlink_to(tmp_path / "key.toml")
    (folder / "secret.toml").symlink_to(tmp_path / "secrets.toml")
    (folder / "a\nb.toml").write_text(RIGHT)
    return folder


def test_a_class_folder_grades_only_its_own_regular_files(klass):
    import lagrangian

    report = lagrangian.load(str(klass.parent / "model.toml")).check_many(klass)
    verdicts = {r.file.rsplit("/", 1)[-1]: r.verdict for r in report}
    assert verdicts == {"a\\nb.toml": "correct", "good.toml": "correct",
                        "key.toml": "unreadable", "secret.toml": "unreadable"}
    for r in report:
        if r.verdict == "unreadable":
            assert r.error.startswith(r.file) and "symbolic link" in r.error


def test_a_link_inside_the_folder_and_a_fifo_are_refused_too(klass):
    import lagrangian

    (klass / "copy.toml").symlink_to(klass / "good.toml")
    os.mkfifo(klass / "pipe.toml")
    system = lagrangian.load(str(klass.parent / "model.toml"))
    reports = []
    assert within(30, lambda: reports.append(system.check_many(klass))) is None
    report = reports[0]
    verdicts = {r.file.rsplit("/", 1)[-1]: r.verdict for r in report}
    assert verdicts["copy.toml"] == "unreadable" and verdicts["pipe.toml"] == "unreadable"
    by_glob = system.check_many(str(klass / "*.toml"))
    assert [r.verdict for r in by_glob] == [r.verdict for r in report]


def test_a_lone_file_is_read_through_its_link_a_class_named_file_by_file_is_not(klass, cli):
    import lagrangian

    system = lagrangian.load(str(klass.parent / "model.toml"))
    assert system.check(klass / "key.toml").passed  # one answer, named: read as named
    # the shell's `class/*.toml` names each file: the link to the key is not graded 'correct',
    # the link to the secrets not read (its API_TOKEN was echoed), a link to a folder not entered
    (klass / "here.toml").symlink_to(klass)
    named = sorted(klass.iterdir())
    report = system.check_many(named)
    verdicts = {r.file.rsplit("/", 1)[-1]: r.verdict for r in report}
    assert verdicts == {"a\\nb.toml": "correct", "good.toml": "correct", "here.toml": "unreadable",
                        "key.toml": "unreadable", "secret.toml": "unreadable"}
    code, text, err = cli("check", str(klass.parent / "model.toml"), *map(str, named))
    assert code == 2 and "API_TOKEN" not in text + err and text.count("symbolic link") == 3


def test_the_class_outputs_never_show_a_refused_file_nor_forge_a_row(cli, klass, tmp_path):
    model = str(klass.parent / "model.toml")
    grades = tmp_path / "grades.csv"
    code, text, err = cli("check", model, str(klass), "--csv", str(grades))
    _, document, _ = cli("check", model, str(klass), "--json")
    table = grades.read_text()
    assert code == 2
    for output in (text, err, document, table):
        assert "API_TOKEN" not in output and "s3cr3t" not in output
    rows = [line for line in text.splitlines() if line.startswith("  ")]
    assert len(rows) == 4 and sum("a\\nb.toml" in row for row in rows) == 1
    assert not any(line.startswith("b.toml") for line in text.splitlines())
    files = [r["file"] for r in json.loads(document)["records"]]
    assert sum(f.endswith("a\\nb.toml") for f in files) == 1 and not any("\n" in f for f in files)
    lines = table.splitlines()
    assert len(lines) == 1 + 4  # a header, one record per file (each has one item or none)
    cells = [row[0] for row in csv.reader(io.StringIO(table))][1:]
    assert sum(c.endswith("a\\nb.toml") for c in cells) == 1


_NAME = st.text(st.characters(blacklist_categories=("Cs",), blacklist_characters="/\0."),
                min_size=1, max_size=20)


@posix_only
@settings(max_examples=25, deadline=None)
@given(names=st.lists(_NAME, min_size=1, max_size=3, unique=True))
def test_any_names_give_one_line_each_in_the_table(tmp_path_factory, names):
    from check_helpers import system

    from lagrangian.output.check import class_text

    folder = tmp_path_factory.mktemp("names")
    written = []
    for name in names:
        try:
            (folder / f"{name}.toml").write_text(RIGHT)
            written.append(name)
        except OSError:  # a name the file system refuses (too long in bytes)
            continue
    report = system("pendulum").check_many(folder)
    assert len(report) == len(written)
    text = class_text(report)
    assert len(text.splitlines()) == len(written) + 2
    assert len(report.csv_text().splitlines()) == len(written) + 1
