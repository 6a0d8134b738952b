"""Final answers of the course (answer-file tables [matrices], [frequencies], [mode_shapes],
[linearized], [generalized_forces] at, [equilibria]) against the seed's worked examples 1-3 and
closed forms; numbers are compared to the precision the student wrote."""

from __future__ import annotations

import json
import math

import pytest
from check_helpers import ANSWERS, check_file, check_text, finding, system

import lagrangian
from lagrangian import ModelError
from lagrangian.check.final_answers import FINAL_CODES
from lagrangian.check.final_reading import agrees, read_written
from lagrangian.cli import main
from lagrangian.model.answer import parse_answer

OMEGA_PENDULUM = math.sqrt(9.81 / 0.5)  # worked example 1: 4.429... rad/s


def unequal():
    return lagrangian.load(ANSWERS / "two_mass_unequal.toml")


# -- worked example 1: the pendulum's small-angle equation and omega_n ----------------------

def test_worked_example_1_small_angle_equation_and_frequency_accepted():
    assert round(OMEGA_PENDULUM, 2) == 4.43  # the seed's closed form
    report = check_file("pendulum", "final_pendulum.toml")
    assert report.verdict == "correct", report
    assert finding(report, "linearized.theta").status == "correct"
    omega = finding(report, "omega[1]")
    assert omega.status == "correct"
    assert "3 significant figures" in omega.message


def test_worked_example_1_wrong_frequency_and_coefficient_rejected():
    report = check_file("pendulum", "final_pendulum_wrong.toml")
    assert report.verdict == "incorrect"
    omega = finding(report, "omega[1]")
    assert omega.code == "frequency_wrong"
    assert "squared" in omega.message  # g/L = 19.6 is omega^2, not omega
    line = finding(report, "linearized.theta")
    assert line.code == "linear_coefficient"
    assert "coefficient of theta is L/g in yours, ours is g/L" in line.message


@pytest.mark.parametrize("equation", [
    "theta_ddot + g/L*theta = 0",
    "m*L^2*theta_ddot = -m*g*L*theta",          # not divided by m L^2: any factor
    "theta_ddot = -19.62*theta",                # g/L at the model's values, 4 s.f.
])
def test_small_angle_equation_in_any_scaling(equation):
    report = check_text("pendulum", f'[linearized]\nabout = {{ theta = 0 }}\ntheta = "{equation}"\n')
    assert report.verdict == "correct", report


def test_a_nonlinear_equation_is_not_a_linearization():
    report = check_text("pendulum", '[linearized]\nabout = { theta = 0 }\n'
                                    'theta = "theta_ddot + g/L*sin(theta) = 0"\n')
    assert finding(report, "linearized.theta").code == "not_linearized"


def test_linearized_about_the_inverted_position():
    # About theta = pi: theta_ddot - (g/L) dtheta = 0, in the deviation or in theta itself.
    for equation in ("theta_ddot - g/L*theta = 0", "theta_ddot - g/L*(theta - pi) = 0"):
        report = check_text("pendulum", f'[linearized]\nabout = {{ theta = "pi" }}\n'
                                        f'theta = "{equation}"\n')
        assert report.verdict == "correct", (equation, report)
    report = check_text("pendulum", '[linearized]\nabout = { theta = "pi" }\n'
                                    'theta = "theta_ddot + g/L*theta = 0"\n')
    assert finding(report, "linearized.theta").code == "linear_coefficient"
    report = check_text("pendulum", '[linearized]\nabout = { theta = "pi" }\n'
                                    'theta = "theta_ddot - g/L*(theta - 1) = 0"\n')
    assert finding(report, "linearized.theta").code == "linear_offset"


# -- worked example 2: a generalized force at 30 degrees ------------------------------------

def test_worked_example_2_generalized_force_accepted():
    report = check_file("virtual_work_link", "final_link.toml")
    assert report.verdict == "correct", report
    assert "3 significant figures" in finding(report, "Q_theta").message


