"""Generated C is built only from identifiers the project makes itself (issue 21): a model's
name, from the whole Unicode range or made of C's own special sequences, changes nothing but an
inert comment, and the exploit of the issue (a name closing the comment and declaring a
constructor) compiles to a module whose code is the plain one's and runs nothing."""

from __future__ import annotations

import dataclasses
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import lagrangian
from lagrangian.compile import codegen, compiled
from lagrangian.dynamics.standalone.standalone import c_prefix, standalone_c

needs_c = pytest.mark.skipif(not compiled.available(), reason="no C compiler / Python headers")

EXPLOIT = ('pend */ int system(const char *); __attribute__((constructor)) static void f(void)'
           '{ system("id > out.txt"); } /*')
C_SPECIALS = ["*/", "/*", "//", "\\", "\n", "\r", "\"", "'", "??/", "??=", "#", "#define X",
              "\x00", "\u2028", "\u202e", "`", "$(id)", "{", "}", ";"]

names = st.one_of(
    st.text(st.characters(codec=None, exclude_categories=("Cs",)), max_size=40),
    st.lists(st.sampled_from(C_SPECIALS + ["pend", " ", "a"]), max_size=12).map("".join),
    st.just(EXPLOIT),
)


@pytest.fixture(scope="module")
def double_pendulum_eom():
    return lagrangian.load("double_pendulum").equations_of_motion()


def renamed(eom, name: str):
    return dataclasses.replace(eom, model=dataclasses.replace(eom.model, name=name))


def without_comments(source: str) -> str:
    return re.sub(r"/\*.*?\*/", "", source, flags=re.S)


def comments_are_inert(source: str) -> None:
    """Every comment closes where the generator closed it and holds nothing C could act on."""
    for comment in re.findall(r"/\*(.*?)\*/", source, flags=re.S):
        assert "/*" not in comment
        assert "??" not in comment


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(name=names)
def test_a_name_changes_only_an_inert_comment_of_the_module(double_pendulum_eom, name):
    plain = codegen.generate(renamed(double_pendulum_eom, "plain")).source
    hostile = codegen.generate(renamed(double_pendulum_eom, name)).source
    assert without_comments(hostile) == without_comments(plain)
    comments_are_inert(hostile)
    assert hostile.isascii()
    shown = re.search(r"generated C for model '(.*)' \(2 coordinates", hostile).group(1)
    assert re.fullmatch(r"[A-Za-z0-9 _.,:;+=()\[\]-]*", shown)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(name=names)
def test_standalone_c_takes_an_ascii_identifier_from_any_name(double_pendulum_eom, name):
    prefix = c_prefix(name)
    assert re.fullmatch(r"[a-z][a-z0-9_]{0,42}", prefix)
    code = standalone_c(renamed(double_pendulum_eom, name), {"m1": 1, "m2": 1, "l1": 1, "l2": 1,
                                                             "g": 9.81})
    plain = standalone_c(renamed(double_pendulum_eom, "plain"), {"m1": 1, "m2": 1, "l1": 1,
                                                                 "l2": 1, "g": 9.81}, prefix)
    for ours, reference in ((code.header, plain.header), (code.source, plain.source)):
        assert without_comments(ours) == without_comments(reference)
        comments_are_inert(ours)
        assert ours.isascii()


@needs_c
def test_the_exploit_name_runs_nothing_on_simulate(tmp_path):
    """The issue's reproducer: the name closes the comment and declares a constructor."""
    model = tmp_path / "evil.toml"
    model.write_text(
        "name = '''" + EXPLOIT + "'''\n"
        '[coordinates]\ntheta = { initial = 0.3 }\n'
        '[parameters]\nm = 1.0\nL = 0.5\ng = 9.81\n'
        '[energy]\nT = "1/2*m*L^2*theta_dot^2"\nV = "-m*g*L*cos(theta)"\n')
    cache = tmp_path / "cache"
    done = subprocess.run([sys.executable, "-m", "lagrangian", "simulate", str(model),
                           "--t-end", "0.2"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300, env=dict(os.environ, LAGRANGIAN_CACHE=str(cache)))
    assert done.returncode == 0, done.stderr
    assert not (tmp_path / "out.txt").exists()
    sources = list(cache.glob("lg_*.c"))
    assert sources and all("system(" not in without_comments(p.read_text()) for p in sources)


@needs_c
def test_the_exploit_name_through_codegen_writes_inert_c(tmp_path):
    model = tmp_path / "evil.urdf"
    model.write_text(Path(lagrangian.__file__).with_name("model").joinpath(
        "examples", "two_link_arm.urdf").read_text().replace(
        'name="two_link_arm"', f'name="{EXPLOIT.replace(chr(34), "&quot;")}"', 1))
    done = subprocess.run([sys.executable, "-m", "lagrangian", "codegen", str(model), "--lang",
                           "c", "--out", str(tmp_path / "out")], capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    written = sorted((tmp_path / "out").iterdir())
    assert [p.suffix for p in written] == [".c", ".h"]
    for path in written:
        text = path.read_text()
        assert "system(" not in without_comments(text)
        comments_are_inert(text)
    # and it compiles as C: the prefix is an identifier of ours
    subprocess.run([*compiled.check_compiler(), "-std=c99", "-Wall", "-Werror", "-c",
                    str(written[0]), "-o", str(tmp_path / "x.o")], check=True, capture_output=True)
