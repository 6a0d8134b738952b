"""`lagrangian simulate`: options, outputs, JSON summary, and bad input (exit status 2)."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest

from lagrangian.cli import main

SINGULAR = """
name = "Singular mass"
[coordinates]
x = { unit = "m", initial = 1.0, rate = 0.0 }
[energy]
T = "1/2*x^2*x_dot^2"
V = "1/2*x^2"
"""


def cli(capsys, *args):
    with pytest.raises(SystemExit) as info:
        main(["simulate", *map(str, args)])
    out, err = capsys.readouterr()
    return info.value.code, out, err


def test_json_summary_of_a_run_stopped_by_a_condition(capsys):
    code, out, err = cli(capsys, "pendulum", "--t-end", "10", "--initial", "theta=30deg",
                         "--stop-when", "theta < 0", "--rtol", "1e-11", "--atol", "1e-11", "--json")
    assert code == 0 and err == ""
    summary = json.loads(out)
    assert summary["status"] == "stopped" and summary["stop_when"] == "theta < 0"
    assert summary["final_state"]["theta"] == pytest.approx(0.0, abs=1e-9)
    # a quarter period of a 30 deg swing: sqrt(L/g) K(sin^2(15 deg)), K from scipy
    from scipy.special import ellipk

    quarter = math.sqrt(0.5 / 9.81) * ellipk(math.sin(math.radians(15)) ** 2)
    assert summary["t_final"] == pytest.approx(quarter, rel=1e-8)
    assert summary["relative_energy_drift"] < 1e-9
    assert summary["max_constraint_residual"] is None
    assert isinstance(summary["steps"], int) and summary["nfev"] > summary["steps"]
    assert summary["wall_time_s"] > 0 and summary["outputs"] == {}


def test_constrained_run_writes_table_plot_and_animation_and_warns_about_projection(
        capsys, tmp_path):
    csv, png, gif = tmp_path / "run.csv", tmp_path / "run.png", tmp_path / "run.gif"
    code, out, err = cli(capsys, "cartesian_pendulum", "--t-end", "0.5", "--initial", "x=0.3",
                         "--samples", "51", "--out", csv, "--plot", png, "--animate", gif)
    assert code == 0
    assert err == ("warning: the initial state violates the constraints; projected onto them: "
                   "y -0.477668244563 -> -0.4\n")
    header, first, *rest = csv.read_text().splitlines()
    assert header == "t,x,y,x_dot,y_dot,energy,lambda_rod,residual_rod,power"
    assert [float(v) for v in first.split(",")[:3]] == pytest.approx([0.0, 0.3, -0.4])
    assert len(rest) == 50
    assert png.read_bytes()[:4] == b"\x89PNG" and gif.read_bytes()[:3] == b"GIF"
    assert "largest constraint residual" in out and f"wrote {csv}" in out


def test_parameters_and_units_on_the_command_line(capsys, tmp_path):
    table = tmp_path / "run.parquet"
    code, out, _ = cli(capsys, "pendulum", "--t-end", "500ms", "--set", "m=2kg",
                       "--initial", "theta=60deg", "--out", table, "--json")
    assert code == 0
    import pandas as pd

    frame = pd.read_parquet(table)
    assert frame["t"].iloc[-1] == 0.5
    assert frame["theta"].iloc[0] == pytest.approx(math.pi / 3)
    # E = -m g L cos(theta0) with m = 2 kg, L = 0.5 m
    assert frame["energy"].iloc[0] == pytest.approx(-2 * 9.81 * 0.5 * 0.5)


@pytest.mark.parametrize(("args", "message"), [
    (["--initial", "phi=1"], "error: --initial: 'phi' is not a coordinate, velocity or t of this "
                             "model; expected one of: theta, theta_dot, t"),
    (["--initial", "thetta=1"], "error: --initial: 'thetta' is not a coordinate, velocity or t of "
                                "this model; did you mean 'theta'?"),
    (["--stop-when", "theta <"], "error: --stop-when: the right side of 'theta <' is empty"),
    (["--stop-when", "theta"], "error: --stop-when: a stop condition has exactly one comparison "
                               "(<, >, <=, >=), found no comparison in 'theta'"),
    (["--stop-when", "__import__('os') < 1"], "error: --stop-when: unknown function '__import__'"),
    (["--method", "Euler"], "error: --method: unknown method 'Euler'; choose one of DOP853, RK45, "
                            "RK23, Radau, BDF, LSODA"),
    (["--out", "run.xlsx"], "error: --out: cannot write run.xlsx: use a .csv or .parquet file name"),
    (["--animate", "run.avi"], "error: --animate: cannot write run.avi: use a .gif, .html or .mp4 "
                               "file name"),
    (["--set", "q=1"], "error: --set: 'q' is not a parameter of this model; expected one of: m, L, g"),
])
def test_bad_input_exits_with_status_2(capsys, args, message):
    code, out, err = cli(capsys, "pendulum", "--t-end", "1", *args)
    assert code == 2 and out == ""
    assert err.strip() == message


def test_end_time_must_follow_the_start(capsys):
    code, _, err = cli(capsys, "pendulum", "--t-end", "0")
    assert code == 2 and "must be after the start time" in err


def test_the_model_file_is_never_overwritten(capsys, tmp_path):
    model = tmp_path / "model.csv"
    model.write_text(SINGULAR)
    code, _, err = cli(capsys, model, "--t-end", "0.1", "--out", model)
    assert code == 2 and "refusing to overwrite the input model file" in err
    assert model.read_text() == SINGULAR


def test_a_failing_run_saves_the_partial_result_and_says_where_it_stopped(capsys, tmp_path):
    model = tmp_path / "singular.toml"
    model.write_text(SINGULAR)
    table = tmp_path / "partial.csv"
    code, out, err = cli(capsys, model, "--t-end", "5", "--method", "RK45", "--out", table)
    assert code == 1
    assert err.startswith("error: integration failed: Required step size is less than spacing "
                          "between numbers (stopped at t = ")
    assert f"partial result saved to {table}" in err
    times = [float(line.split(",")[0]) for line in table.read_text().splitlines()[1:]]
    assert 0.9 < times[-1] < 1.1  # x reaches 0 (M = x^2 singular) at t = 1 s


def test_console_script_runs_simulate():
    done = subprocess.run([sys.executable, "-m", "lagrangian", "simulate", "atwood", "--t-end", "1",
                           "--json"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout)
    # y = a t^2 / 2 with a = (m1 - m2) g / (m1 + m2 + I/R^2) = 9.81/6
    assert summary["final_state"]["y"] == pytest.approx(9.81 / 12, rel=1e-8)


def test_nothing_to_animate_is_refused_before_the_run(capsys, tmp_path):
    plot = tmp_path / "run.png"
    code, out, err = cli(capsys, "pendulum", "--t-end", "1", "--plot", plot, "--animate",
                         tmp_path / "run.gif")
    assert code == 2 and out == "" and not plot.exists()
    assert err == ("error: --animate: nothing to animate: the model has no particles or bodies "
                   "(it is given by its energies only)\n")
