"""The public face (issue 26): option types, dynamics, code generation and errors are all
importable from `lagrangian`, the option types are accepted by System.simulate and System.sweep
(the plain keywords kept as a thin shim), and System.to_c gives the C the CLI writes."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

import lagrangian
from lagrangian.compile import compiled


def test_every_returned_or_raised_type_is_exported():
    for name in ("StepControl", "SaveAt", "StopCondition", "Dynamics", "SpeedForm", "SpeedSweep",
                 "StandaloneSource", "BackendUnavailable", "CompilerMissing", "CacheRefused",
                 "Simulation", "LinearModel", "ModelError", "LagrangianError"):
        assert name in lagrangian.__all__ and getattr(lagrangian, name) is not None
    assert issubclass(lagrangian.CacheRefused, lagrangian.LagrangianError)
    assert issubclass(lagrangian.CompilerMissing, lagrangian.BackendUnavailable)


def test_option_types_give_the_same_run_as_the_plain_keywords():
    """theta_ddot = -(g/L) sin(theta): both runs are one run, and T + V is kept."""
    pendulum = lagrangian.load("pendulum")
    plain = pendulum.simulate(1.0, method="RK45", rtol=1e-10, atol=1e-10, samples=11)
    typed = pendulum.simulate(1.0, step_control=lagrangian.StepControl("RK45", 1e-10, 1e-10),
                              save_at=lagrangian.SaveAt(11))
    np.testing.assert_array_equal(plain.q, typed.q)
    assert len(typed.t) == 11
    assert np.ptp(typed.energy) < 1e-8 * abs(typed.energy[0])


def test_a_stop_condition_object_is_accepted():
    pendulum = lagrangian.load("pendulum")
    stop = lagrangian.load("pendulum").simulate(5.0, stop_when="theta < 0").t[-1]
    from lagrangian.simulation.events import parse_stop_condition

    condition = parse_stop_condition("theta < 0", pendulum.model)
    assert isinstance(condition, lagrangian.StopCondition)
    assert pendulum.simulate(5.0, stop_when=condition).t[-1] == stop
    # a quarter period of the small-amplitude pendulum (theta0 = 0.3): pi/2 sqrt(L/g), +0.6 %
    assert stop == pytest.approx(np.pi / 2 * np.sqrt(0.5 / 9.81), rel=1e-2)


def test_an_option_given_twice_is_refused():
    pendulum = lagrangian.load("pendulum")
    with pytest.raises(lagrangian.ModelError, match="not both"):
        pendulum.simulate(1.0, step_control=lagrangian.StepControl("RK45"), method="RK23")
    with pytest.raises(lagrangian.ModelError, match="not both"):
        pendulum.simulate(1.0, save_at=lagrangian.SaveAt(11), samples=21)
    with pytest.raises(lagrangian.ModelError, match="StepControl"):
        pendulum.simulate(1.0, step_control="RK45")


def test_to_c_equals_what_the_cli_writes(cli, tmp_path):
    code = lagrangian.load("two_link_arm").to_c("arm")
    assert isinstance(code, lagrangian.StandaloneSource)
    assert cli("codegen", "two_link_arm", "--out", str(tmp_path), "--name", "arm").code == 0
    assert (tmp_path / "arm.h").read_text() == code.header
    assert (tmp_path / "arm.c").read_text() == code.source


@pytest.mark.skipif(not compiled.available(), reason="no C compiler")
def test_to_c_of_the_pendulum_computes_its_closed_form(tmp_path):
    """M = m L^2, g(q) = m g L sin(theta) with the parameters compiled in (g = 3.71: Mars)."""
    from lagrangian.output.files import write_c

    code = lagrangian.load("pendulum").to_c(parameters={"g": 3.71})
    write_c(code, tmp_path)
    P = code.prefix
    (tmp_path / "main.c").write_text(
        f'#include <stdio.h>\n#include "{P}.h"\nint main(void) {{ double q[1] = {{0.3}}, M[1], '
        f'g[1]; {P}_mass_matrix(q, {P}_parameters, M); {P}_gravity(q, {P}_parameters, g); '
        'printf("%.17g %.17g\\n", M[0], g[0]); return 0; }\n')
    exe = tmp_path / "main"
    subprocess.run([*compiled.check_compiler(), "-std=c99", "-Wall", "-Werror", "-O2",
                    str(tmp_path / "main.c"), str(tmp_path / f"{P}.c"), "-o", str(exe), "-lm"],
                   check=True, capture_output=True)
    mass, gravity = map(float, subprocess.run([str(exe)], capture_output=True, text=True,
                                              check=True).stdout.split())
    assert mass == pytest.approx(1.0 * 0.5**2, rel=1e-15)
    assert gravity == pytest.approx(1.0 * 3.71 * 0.5 * np.sin(0.3), rel=1e-15)


def test_to_c_refuses_a_bad_prefix_and_an_unknown_parameter():
    arm = lagrangian.load("two_link_arm")
    with pytest.raises(lagrangian.ModelError, match="not a C identifier"):
        arm.to_c("my arm")
    with pytest.raises(lagrangian.ModelError, match="not a parameter"):
        arm.to_c(parameters={"gg": 1.0})


def test_every_dynamics_path_returns_the_one_dynamics_type():
    """A URDF arm (recursive C, recursive numpy) and a model file (derived equations) give a
    lagrangian.Dynamics with the same M at the same state: the two-link arm's closed form."""
    arm = lagrangian.load("two_link_arm")
    for backend in ("auto", "numpy"):
        dynamics = arm.dynamics(backend=backend)
        assert isinstance(dynamics, lagrangian.Dynamics)
        M = dynamics.mass_matrix([0.3, 0.7])
        np.testing.assert_allclose(M[1, 1], 0.34, rtol=1e-12)
        np.testing.assert_allclose(M[0, 0], 2.54 + 1.2 * np.cos(0.7), rtol=1e-12)
    pendulum = lagrangian.load("pendulum").dynamics()
    assert isinstance(pendulum, lagrangian.Dynamics)
    assert pendulum.coordinates == ("theta",) and pendulum.n == 1


