"""`lagrangian equilibria` and `lagrangian modes`: output contracts, the plot, exit codes."""

from __future__ import annotations

import json
import math
import struct

import pytest

from lagrangian.output.modes import mode_plot_size

MODE_KEYS = {"frequency", "frequency_hz", "period", "damping_ratio", "growth_rate", "shape",
             "amplitude", "phase"}


def test_modes_json_contract_for_worked_example_3(cli):
    code, out, _ = cli("modes", "two_mass", "--json")
    assert code == 0
    document = json.loads(out)
    assert set(document) == {"equilibrium", "stable", "mass_matrix", "damping_matrix",
                             "stiffness_matrix", "coordinates", "modes"}
    assert document["equilibrium"] == {"x1": 0.0, "x2": 0.0}
    assert document["stable"] is True
    assert document["coordinates"] == ["x1", "x2"]
    assert document["mass_matrix"] == [[1.0, 0.0], [0.0, 1.0]]
    assert document["stiffness_matrix"] == [[2.0, -1.0], [-1.0, 2.0]]
    assert document["damping_matrix"] == [[0.0, 0.0], [0.0, 0.0]]
    first, second = document["modes"]
    assert set(first) == MODE_KEYS
    assert first["frequency"] == pytest.approx(1.0)
    assert second["frequency"] == pytest.approx(math.sqrt(3))
    assert first["frequency_hz"] == pytest.approx(1 / (2 * math.pi))
    assert first["period"] == pytest.approx(2 * math.pi)
    assert first["shape"] == pytest.approx({"x1": 1.0, "x2": 1.0})
    assert second["shape"] == pytest.approx({"x1": 1.0, "x2": -1.0})


def test_modes_text_report(cli):
    code, out, _ = cli("modes", "pendulum")
    assert code == 0
    assert "4.42945" in out and "1.4185" in out  # rad/s and period in s (1.41850)
    assert "Stiffness matrix K" in out


def test_complex_mode_phases_in_text(cli):
    code, out, _ = cli("modes", "charged_particle")
    assert code == 0
    assert "mode 2: x 1 at +0.0 deg, y 1 at +90.0 deg" in out


def test_inverted_pendulum_about_pi(cli):
    code, out, _ = cli("modes", "cart_pendulum", "--about", "theta=pi", "--json")
    assert code == 0
    document = json.loads(out)
    assert document["equilibrium"]["theta"] == pytest.approx(math.pi)
    assert document["stable"] is False
    growing = [m for m in document["modes"] if m["growth_rate"] > 0]
    assert len(growing) == 1 and growing[0]["period"] is None
    assert growing[0]["growth_rate"] == pytest.approx(math.sqrt(9.81 * 2.5 / (2.0 * 0.6)))


def test_about_in_degrees_and_set(cli):
    code, out, _ = cli("modes", "pendulum", "--about", "theta=180deg", "--set", "L=2m",
                       "--json")
    assert code == 0
    (mode,) = json.loads(out)["modes"]
    assert mode["growth_rate"] == pytest.approx(math.sqrt(9.81 / 2.0))


def test_constrained_modes_json_names_the_independent_coordinates(cli):
    code, out, _ = cli("modes", "cartesian_pendulum", "--json")
    document = json.loads(out)
    assert code == 0
    assert document["coordinates"] == ["x"]
    assert document["equilibrium"] == pytest.approx({"x": 0.0, "y": -0.5})
    (mode,) = document["modes"]
    assert mode["frequency"] == pytest.approx(math.sqrt(9.81 / 0.5))
    assert mode["shape"] == {"x": 1.0, "y": 0.0}


def test_equilibria_json_shows_the_pitchfork(cli):
    code, out, _ = cli("equilibria", "bead_on_hoop", "--set", "Omega=3", "--json")
    assert code == 0
    below = json.loads(out)["equilibria"]
    assert [(e["coordinates"]["theta"], e["stable"]) for e in below] == \
        [(0.0, True), (pytest.approx(math.pi), False)]
    code, out, _ = cli("equilibria", "bead_on_hoop", "--set", "Omega=6", "--json")
    above = json.loads(out)["equilibria"]
    side = math.acos(9.81 / (0.5 * 36))
    assert [e["coordinates"]["theta"] for e in above] == \
        pytest.approx([-side, 0.0, side, math.pi])
    assert [e["stable"] for e in above] == [True, False, True, False]
    assert all(set(e) == {"coordinates", "stable"} for e in above)


def test_equilibria_text_with_multipliers(cli):
    code, out, _ = cli("equilibria", "cartesian_pendulum")
    assert code == 0
    assert "stable" in out and "lambda_rod = 9.81" in out


def test_mode_shape_plot_is_a_png_of_the_stated_size(cli, tmp_path):
    target = tmp_path / "modes.png"
    code, out, _ = cli("modes", "double_pendulum", "--about", "theta1=0",
                       "--about", "theta2=0", "--plot", str(target))
    assert code == 0 and "drawn to" in out
    data = target.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", data[16:24])
    assert (width, height) == mode_plot_size(2) == (800, 300)
    # Many modes: a grid of at most three columns, the lowest twelve drawn.
    assert mode_plot_size(50) == (1200, 1200)


def test_plot_never_overwrites_the_model_file(cli, tmp_path):
    from lagrangian.model.examples import example_path

    model = tmp_path / "pendulum.png"
    model.write_bytes(open(example_path("pendulum"), "rb").read())
    code, _, err = cli("modes", str(model), "--plot", str(model))
    assert code == 2 and "refusing to overwrite" in err


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["modes", "pendulum", "--about", "phi=0"],
         "error: --about: 'phi' is not a coordinate of this model"),
        (["modes", "cart_pendulum", "--about", "thetta=0"], "did you mean 'theta'?"),
        (["modes", "pendulum", "--about", "theta=0.1"],
         "error: --about: theta=0.1 is not an equilibrium: the forces at rest do not balance "
         "(residual -0.4897 on theta); the nearest equilibrium is at theta=0"),
        (["modes", "pendulum", "--about", "theta=1m"], "not in units compatible with 'rad'"),
        (["modes", "atwood"], "no equilibrium found"),
        (["equilibria", "support_pendulum"], "depend on time t explicitly"),
        (["modes", "pendulum", "--plot", "modes.svg"], "name the file *.png"),
        (["equilibria", "pendulum", "--set", "Q=1"], "'Q' is not a parameter"),
    ],
)
def test_bad_input_exits_with_status_2(cli, args, message):
    code, out, err = cli(*args)
    assert code == 2
    assert message in err
    assert "Traceback" not in err and out == ""
