"""System.to_fmu / `lagrangian export --fmu`: an FMI 2.0 FMU (Model Exchange and Co-Simulation)
that passes fmpy's validation, and whose simulation by fmpy matches closed forms and our own
simulate."""

from __future__ import annotations

import re
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

import lagrangian
from lagrangian.errors import InputError


@pytest.fixture(scope="module")
def pendulum_fmu(tmp_path_factory):
    system = lagrangian.load("pendulum")
    return system, system.to_fmu(tmp_path_factory.mktemp("fmu") / "pendulum.fmu")


def crossings(t, x):
    """Times where x crosses 0 upwards, by linear interpolation."""
    i = np.nonzero((x[:-1] < 0) & (x[1:] >= 0))[0]
    return t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])


def test_the_fmu_passes_fmpys_validation(pendulum_fmu):
    _, path = pendulum_fmu
    assert validate_fmu(str(path)) == []
    description = read_model_description(str(path))
    assert description.fmiVersion == "2.0" and description.modelExchange is not None
    assert description.coSimulation is not None
    kinds = {v.name: (v.causality, v.variability) for v in description.modelVariables}
    assert kinds["theta"] == ("output", "continuous")
    assert kinds["theta_dot"] == ("output", "continuous")
    assert kinds["L"] == ("parameter", "tunable")
    assert kinds["Q_theta"] == ("input", "continuous")


@pytest.mark.parametrize("kind", ["ModelExchange", "CoSimulation"])
def test_fmpy_matches_our_simulate(pendulum_fmu, kind):
    """fmpy's CVode on the Model Exchange FMU, and the Co-Simulation FMU's own Runge-Kutta."""
    system, path = pendulum_fmu
    result = simulate_fmu(str(path), stop_time=3.0, output_interval=0.01,
                          relative_tolerance=1e-11, fmi_type=kind)
    run = system.simulate(3.0, samples=301, rtol=1e-11, atol=1e-11)
    assert np.allclose(result["time"], run.t, atol=1e-12)
    assert np.abs(result["theta"] - run.q[:, 0]).max() < 1e-6
    assert np.abs(result["theta_dot"] - run.q_dot[:, 0]).max() < 1e-6


def test_small_angle_period_and_a_tuned_length(pendulum_fmu):
    """T = 4 sqrt(L/g) K(sin^2(theta0/2)) = 2 pi sqrt(L/g) (1 + theta0^2/16 + ...): 0.001 rad
    away, the small-angle period within 1e-6 (the amplitude's share 6e-8) and the exact one
    within 1e-9; L tuned to 2 m in the FMU (a tunable parameter) gives the longer pendulum's."""
    from scipy.special import ellipk

    system, path = pendulum_fmu
    g, theta0 = system.parameters["g"], 0.001
    for L in (system.parameters["L"], 2.0):
        result = simulate_fmu(str(path), stop_time=6.0, output_interval=0.001,
                              relative_tolerance=1e-11,
                              start_values={"theta": theta0, "L": L})
        up = crossings(result["time"], result["theta_dot"])
        period = float(np.mean(np.diff(up)))
        assert period == pytest.approx(2 * np.pi * np.sqrt(L / g), rel=1e-6)
        assert period == pytest.approx(4 * np.sqrt(L / g) * ellipk(np.sin(theta0 / 2) ** 2),
                                       rel=1e-9)


def test_two_coordinates_and_the_cli(cli, tmp_path):
    path = tmp_path / "double.fmu"
    result = cli("export", "double_pendulum", "--fmu", str(path), "--set", "m2=0.5")
    assert result.code == 0, result.err
    assert "written to" in result.out and path.exists()
    assert validate_fmu(str(path)) == []
    system = lagrangian.load("double_pendulum").with_parameters(m2=0.5)
    fmu = simulate_fmu(str(path), stop_time=2.0, output_interval=0.01, relative_tolerance=1e-11)
    run = system.simulate(2.0, samples=201, rtol=1e-11, atol=1e-11)
    for k, name in enumerate(("theta1", "theta2")):
        assert np.abs(fmu[name] - run.q[:, k]).max() < 1e-6
    for args, message in ((["double_pendulum"], "--fmu out.fmu"),
                          (["slider_crank", "--fmu", str(tmp_path / "s.fmu")],
                           "without constraints"),
                          (["pendulum", "--fmu", str(tmp_path / "p.zip")], "does not end in .fmu")):
        bad = cli("export", *args)
        assert bad.code == 2 and message in bad.err and bad.err.count("\n") == 1


HOSTILE = """
name = "Evil */ #include <stdio.h> int main() { return system(0); } /*"
description = "</description><script/> ]]>"
[coordinates]
x = { unit = "m", initial = 0.1 }
[parameters]
k = { value = 2.0, unit = "N/m" }
m = { value = 0.5, unit = "kg" }
[energy]
T = "1/2*m*x_dot^2"
V = "1/2*k*x^2"
"""


def test_no_user_text_reaches_the_c(tmp_path):
    """A model's name and description are in the XML (escaped) and, made harmless, in a C
    comment only, never in the code; and the oscillator's period is 2 pi sqrt(m/k)."""
    system = lagrangian.System(lagrangian.parse_model(HOSTILE))
    path = system.to_fmu(tmp_path / "oscillator.fmu")
    with zipfile.ZipFile(path) as archive:
        c_files = [archive.read(n).decode() for n in archive.namelist()
                   if n.startswith("sources/")]
    assert c_files and not any("#include <stdio.h>" in text for text in c_files)
    code = [re.sub(r"/\*.*?\*/", "", text, flags=re.S) for text in c_files]  # comments out
    assert not any("Evil" in text or "system(" in text for text in code)
    assert validate_fmu(str(path)) == []
    assert read_model_description(str(path)).modelName == system.name
    result = simulate_fmu(str(path), stop_time=5.0, output_interval=0.001,
                          relative_tolerance=1e-11)
    period = float(np.mean(np.diff(crossings(result["time"], result["x_dot"]))))
    assert period == pytest.approx(2 * np.pi * np.sqrt(0.5 / 2.0), rel=1e-6)
    with pytest.raises(InputError, match="does not end in .fmu"):
        system.to_fmu(tmp_path / "oscillator.zip")
