"""lagrangian.optimize: direct collocation against closed forms, the two transcriptions against
each other, and the optimal inputs replayed through our own simulate."""

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import InputError, MissingExtraError, ModelError

MOTOR_PENDULUM = """
name = "Pendulum with a motor"
[coordinates]
theta = { unit = "rad", initial = 0.0, rate = 0.0 }
[parameters]
m = { value = 1.0, unit = "kg" }
l = { value = 1.0, unit = "m" }
g = { value = 9.81, unit = "m/s^2" }
u = { value = 0.0, unit = "N*m" }
[energy]
T = "1/2*m*l^2*theta_dot^2"
V = "-m*g*l*cos(theta)"
[[loads]]
name = "motor"
torque = "u"
angle = "theta"
"""

BLOCK = """
name = "Block pushed on a frictionless floor"
[coordinates]
x = { unit = "m", initial = 0.0, rate = 0.0 }
[parameters]
m = { value = 2.0, unit = "kg" }
F = { value = 0.0, unit = "N" }
[[particles]]
name = "block"
mass = "m"
position = ["x", 0]
[[loads]]
name = "push"
point = "block"
force = ["F", 0]
"""

# The torque-limited swing-up's optimum (N^2 m^2 s) by two tools independent of ours, each on
# the pendulum written from its textbook equation: CasADi/IPOPT multiple shooting (RK4, 200
# intervals) and SciPy's SLSQP on a trapezoidal collocation of its own (61 nodes);
# benchmarks/swing_up_references.py computes them.
SWING_UP_OPTIMA = {"casadi multiple shooting": 37.1255, "scipy slsqp trapezoidal": 37.2675}
SWING_UP = {"start": {"theta": 0.0, "theta_dot": 0.0},
            "goal": {"theta": np.pi, "theta_dot": 0.0}, "bounds": {"u": (-5.0, 5.0)}}


@pytest.fixture(scope="module")
def motor_pendulum(tmp_path_factory):
    path = tmp_path_factory.mktemp("models") / "motor_pendulum.toml"
    path.write_text(MOTOR_PENDULUM)
    return lagrangian.load(path)


@pytest.fixture(scope="module")
def swing_up(motor_pendulum):
    return lagrangian.optimize(motor_pendulum, ["u"], 3.0, 30, method="hermite-simpson",
                               **SWING_UP)


def test_minimum_effort_rest_to_rest_is_the_closed_form(tmp_path):
    """m x_ddot = F from rest at 0 to rest at d in T: F*(t) = m (6 d/T^2 - 12 d t/T^3),
    J = 12 m^2 d^2 / T^3 (linear F, cubic x: Hermite-Simpson is exact)."""
    path = tmp_path / "block.toml"
    path.write_text(BLOCK)
    block = lagrangian.load(path)
    m, d, T = 2.0, 1.5, 2.0
    for method, nodes, rel in (("hermite-simpson", 6, 1e-8), ("trapezoidal", 41, 5e-3)):
        result = lagrangian.optimize(block, ["push"], T, nodes, goal={"x": d, "x_dot": 0.0},
                                     method=method)
        assert result.converged
        assert result.cost == pytest.approx(12 * m**2 * d**2 / T**3, rel=rel)
        exact = m * (6 * d / T**2 - 12 * d * result.t / T**3)
        assert np.allclose(result.inputs["push"], exact, rtol=0, atol=rel * 30)


def test_torque_limited_swing_up_both_transcriptions_agree(motor_pendulum, swing_up):
    trapezoidal = lagrangian.optimize(motor_pendulum, ["u"], 3.0, 80, **SWING_UP)
    for result in (swing_up, trapezoidal):
        assert result.converged and result.status == "Solve_Succeeded"
        assert result.defects["final_state"] < 1e-9
        assert result.defects["collocation"] < 1e-8
        assert np.abs(result.inputs["u"]).max() == pytest.approx(5.0, abs=1e-6)  # saturated
        assert result.states["theta"][-1] == pytest.approx(np.pi, abs=1e-9)
    # the continuous optimum is about 37.12 N^2 m^2 s: the two meet within 1 %, and each meets
    # the optimum the two independent tools found
    assert trapezoidal.cost == pytest.approx(swing_up.cost, rel=0.01)
    for optimum in SWING_UP_OPTIMA.values():
        assert swing_up.cost == pytest.approx(optimum, rel=0.01)
        assert trapezoidal.cost == pytest.approx(optimum, rel=0.01)
    assert swing_up.defects["replay"] < trapezoidal.defects["replay"]  # 4th against 2nd order