@pytest.mark.parametrize(("value", "hint"), [
    ("86.6 N*m", "twice ours"),          # F L cos 30 x 2
    ("25 N*m", "sin and cos exchanged"),  # F L sin 30 = 25 exactly
    ("-43.3 N*m", "opposite sign"),
    ("50.0 N*m", "Did I do virtual work"),  # F L, no projection
])
def test_worked_example_2_wrong_values_rejected(value, hint):
    report = check_text("virtual_work_link",
                        f'[generalized_forces]\nat = {{ theta = "30deg" }}\ntheta = "{value}"\n')
    q = finding(report, "Q_theta")
    assert q.code == "generalized_force_value"
    assert "'F': 43.3013" in q.message and q.expected == "43.3013 N*m"
    assert hint in q.message


def test_generalized_force_in_other_units_and_at_90_degrees():
    # 43.30 N m = 4330. N cm (a whole number without its point is exact: 43.3013 is not 4330);
    # at 90 deg the force is along the link: Q = 0 exactly; at 0, F L = 50 N m.
    text = '[generalized_forces]\nat = {{ theta = "{at}" }}\ntheta = "{q}"\n'
    assert check_text("virtual_work_link", text.format(at="30deg", q="4330. N*cm")).verdict \
        == "correct"
    assert check_text("virtual_work_link", text.format(at="30deg", q="4330 N*cm")).verdict \
        == "incorrect"
    assert check_text("virtual_work_link", text.format(at="90deg", q="0 N*m")).verdict \
        == "correct"
    assert check_text("virtual_work_link", text.format(at="0", q="50.0 N*m")).verdict \
        == "correct"


# -- worked example 3: M, K, frequencies, mode shapes ----------------------------------------

def test_worked_example_3_matrices_frequencies_shapes_accepted():
    report = check_file("two_mass", "final_two_mass.toml")
    assert report.verdict == "correct", report
    assert {f.item for f in report.findings} == {"M", "K", "omega[1]", "omega[2]", "shape[1]",
                                                "shape[2]"}


def test_worked_example_3_numbers_read_at_the_model_values():
    report = check_text("two_mass", """
[matrices]
M = [[1, 0], [0, 1]]
K = [[2, -1], [-1, 2]]
[frequencies]
omega = [1, 1.73]
[mode_shapes]
shapes = [[2, 2], ["-0.5", "0.5"]]
""")
    assert report.verdict == "correct", report


def test_worked_example_3_a_wrong_stiffness_entry_is_named():
    report = check_text("two_mass", '[matrices]\nK = [["k + k_c", "k_c"], ["-k_c", "k + k_c"]]\n')
    k = finding(report, "K")
    assert k.code == "matrix_entry"
    assert "K[1,2] (row x1, column x2) is k_c in yours, ours is -k_c" in k.message
    assert "K[2,1]" not in k.message


def test_shapes_as_constants_and_decimals():
    # (1, -1) written as (sqrt(2), -sqrt(2)) or (0.707, -0.707): any scale
    for shapes in ('[[1, 1], ["sqrt(2)", "-sqrt(2)"]]', '[[1, 1], [0.707, -0.707]]'):
        report = check_text("two_mass", f"[mode_shapes]\nshapes = {shapes}\n")
        assert report.verdict == "correct", report


def test_wrong_shape_and_missing_frequency():
    report = check_text("two_mass", '[frequencies]\nomega = ["1 rad/s"]\n'
                                    '[mode_shapes]\nshapes = [[1, 1], [1, 1]]\n')
    assert finding(report, "frequencies").code == "frequency_count"
    assert finding(report, "omega[1]").status == "correct"
    assert finding(report, "shape[1]").status == "correct"
    assert finding(report, "shape[2]").code == "mode_shape_wrong"


