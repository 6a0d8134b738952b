"""Hostile command lines (issue 14): one line `error: ...` and the right exit status, never a
traceback; a failed integration keeps its partial result and says where and why."""

from __future__ import annotations

import json

import pytest

SINGULAR_AT_ZERO = """
[coordinates]
x = { unit = "m", initial = 0.0, rate = 1.0 }
[energy]
T = "x^2*x_dot^2"
"""

QUARTIC = """
[coordinates]
x = { unit = "m", initial = 0.0, rate = 0.0 }
[energy]
T = "x_dot^4"
"""


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        # a traceback: "cannot reshape array of size 0" (the C loop failed at the first step)
        (("--set", "g=1e308"), "error: integration failed: Required step size is less than "
         "spacing between numbers at t = 0 s: the acceleration of theta is -5.91e+307 there, too "
         "large to integrate (check the parameters and initial values); partial result saved to "
         "{out}"),
        (("--initial", "theta_dot=1e300"), "error: integration failed: Required step size is "
         "less than spacing between numbers at t = 0 s: theta_dot = 1e+300 there is too large to "
         "integrate (check the parameters and initial values); partial result saved to {out}"),
    ],
)
def test_a_run_failing_at_the_first_step_keeps_the_start_and_says_why(cli, tmp_path, args,
                                                                      message):
    out = tmp_path / "run.csv"
    code, _, err = cli("simulate", "pendulum", "--t-end", "1", *args, "--out", str(out))
    assert code == 1
    assert one_line(err) == message.format(out=out)
    rows = out.read_text().splitlines()
    assert rows[0].startswith("t,theta,theta_dot") and rows[1].startswith("0.0,0.3,")


@pytest.mark.parametrize(("text", "name"), [(SINGULAR_AT_ZERO, "x2"), (QUARTIC, "x4")])
def test_a_mass_matrix_singular_at_the_start_is_named(cli, tmp_path, text, name):
    # M = 2 x^2 and 12 x_dot^2: both zero at the start
    model = tmp_path / f"{name}.toml"
    model.write_text(text)
    code, _, err = cli("simulate", str(model), "--t-end", "1")
    assert code == 1
    assert one_line(err) == "error: integration failed: Singular mass matrix at t = 0 s"


def test_a_sample_count_beyond_memory_is_refused_up_front(cli):
    code, out, err = cli("simulate", "pendulum", "--t-end", "1", "--samples", "1000000000000")
    assert code == 2 and out == ""
    assert one_line(err) == ("error: --samples: samples must be at most 10,000,000, "
                             "got 1,000,000,000,000")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("modes", "pendulum", "--about", "theta=pi/0"),
         "error: --about theta: division by zero in 'pi/0'"),  # a ZeroDivisionError traceback
        (("simulate", "pendulum", "--t-end", "1", "--stop-when", "log(-1) > theta"),
         "error: --stop-when: 'log(-1)' is not a real number"),  # the real part was used
        (("simulate", "pendulum", "--t-end", "1", "--stop-when", "theta > 1.0000001^1000"),
         "error: --stop-when: the exact value of '1.0000001^1000' has about 7000 digits (at most "
         "1000): write it as a decimal number (about 1.0001)"),
        (("forces", "pendulum", "--at", "theta=1 rad*9^9^9"),
         "error: --at theta: unit 'rad*9^9^9': powers of powers are not allowed in a unit"),
        (("forces", "pendulum", "--at", "theta=1e308pi"),  # units after the finiteness check
         "error: --at theta: '1e308pi' is not a finite number in SI units"),
    ],
)
def test_hostile_values_on_the_command_line(cli, args, message):
    code, out, err = cli(*args)
    assert code == 2 and out == ""
    assert one_line(err) == message


CONSTRAINED = """
[coordinates]
x = { unit = "m", initial = 1.0 }
y = { unit = "m", initial = 0.0 }
[energy]
T = "1/2*(x_dot^2 + y_dot^2)"
[[constraints]]
name = "one"
FIRST
[[constraints]]
name = "two"
SECOND
"""


@pytest.mark.parametrize(
    ("first", "second", "message"),
    [
        # x = 1 and x = 2 cannot both hold: once called "redundant"
        ('holonomic = "x - 1"', 'holonomic = "x - 2"', "error: inconsistent constraints: where "
         "'one' holds, 'two' equals -1, never 0; correct or remove one of them"),
        ('velocity = "x_dot - 1"', 'velocity = "x_dot - 2"', "error: inconsistent constraints: "
         "where 'one' holds, 'two' equals -1, never 0; correct or remove one of them"),
        # 2x - 2 = 0 says again what x - 1 = 0 says
        ('holonomic = "x - 1"', 'holonomic = "2*x - 2"', "error: redundant constraint 'two': it "
         "depends on the constraints before it (one); remove it so that there is exactly one "
         "multiplier per independent constraint"),
    ],
)
def test_inconsistent_constraints_are_told_from_redundant_ones(cli, tmp_path, first, second,
                                                               message):
    model = tmp_path / "constrained.toml"
    model.write_text(CONSTRAINED.replace("FIRST", first).replace("SECOND", second))
    code, out, err = cli("derive", str(model))
    assert code == 2 and out == ""
    assert one_line(err) == message


