"""Control laws written in the model file ([control]): compiled with the equations, they give
the same run as the same law as a Python callable, and the closed-loop closed forms; bad
tables are one line naming the file, the field and the fault."""

from __future__ import annotations

import json

import numpy as np
import pytest

import lagrangian
from control_models import PENDULUM
from lagrangian.errors import InputError, ModelError
from lagrangian.model.examples import example_path

TIGHT = {"rtol": 1e-12, "atol": 1e-12}


def _system(tmp_path, text: str, name: str = "model.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return lagrangian.load(path)


def test_a_pd_law_in_the_file_is_the_same_run_as_the_callable(tmp_path):
    system = _system(tmp_path, PENDULUM + '[control]\ntheta = "-Kp*(theta - theta_ref) - '
                     'Kd*theta_dot"\n')
    run = system.simulate(4, controller="model", samples=81, **TIGHT)

    def pd(t, q, v):
        return -4.0 * (q - 0.2 * np.sin(t)) - 2.0 * v

    reference = system.simulate(4, controller=pd, samples=81, **TIGHT)
    assert np.abs(run.q - reference.q).max() < 1e-8
    assert np.abs(run.q_dot - reference.q_dot).max() < 1e-8
    assert np.abs(run.controls - reference.controls).max() < 1e-8
    assert run.control_names == ("theta",)
    assert run.summary()["invariant"] == "work_balance"


def test_a_tracking_law_reaches_its_critically_damped_closed_form(tmp_path):
    # The law cancels gravity and feeds the reference's acceleration forward, so the error
    # e = theta - a sin t obeys m L^2 e'' + Kd e' + Kp e = 0: with Kp = m L^2 w^2 and
    # Kd = 2 m L^2 w, e = (e0 + (e0' + w e0) t) exp(-w t), w = 4 rad/s.
    law = ('theta = "m*g*L*sin(theta) - m*L^2*a*sin(t) + Kd*(a*cos(t) - theta_dot) '
           '+ Kp*(theta_ref - theta)"\n')
    system = _system(tmp_path, PENDULUM + "[control]\n" + law)
    run = system.simulate(3, controller="model", samples=61, **TIGHT)
    w, e0, de0 = 4.0, 0.3, -0.2  # theta(0) = 0.3, theta_dot(0) = 0, reference rate a = 0.2
    error = (e0 + (de0 + w * e0) * run.t) * np.exp(-w * run.t)
    assert np.abs(run.q[:, 0] - 0.2 * np.sin(run.t) - error).max() < 1e-9


def test_small_motion_follows_the_closed_loop_eigenvalues(tmp_path):
    # m L^2 theta'' + Kd theta' + (Kp + m g L) theta = 0 for small theta.
    system = _system(tmp_path, PENDULUM + '[control]\ntheta = "-Kp*theta - Kd*theta_dot"\n')
    theta0 = 1e-4
    run = system.simulate(2, initial={"theta": theta0}, controller="model", samples=41, **TIGHT)
    s = np.roots([0.25, 2.0, 4.0 + 9.81 * 0.5])  # a complex pair
    c = np.linalg.solve(np.array([[1, 1], s]), [theta0, 0.0])
    linear = np.real(np.exp(np.outer(run.t, s)) @ c)
    assert np.abs(run.q[:, 0] - linear).max() < 1e-6 * theta0


def test_a_law_on_a_load_and_on_a_constrained_model(tmp_path):
    # A law on the cart's push force F (a load's parameter: B = df/dF) ...
    cart = example_path("cart_pendulum").read_text(encoding="utf-8")
    system = _system(tmp_path, cart + '\n[control]\npush = "-5*x - 3*x_dot + 10*theta"\n')
    run = system.simulate(2, controller="model", samples=21, **TIGHT)
    reference = system.simulate(2, controller=lambda t, q, v: -5 * q[0] - 3 * v[0] + 10 * q[1],
                                inputs=["F"], samples=21, **TIGHT)
    assert np.abs(run.q - reference.q).max() < 1e-8
    # ... and on a coordinate of a model with a constraint (the rod's multiplier included).
    bob = example_path("cartesian_pendulum").read_text(encoding="utf-8")
    system = _system(tmp_path, bob + '\n[control]\nx = "-3*x - 0.5*x_dot"\n', "bob.toml")
    run = system.simulate(1, controller="model", samples=11, **TIGHT)
    reference = system.simulate(1, controller=lambda t, q, v: [-3 * q[0] - 0.5 * v[0], 0.0],
                                samples=11, **TIGHT)
    assert np.abs(run.q - reference.q).max() < 1e-8
    assert np.abs(run.multipliers - reference.multipliers).max() < 1e-6


def test_derive_is_unchanged_by_a_control_table(tmp_path):
    plain = _system(tmp_path, PENDULUM, "plain.toml").equations_of_motion()
    law = _system(tmp_path, PENDULUM + '[control]\ntheta = "-Kp*theta"\n').equations_of_motion()
    assert plain.forcing == law.forcing and plain.mass_matrix == law.mass_matrix


@pytest.mark.parametrize("table, field, fault", [
    ('theta = "-Kq*theta"', "control.theta", "unknown name 'Kq'"),
    ('nope = "-Kp*theta"', "control.nope", "'nope' is not a parameter, load or coordinate"),
    ('theta_dot = "1"', "control.theta_dot", "is not a parameter, load or coordinate"),
    ("theta = 5", "control.theta", "expected a string"),
    ('theta = ["-theta"]', "control.theta", "expected a string"),
    ('theta = "-Kp*theta +"', "control.theta", "ends too early"),
])
def test_a_bad_control_table_is_one_line(tmp_path, table, field, fault):
    with pytest.raises(ModelError) as caught:
        _system(tmp_path, PENDULUM + "[control]\n" + table + "\n", "bad.toml")
    assert caught.value.field == field and caught.value.source.endswith("bad.toml")
    assert fault in caught.value.message and "\n" not in str(caught.value)


def test_a_law_on_an_inertia_or_without_a_table_is_refused(tmp_path):
    system = _system(tmp_path, PENDULUM + '[control]\nm = "1"\n')
    with pytest.raises(ModelError, match="control: input 'm' enters the mass matrix"):
        system.simulate(1, controller="model")
    with pytest.raises(InputError, match="no \\[control\\] table"):
        lagrangian.load("pendulum").simulate(1, controller="model")
    with pytest.raises(InputError, match="name their own inputs"):
        system.simulate(1, controller="model", inputs=["theta"])
    with pytest.raises(InputError, match="unknown controller 'modle'"):
        system.simulate(1, controller="modle")


def test_the_command_line_runs_the_file_law(tmp_path, cli):
    path = tmp_path / "pd.toml"
    path.write_text(PENDULUM + '[control]\ntheta = "-Kp*theta - Kd*theta_dot"\n',
                    encoding="utf-8")
    result = cli("simulate", str(path), "--t-end", "1", "--control", "model", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["control"] == {"kind": "model", "inputs": ["theta"],
                                   "laws": {"theta": "-Kd*theta_dot - Kp*theta"}}
    result = cli("simulate", "pendulum", "--t-end", "1", "--control", "model")
    assert result.code == 2 and result.err.strip().splitlines() == [
        "error: --control: the model has no [control] table: no laws of its own to run"]
    result = cli("simulate", str(path), "--t-end", "1", "--control", "model", "--kp", "3")
    assert result.code == 2 and "--kp is not used by --control model" in result.err


def test_a_gain_set_from_the_command_line_changes_the_run_without_a_warning(tmp_path, cli):
    # the law cancels gravity: m L^2 theta'' = -Kp theta - Kd theta', so a stiffer Kp (16)
    # with Kd = 2 sqrt(Kp m L^2) settles as (1 + w t) exp(-w t), w = sqrt(Kp / (m L^2)) = 8
    path = tmp_path / "pd.toml"
    path.write_text(PENDULUM + '[control]\ntheta = "m*g*L*sin(theta) - Kp*theta - '
                    'Kd*theta_dot"\n', encoding="utf-8")
    result = cli("simulate", str(path), "--t-end", "1", "--set", "Kp=16,Kd=4", "--control",
                 "model", "--rtol", "1e-12", "--atol", "1e-12", "--json")
    assert result.code == 0 and "warning" not in result.err, result.err
    w = 8.0
    expected = 0.3 * (1 + w) * np.exp(-w)
    assert json.loads(result.out)["final_state"]["theta"] == pytest.approx(expected, rel=1e-7)


def test_a_law_from_the_python_builder():
    b = lagrangian.SystemBuilder("PD pendulum")
    theta = b.coordinate("theta", unit="rad", initial=0.3)
    m, L, g = b.parameter("m", 1.0), b.parameter("L", 0.5), b.parameter("g", 9.81)
    b.add_kinetic_energy(m * L**2 * b.velocity("theta") ** 2 / 2)
    b.add_potential_energy(-m * g * L * lagrangian.cos(theta))
    b.add_control_law("theta", m * g * L * lagrangian.sin(theta) - 4 * theta
                      - 2 * b.velocity("theta"))
    run = b.build().simulate(1, controller="model", samples=11, **TIGHT)
    w = 4.0  # Kp = 4 = m L^2 w^2, Kd = 2 = 2 m L^2 w: critically damped
    np.testing.assert_allclose(run.q[:, 0], 0.3 * (1 + w * run.t) * np.exp(-w * run.t),
                               atol=1e-9)