def test_coordinate_order_of_the_student():
    # m2 = 2 m1: omega^2 = (3 -+ sqrt 3)/2; in the order x2, x1 the shapes are (1.366, 1) and
    # (-0.366, 1), M = diag(m2, m1).
    s = unequal()
    assert s.check(ANSWERS / "final_two_mass_unequal_swapped.toml").verdict == "correct"
    w = sorted(math.sqrt((3 + sign * math.sqrt(3)) / 2) for sign in (-1, 1))
    assert s.modes().natural_frequencies == pytest.approx(w)
    # the same numbers in the model's order are wrong
    text = (ANSWERS / "final_two_mass_unequal_swapped.toml").read_text()
    report = s.check(parse_answer(text.replace('coordinates = ["x2", "x1"]', ""), s.model))
    assert finding(report, "M").code == "matrix_entry"
    assert finding(report, "shape[1]").code == "mode_shape_wrong"
    assert finding(report, "omega[1]").status == "correct"  # frequencies have no order


# -- damping ratios, f and period ------------------------------------------------------------

def test_damping_ratio_and_frequency_of_a_damped_oscillator():
    # m = 1, k = 4, c = 0.4: omega_n = 2 rad/s, zeta = c / (2 sqrt(k m)) = 0.1, C = [[c]]
    right = check_text("damped_oscillator", '[frequencies]\nomega = ["2.00 rad/s"]\nzeta = [0.1]\n'
                                            '[matrices]\nC = [["c"]]\nK = [[4]]\n')
    assert right.verdict == "correct", right
    wrong = check_text("damped_oscillator", "[frequencies]\nzeta = [0.2]\n")
    assert finding(wrong, "zeta[1]").code == "damping_ratio_wrong"
    # omega_d = omega_n sqrt(1 - zeta^2) = 2 sqrt(0.99) = 1.990 is not the natural frequency
    damped = check_text("damped_oscillator", '[frequencies]\nomega = ["1.990 rad/s"]\n')
    assert "damped one" in finding(damped, "omega[1]").message


def test_frequency_in_hertz_and_period():
    # f = omega / 2 pi = 0.705 Hz, T = 2 pi / omega = 1.42 s (worked example 1)
    assert check_text("pendulum", '[frequencies]\nf = ["0.705 Hz"]\n').verdict == "correct"
    assert check_text("pendulum", '[frequencies]\nperiod = ["1.42 s"]\n').verdict == "correct"
    wrong = check_text("pendulum", '[frequencies]\nomega = ["0.705 rad/s"]\n')
    assert "2 pi" in finding(wrong, "omega[1]").message


# -- equilibria ------------------------------------------------------------------------------

@pytest.mark.parametrize("positions", ['["0", "pi"]', '["pi", "0"]', '["-pi", 0]',
                                       '["3.14", "0"]', '["180deg", "0deg"]'])
def test_pendulum_equilibria_accepted_in_any_order(positions):
    report = check_text("pendulum", f"[equilibria]\ntheta = {positions}\n")
    assert report.verdict == "correct", report


def test_pendulum_equilibria_wrong_or_missing():
    report = check_text("pendulum", '[equilibria]\ntheta = ["0", "pi/2"]\n')
    assert finding(report, "equilibrium.theta[1]").status == "correct"
    assert finding(report, "equilibrium.theta[2]").code == "equilibrium_wrong"
    assert finding(report, "equilibria").code == "equilibrium_missing"
    report = check_text("pendulum", '[equilibria]\ntheta = ["0"]\n')
    assert "missing theta = 3.14159" in finding(report, "equilibria").message


def test_double_pendulum_equilibria_as_points():
    report = check_text("double_pendulum", '[equilibria]\ntheta1 = [0, 0, "pi", "pi"]\n'
                                           'theta2 = [0, "pi", 0, "pi"]\n')
    assert report.verdict == "correct", report
    assert finding(report, "equilibrium[4]").status == "correct"


# -- precision -------------------------------------------------------------------------------