@pytest.mark.parametrize(
    ("args", "message"),
    [
        # the command line's own errors were a 5-6 line box from the CLI framework
        (("derive", "pendulum", "--format", "xml"), "error: invalid value for '--format' / '-f': "
         "'xml' is not one of 'text', 'latex', 'json' (see 'lagrangian derive "
         "--help')"),
        (("simulate", "pendulum"), "error: missing option '--t-end' (see 'lagrangian simulate "
         "--help')"),
        (("simulate", "pendulum", "--t-end", "1", "--samples", "abc"), "error: invalid value for "
         "'--samples': 'abc' is not a valid int "
         "(see 'lagrangian simulate --help')"),
        (("nosuch",), "error: no such command 'nosuch' (see 'lagrangian --help')"),
        (("derive",), "error: missing argument 'model' (see 'lagrangian derive --help')"),
    ],
)
def test_command_line_errors_are_one_line(cli, args, message):
    code, out, err = cli(*args)
    assert code == 2 and out == ""
    assert one_line(err) == message


def test_output_paths_are_checked_before_the_run(cli, tmp_path):
    folder = tmp_path / "run.csv"
    folder.mkdir()
    code, out, err = cli("simulate", "pendulum", "--t-end", "1", "--out", str(folder))
    assert code == 2 and out == ""
    assert one_line(err) == f"error: --out: cannot write {folder}: it is a directory"
    afile = tmp_path / "afile"
    afile.write_text("x")
    # was "[Errno 17] File exists: 'afile'" after the run (29 s of animation lost)
    code, out, err = cli("simulate", "pendulum", "--t-end", "1", "--plot", str(afile / "run.png"))
    assert code == 2 and out == ""
    assert one_line(err) == (f"error: --plot: cannot write {afile / 'run.png'}: {afile} is a "
                             "file, not a directory")
    shapes = tmp_path / "shapes.png"
    shapes.mkdir()
    code, out, err = cli("modes", "pendulum", "--plot", str(shapes))
    assert code == 2 and out == ""
    assert one_line(err) == f"error: --plot: cannot write {shapes}: it is a directory"


def test_a_read_only_directory_is_refused_before_the_run(cli, tmp_path, monkeypatch):
    import os

    from lagrangian.output import files

    folder = tmp_path / "locked"
    folder.mkdir()
    # what a read-only directory answers (root could write into one, so it is simulated)
    monkeypatch.setattr(files.os, "access",
                        lambda path, mode: os.path.abspath(path) != str(folder))
    code, out, err = cli("simulate", "double_pendulum", "--t-end", "1", "--animate",
                         str(folder / "run.gif"))
    assert code == 2 and out == ""
    assert one_line(err) == (f"error: --animate: cannot write {folder / 'run.gif'}: the "
                             f"directory {folder} is not writable")
    code, out, err = cli("simulate", "pendulum", "--t-end", "1", "--out",
                         str(folder / "new" / "run.csv"))
    assert one_line(err) == (f"error: --out: cannot write {folder / 'new' / 'run.csv'}: "
                             f"{folder / 'new'} cannot be created: {folder} is not writable")


def test_a_partial_result_never_replaces_an_existing_file(cli, tmp_path):
    model = tmp_path / "x2.toml"
    model.write_text(SINGULAR_AT_ZERO)
    table = tmp_path / "run.csv"
    table.write_text("a good result\n")
    code, _, err = cli("simulate", str(model), "--t-end", "1", "--out", str(table))
    assert code == 1
    partial = tmp_path / "run.partial.csv"
    assert one_line(err) == ("error: integration failed: Singular mass matrix at t = 0 s; "
                             f"partial result saved to {partial}")
    assert table.read_text() == "a good result\n"
    assert partial.read_text().splitlines()[1] == "0.0,0.0,1.0,0.0,0.0"


INDEFINITE = """
[coordinates]
x = { unit = "m", initial = 0.5 }
y = { unit = "m", initial = 0.5 }
[energy]
T = "1/2*x_dot^2 - 1/2*y_dot^2"
V = "1/2*x^2 + 1/2*y^2"
"""

NAN_IN_V = """
[coordinates]
x = { unit = "m", initial = 0.5 }
[parameters]
k = -1.0
[energy]
T = "1/2*x_dot^2"
V = "sqrt(k)*x^2"
"""


