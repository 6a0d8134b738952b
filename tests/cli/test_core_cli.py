"""`lagrangian derive`, `forces` and `examples` as a user meets them, bad input included."""

import json
import subprocess
import sys

import pytest

import lagrangian

pytestmark = pytest.mark.smoke  # pytest -m smoke: the quick subset


def test_examples_lists_every_builtin(cli):
    result = cli("examples", "--json")
    assert result.code == 0
    names = [e["name"] for e in json.loads(result.out)["examples"]]
    assert names == lagrangian.examples()
    for required in ("pendulum", "virtual_work_link", "two_mass", "ladder_pendulum",
                     "ladder_vertical_force", "ladder_spring_mass", "double_pendulum",
                     "cartesian_pendulum", "cart_pendulum"):
        assert required in names
    text = cli("examples")
    assert text.code == 0 and "pendulum" in text.out
    show = cli("examples", "--show", "pendulum")
    assert show.code == 0 and "[coordinates]" in show.out


@pytest.mark.parametrize("name", ["pendulum", "two_mass", "cartesian_pendulum"])
def test_derive_every_format(cli, name):
    text = cli("derive", name)
    assert text.code == 0 and "Equations of motion" in text.out
    latex = cli("derive", name, "--format", "latex")
    assert latex.code == 0 and r"\begin{align}" in latex.out
    document = cli("derive", name, "--format", "json")
    assert document.code == 0 and json.loads(document.out)["coordinates"]


def test_derive_text_shows_the_pendulum_equation(cli):
    out = cli("derive", "pendulum").out
    assert "[theta]  L**2*m*theta_ddot = -L*g*m*sin(theta)" in out
    assert "theta_ddot = -g*sin(theta)/L" in out


def test_derive_shows_constraints_and_multipliers(cli):
    out = cli("derive", "cartesian_pendulum").out
    assert "rod (holonomic): -L**2 + x**2 + y**2 = 0   multiplier lambda_rod" in out
    assert "Constraint Jacobian Phi_q:\n  [2*x, 2*y]" in out


def test_forces_at_thirty_degrees(cli):
    result = cli("forces", "virtual_work_link", "--at", "theta=30deg", "--json")
    assert result.code == 0
    document = json.loads(result.out)
    assert document["generalized_forces"]["theta"] == pytest.approx(43.30, abs=0.005)
    assert document["configuration"]["theta"] == pytest.approx(0.5235987755982988)
    more = json.loads(cli("forces", "virtual_work_link", "--at", "theta=30deg", "--set",
                          "F=120", "--json").out)
    assert more["generalized_forces"]["theta"] == pytest.approx(120 * 0.5 * 0.8660254, rel=1e-6)
    text = cli("forces", "virtual_work_link", "--at", "theta=30deg")
    assert "Q[theta] = 43.3013 N*m" in text.out and "from F: 43.3013 N*m" in text.out


def test_forces_units_on_values(cli):
    result = cli("forces", "cart_pendulum", "--at", "x=50cm", "--set", "F=2N", "--json")
    document = json.loads(result.out)
    assert document["configuration"]["x"] == pytest.approx(0.5)
    assert document["generalized_forces"]["x"] == pytest.approx(2.0)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("derive", "no_such_model"),
         "error: no such file or built-in example 'no_such_model' (`lagrangian examples` lists them)"),
        (("derive", "pendulm"),
         "error: no such file or built-in example 'pendulm'; did you mean 'pendulum'? "
         "(`lagrangian examples` lists them)"),
        (("derive", "missing.toml"), "error: missing.toml: no such file"),
        (("forces", "pendulum", "--at", "thet=1"),
         "error: --at: 'thet' is not a coordinate, velocity or t of this model; did you mean 'theta'?"),
        (("forces", "pendulum", "--at", "theta=0.5m"),
         "error: --at theta: '0.5m' is not in units compatible with 'rad'"),
        (("forces", "pendulum", "--at", "theta"), "error: --at: expected NAME=VALUE, got 'theta'"),
        # a name given twice: one of the two would be dropped without a word
        (("forces", "pendulum", "--at", "theta=0.1,theta=0.2"),
         "error: --at: 'theta' is given twice ('0.1', then '0.2'): give it once"),
        (("dynamics", "pendulum", "--set", "m=1", "--set", "m=2"),
         "error: --set: 'm' is given twice ('1', then '2'): give it once"),
        (("forces", "pendulum", "--set", "q=1"),
         "error: --set: 'q' is not a parameter of this model; expected one of: m, L, g"),
        (("forces", "pendulum", "--at", "theta=abc"),
         "error: --at theta: expected a number with an optional unit (like 30deg), got 'abc'"),
    ],
)
def test_bad_input_exits_2_with_one_line(cli, args, message):
    result = cli(*args)
    assert result.code == 2
    # where example-robot-data is installed, its robots are named too
    assert result.err.strip().replace("; `lagrangian examples --robots` the robots", "") \
        == message
    assert "Traceback" not in result.err


def test_bad_model_file_exits_2_without_traceback(tmp_path):
    model = tmp_path / "bad.toml"
    model.write_text('[coordinates]\nx = "m"\n[energy]\nT = "__import__(\'os\')"\n')
    process = subprocess.run([sys.executable, "-m", "lagrangian", "derive", str(model)],
                             capture_output=True, text=True)
    assert process.returncode == 2
    assert process.stderr.strip() == f"error: {model}: energy.T: unknown function '__import__'"
    assert model.read_text().startswith("[coordinates]")  # the input is never touched


def test_singular_model_exits_2(cli, tmp_path):
    model = tmp_path / "singular.toml"
    model.write_text('[coordinates]\nx = "m"\ny = "m"\n[energy]\nT = "x_dot^2/2"\n')
    result = cli("derive", str(model))
    assert result.code == 2 and "kinetic energy does not contain the velocity of 'y'" in result.err


def test_usage_error_exit_code(cli):
    assert cli("derive").code == 2


def test_non_finite_option_values_exit_2(cli):
    result = cli("forces", "virtual_work_link", "--set", "F=1e400")
    assert result.code == 2 and result.err.strip() == "error: --set F: '1e400' is not a finite number"