@pytest.mark.parametrize(("written", "accepted", "words"), [
    ("4.43 rad/s", True, "3 significant figures"),
    ("4.4 rad/s", True, "2 significant figures"),
    ("4.5 rad/s", False, "2 significant figures"),
    ("4.42 rad/s", False, "3 significant figures"),
    ("4.4294 rad/s", True, "5 significant figures"),
    ("4 rad/s", False, "exactly"),
    ("4. rad/s", True, "1 significant figure"),
])
def test_precision_the_student_wrote(written, accepted, words):
    report = check_text("pendulum", f'[frequencies]\nomega = ["{written}"]\n')
    omega = finding(report, "omega[1]")
    assert (omega.status == "correct") is accepted, omega
    assert words in omega.message


def test_rounding_rule():
    w = read_written("4.43 rad/s", "rad/s", "f", "a.toml")
    assert (w.value, w.figures) == (4.43, 3) and w.step == pytest.approx(0.01)
    assert agrees(w, 4.4349) and agrees(w, 4.425) and not agrees(w, 4.4351)
    deg = read_written("30.0deg", "rad", "f", "a.toml")
    assert deg.step == pytest.approx(math.radians(0.1))
    assert read_written("pi/2", "rad", "f", "a.toml").step is None
    assert agrees(read_written("1.2e3", None, "f", "a.toml"), 1249)


# -- the JSON and the command line -----------------------------------------------------------

def test_cli_json_and_exit_status(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["check", "pendulum", str(ANSWERS / "final_pendulum_wrong.toml"), "--json"])
    assert exit_info.value.code == 1
    document = json.loads(capsys.readouterr().out)
    assert document["verdict"] == "incorrect"
    items = {f["item"]: f for f in document["findings"]}
    assert set(items["omega[1]"]) == {"item", "status", "code", "message", "expected"}
    assert items["omega[1]"]["expected"] == "4.42945 rad/s"
    with pytest.raises(SystemExit) as exit_info:
        main(["check", "two_mass", str(ANSWERS / "final_two_mass.toml")])
    assert exit_info.value.code == 0


@pytest.mark.parametrize(("text", "message"), [
    ('[matrices]\nK = [[1, 2]]\n',
     "a.toml: matrices.K: expected 2 rows (one per coordinate: x1, x2), got 1"),
    ('[matrices]\nK = [[1, 2], [3]]\n', "a.toml: matrices.K[2]: expected 2 entries"),
    ('[matrices]\nL = [[1]]\n', "a.toml: matrices.L: unknown key 'L'"),
    ('[matrices]\nK = [["k + k_C", 0], [0, 1]]\n', "a.toml: matrices.K[1][1]: unknown name 'k_C'"),
    ('[frequencies]\nomega = "1 rad/s"\n', "a.toml: frequencies.omega: expected a list of values in rad/s"),
    ('[frequencies]\nomega = ["1 m"]\n', "a.toml: frequencies.omega[1]: '1 m' is not in units"),
    ('[frequencies]\nomega = ["1 Hz"]\n', "a.toml: frequencies.omega[1]: omega is in rad/s"),
    ('[frequencies]\nomega = [1]\nf = [1]\n', "a.toml: frequencies: give one of omega"),
    ('[frequencies]\nomega = [true]\n', "a.toml: frequencies.omega[1]: expected a number"),
    ('[mode_shapes]\nshapes = [[1, 1, 1]]\n', "a.toml: mode_shapes.shapes[1]: expected 2 components"),
    ('[mode_shapes]\nshapes = [["1 m", 1]]\n', "a.toml: mode_shapes.shapes[1][1]: expected a plain"),
    ('[frequencies]\nzeta = ["0.1 m"]\n', "a.toml: frequencies.zeta[1]: expected a plain number"),
    ('[frequencies]\nomega = ["-1 rad/s"]\n', "a.toml: frequencies.omega[1]: expected a positive"),
    ('[matrices]\nK = [["1/0", 0], [0, 1]]\n', "a.toml: matrices.K[1][1]: division by zero"),
    ('[mode_shapes]\nshapes = [[0, 0]]\n', "a.toml: mode_shapes.shapes[1]: a mode shape cannot"),
    ('[mode_shapes]\nvectors = [[1, 0]]\n', "a.toml: mode_shapes.vectors: unknown key"),
    ('[linearized]\nx1 = "x1_ddot = 0"\n', "a.toml: linearized.about: give the equilibrium"),
    ('[linearized]\nabout = { y = 0 }\nx1 = "x1_ddot"\n',
     "a.toml: linearized.about.y: unknown coordinate 'y'"),
    ('[generalized_forces]\nat = { x1 = "1 s" }\nx1 = "1 N"\n',
     "a.toml: generalized_forces.at.x1: '1 s' is not in units"),
    ('[generalized_forces]\nat = { x1 = 0 }\nx1 = "1 N*m"\n',
     "a.toml: generalized_forces.x1: '1 N*m' is not in units compatible with 'N'"),
    ('[equilibria]\nx1 = [0, 1]\nx2 = [0]\n', "a.toml: equilibria.x2: expected 2 positions"),
    ('coordinates = ["x1"]\n[equilibria]\nx1 = [0]\n', "a.toml: coordinates: list every"),
    ('coordinates = ["x2", "x1"]\n', "a.toml: the answer has nothing to check"),
])
def test_malformed_tables_refused_by_field(text, message):
    two_mass = system("two_mass")
    with pytest.raises(ModelError) as error:
        two_mass.check(parse_answer(text, two_mass.model, source="a.toml"))
    assert str(error.value).startswith(message), str(error.value)
    assert "\n" not in str(error.value)