@pytest.mark.parametrize(
    ("args", "warning"),
    [
        # M = m L^2 = -0.25: simulated with exit 0 and no word before
        (("pendulum", "--set", "m=-1"), "warning: the kinetic energy is not positive at the "
         "initial state (the mass matrix has the eigenvalue -0.25): T < 0 for some velocities, so "
         "the motion is not physical"),
        (("double_pendulum", "--set", "m1=-1"), "warning: particle 'bob1' has a negative mass (-1)"),
    ],
)
def test_a_negative_mass_is_warned_about_in_derive_and_simulate(cli, args, warning):
    code, out, err = cli("derive", *args)
    assert code == 0 and out
    assert one_line(err) == warning
    code, out, err = cli("simulate", *args, "--t-end", "0.1")
    assert err.splitlines()[0] == warning


def test_an_indefinite_kinetic_energy_is_warned_about(cli, tmp_path):
    model = tmp_path / "indefinite.toml"
    model.write_text(INDEFINITE)
    code, out, err = cli("simulate", str(model), "--t-end", "1")
    assert code == 0
    assert one_line(err) == ("warning: the kinetic energy is not positive at the initial state "
                             "(the mass matrix has the eigenvalue -1): T < 0 for some "
                             "velocities, so the motion is not physical")


def test_the_analysis_refuses_what_it_cannot_get_right(cli):
    code, out, err = cli("modes", "pendulum", "--set", "m=-1")
    assert code == 2 and out == ""
    assert one_line(err) == ("error: the mass matrix is not positive definite at this "
                             "equilibrium (is the kinetic energy complete and positive?)")


def test_a_nan_in_v_is_a_potential_energy_problem(cli, tmp_path):
    model = tmp_path / "nan.toml"
    model.write_text(NAN_IN_V)
    code, out, err = cli("simulate", str(model), "--t-end", "1")
    assert code == 1
    assert one_line(err) == ("error: integration failed: Required step size is less than "
                             "spacing between numbers at t = 0 s: the potential energy V is not "
                             "a real number there (NaN: a square root or logarithm of a negative "
                             "value?)")
    code, out, err = cli("modes", str(model))
    assert code == 2  # was "--set: the value 2.0*I is not real", naming a flag not given
    assert one_line(err) == ("error: the potential energy V or a load (the stiffness) is not a "
                             "real number with these parameter values (a value 2.0*I): a square "
                             "root or logarithm of a negative value?")


TOWER_AND_ROOT = """
[coordinates]
x = { unit = "m", initial = 0.5 }
y = { unit = "m", initial = 0.3 }
[energy]
T = "1/2*(x_dot^2 + y_dot^2)"
V = "exp(exp(exp(exp(exp(x)))))"
[[constraints]]
name = "path"
holonomic = "y - x^0.123456789"
"""


def test_derive_survives_towers_and_long_rational_exponents_of_coordinates(cli, tmp_path):
    # campaign finds: the closed-form solve cancelled polynomials of degree 123456789 (hours),
    # and checked the tower at a random point with mpmath (MemoryError)
    model = tmp_path / "tower.toml"
    model.write_text(TOWER_AND_ROOT)
    code, out, err = cli("derive", str(model), "--format", "json")
    assert code == 0 and err == ""
    # no closed form is claimed (the implicit M q_ddot = f stands)
    assert json.loads(out)["accelerations"] == {"x": None, "y": None}


def test_a_mass_near_overflow_is_judged_without_a_traceback(cli, tmp_path):
    # campaign find: M + M^T overflowed and the eigenvalue solver did not converge
    model = tmp_path / "heavy.toml"
    model.write_text('[coordinates]\nq = { unit = "rad" }\n[parameters]\nm = -1e308\n'
                     '[energy]\nT = "1/2*m*q_dot^2"\n')
    code, out, err = cli("derive", str(model))
    assert code == 0
    assert one_line(err) == ("warning: the kinetic energy is not positive at the initial state "
                             "(the mass matrix has the eigenvalue -1e+308): T < 0 for some "
                             "velocities, so the motion is not physical")



def test_a_model_too_deep_for_sympy_is_one_line_not_a_traceback(monkeypatch, capsys):
    # A chain of ~1500 bodies nests its positions deeper than sympy can recurse (seen with a
    # real model file, 30 s to build); the CLI's backstop names it in one line.
    from lagrangian.api.system import System
    from lagrangian.cli import main

    def too_deep(self):
        raise RecursionError("maximum recursion depth exceeded")

    monkeypatch.setattr(System, "equations_of_motion", too_deep)
    with pytest.raises(SystemExit) as stop:
        main(["derive", "pendulum"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("error: the model is nested too deeply") and err.count("\n") == 1