def test_the_functions_the_command_line_uses_are_public():
    """The CLI is a client of `lagrangian` (import contract in pyproject.toml): what it reads
    with is public, e.g. 30deg is pi/6 rad and 0.5 min is 30 s."""
    assert lagrangian.parse_quantity("30deg", "rad", "x") == pytest.approx(np.pi / 6)
    assert lagrangian.parse_quantity("0.5 min", "s", "t") == pytest.approx(30.0)
    assert "pendulum" in lagrangian.example_names()
    assert "DOP853" in lagrangian.SIMULATION_METHODS
    lines = lagrangian.bare_angle_warnings("--at", [("theta", "30")], {"theta": "rad"},
                                           {"theta": 30.0})
    assert len(lines) == 1 and "30deg" in lines[0]
    assert lagrangian.bare_angle_warnings("--at", [("theta", "3")], {"theta": "rad"},
                                          {"theta": 3.0}) == []


def test_one_simulation_type():
    """System.simulate returns a Simulation; the old name SimulationResult is that same type."""
    assert lagrangian.SimulationResult is lagrangian.Simulation
    run = lagrangian.load("pendulum").simulate(0.1)
    assert type(run) is lagrangian.Simulation


def test_the_command_lines_own_helpers_are_not_the_public_face():
    """Names that only the CLI uses (issue 38) are out of ``__all__`` and ``dir()``, yet found
    on the package (the CLI imports nothing else) and public in their own modules."""
    from lagrangian.model.values import resolve_state

    helpers = lagrangian._CLI_HOMES
    assert "resolve_state" in helpers and "state_units" in helpers
    for name in helpers:
        assert name not in lagrangian.__all__
        assert getattr(lagrangian, name) is not None
        assert name not in dir(lagrangian)
    assert lagrangian.resolve_state is resolve_state
    # still every one of the API's names, and the functions the documentation uses
    for name in ("load", "System", "example_path", "parse_steady_rates", "lqr", "sin"):
        assert name in lagrangian.__all__