def test_cli_refuses_a_malformed_table_in_one_line(tmp_path, capsys):
    answer = tmp_path / "a.toml"
    answer.write_text('[frequencies]\nomega = ["4.43 m"]\n')
    with pytest.raises(SystemExit) as exit_info:
        main(["check", "pendulum", str(answer), "--json"])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "a.toml: frequencies.omega[1]:" in err


def test_an_about_that_is_no_equilibrium_is_refused():
    with pytest.raises(ModelError) as error:
        check_text("pendulum", '[linearized]\nabout = { theta = 1 }\ntheta = "theta_ddot"\n')
    assert "linearized.about" in str(error.value)


def test_every_final_code_is_exercised_by_this_file_or_the_statics_one():
    import inspect
    import sys
    from pathlib import Path

    source = inspect.getsource(sys.modules[__name__]) + (
        Path(__file__).with_name("test_final_statics.py").read_text(encoding="utf-8"))
    missing = [code for code in FINAL_CODES if f'"{code}"' not in source]
    assert not missing, missing


# -- the practice ladder -----------------------------------------------------------------------

def test_ladder_levels_1_and_2():
    # level 1: omega_n = sqrt(9.81/2) = 2.21 rad/s; level 2: Q_theta = -F L sin 0 = 0
    assert math.sqrt(9.81 / 2) == pytest.approx(2.2147, abs=1e-4)
    level_1 = check_text("ladder_pendulum", '[frequencies]\nomega = ["2.21 rad/s"]\n')
    assert level_1.verdict == "correct", level_1
    assert check_text("ladder_pendulum", '[frequencies]\nomega = ["2.22 rad/s"]\n').verdict \
        == "incorrect"
    level_2 = check_text("ladder_vertical_force",
                         '[generalized_forces]\nat = { theta = 0 }\ntheta = "0 N*m"\n')
    assert level_2.verdict == "correct", level_2
    # at 30 deg, -F L sin 30 = -60 * 0.4 * 0.5 = -12 N m
    at_30 = check_text("ladder_vertical_force",
                       '[generalized_forces]\nat = { theta = "30deg" }\ntheta = "-12.0 N*m"\n')
    assert at_30.verdict == "correct", at_30