def test_replayed_in_simulate_the_states_follow(motor_pendulum, swing_up):
    """u(t) replayed open-loop through our simulate stays within the reported replay defect."""
    run = motor_pendulum.simulate(3.0, initial=swing_up.initial_state(),
                                  controller=swing_up.controller(), rtol=1e-10, atol=1e-10,
                                  samples=len(swing_up.t))
    assert np.allclose(run.t, swing_up.t)
    error = max(np.abs(run.q[:, 0] - swing_up.states["theta"]).max(),
                np.abs(run.q_dot[:, 0] - swing_up.states["theta_dot"]).max())
    assert error <= 1.05 * swing_up.defects["replay"] + 1e-8
    assert swing_up.defects["replay"] < 0.01
    assert "converged" in repr(swing_up) and "37.1" in repr(swing_up)


def test_a_constrained_crank_turned_rest_to_rest():
    """The slider-crank (two loop constraints) turned by a crank torque from rest at its
    initial angle to rest at 1.5 rad: the start lies on the constraints (position and velocity),
    the trajectory keeps to them within the discretisation error, and simulate replays it."""
    crank = lagrangian.load("slider_crank")
    result = lagrangian.optimize(crank, ["theta"], 1.0, 15, method="hermite-simpson",
                                 start={"theta": 1.0, "theta_dot": 0.0},
                                 goal={"theta": 1.5, "theta_dot": 0.0})
    assert result.converged and result.cost > 0
    start = result.initial_state()
    residual = crank.numeric().constraint_residual([start[k] for k in ("theta", "phi", "x")],
                                                   [start[k + "_dot"] for k in ("theta", "phi", "x")])
    assert np.abs(residual).max() < 1e-9
    assert 0 < result.defects["constraints"] < result.defects["replay"]
    run = crank.simulate(1.0, initial=start, controller=result.controller(), samples=15,
                         rtol=1e-10, atol=1e-10)
    assert np.abs(run.q[:, 0] - result.states["theta"]).max() <= result.defects["replay"]


def test_a_solve_cut_short_says_so(motor_pendulum):
    import json

    result = lagrangian.optimize(motor_pendulum, ["u"], 3.0, 10, max_iterations=2, **SWING_UP)
    assert not result.converged and result.status == "Maximum_Iterations_Exceeded"
    json.dumps(result.to_dict(), allow_nan=False)  # a JSON document whatever the solve left
    assert "not converged" in repr(result) and "not converged" in result._repr_html_()


def test_bad_requests_are_refused_in_one_line(motor_pendulum, monkeypatch):
    cases = [
        (dict(goal={"phi": 1.0}), ModelError, "'phi' is not a state"),
        (dict(start={3: 0.0}), ModelError, "'3' is not a state"),  # was an AttributeError
        (dict(bounds={"u": (5, -5)}), InputError, "above the upper bound"),
        (dict(bounds={"v": (0, 1)}), ModelError, "'v' is not a input or state"),
        (dict(method="euler"), InputError, "not one of trapezoidal, hermite-simpson"),
        (dict(objective="time"), InputError, "objective 'time'"),
        (dict(nodes=2), InputError, "nodes must be a whole number from 3"),
        (dict(t_final=-1.0), InputError, "t_final must be positive"),
    ]
    for change, error, message in cases:
        arguments = {"inputs": ["u"], "t_final": 1.0, "nodes": 5, **change}
        with pytest.raises(error, match=message) as caught:
            lagrangian.optimize(motor_pendulum, **arguments)
        assert "\n" not in str(caught.value)
    with pytest.raises(InputError, match="at least one input"):
        lagrangian.optimize(motor_pendulum, [], 1.0, 5)
    import sys

    monkeypatch.setitem(sys.modules, "casadi", None)  # as if not installed
    with pytest.raises(MissingExtraError, match=r'pip install "lagrangian\[casadi\]"'):
        lagrangian.optimize(motor_pendulum, ["u"], 1.0, 5)


def test_cli_optimize_json_and_errors(cli, tmp_path):
    import json

    path = tmp_path / "motor_pendulum.toml"
    path.write_text(MOTOR_PENDULUM)
    result = cli("optimize", str(path), "--to", "theta=pi", "--to", "theta_dot=0",
                 "--t-final", "3", "--nodes", "20", "--bound", "u=-5:5",
                 "--method", "hermite-simpson", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["converged"] is True
    assert len(document["t"]) == 20 and document["t"][-1] == 3.0
    assert document["states"]["theta"][-1] == pytest.approx(np.pi, abs=1e-9)
    assert max(map(abs, document["inputs"]["u"])) == pytest.approx(5.0, abs=1e-6)
    assert document["cost"] == pytest.approx(37.12, rel=0.01)
    text = cli("optimize", str(path), "--to", "theta=180deg", "--t-final", "3", "--nodes", "10",
               "--bound", "u=-5:5")
    assert text.code == 0 and "converged" in text.out and "effort" in text.out
    for args, message in ((["--bound", "u=5"], "expected LOWER:UPPER"),
                          (["--to", "phi=1", "--bound", "u=-5:5"], "'phi' is not a state"),
                          ([], "at least one input")):
        bad = cli("optimize", str(path), "--nodes", "5", *args)
        assert bad.code == 2 and message in bad.err and bad.err.count("\n") == 1
