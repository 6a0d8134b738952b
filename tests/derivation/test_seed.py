"""The seed's worked examples and practice ladder, asserted as numbers (course module 7)."""

import math

import pytest
import sympy as sp

import lagrangian

pytestmark = pytest.mark.smoke  # pytest -m smoke: the quick subset


def small_angle_frequency(name: str, coordinate: str) -> float:
    """omega_n from the linear term of the equation: omega^2 = -(df/dq)/M at q = 0."""
    system = lagrangian.load(name)
    eom = system.equations_of_motion()
    q = system.symbol(coordinate)
    values = {system.symbol(p): v for p, v in system.parameters.items()}
    values.update({s: 0 for s in system.coordinates + system.velocities})
    stiffness = -eom.forcing[0].diff(q).xreplace(values)
    mass = eom.mass_matrix[0, 0].xreplace(values)
    return math.sqrt(float(stiffness / mass))


def test_worked_example_1_pendulum_equation_and_frequency():
    system = lagrangian.load("pendulum")
    eom = system.equations_of_motion()
    theta, m, L, g = (system.symbol(n) for n in ("theta", "m", "L", "g"))
    theta_ddot = system.symbol("theta_ddot")
    # d/dt(m L^2 theta_dot) + m g L sin(theta) = 0
    assert sp.expand(eom.equations[0] - (m * L**2 * theta_ddot + m * g * L * sp.sin(theta))) == 0
    assert eom.accelerations[0] == -g * sp.sin(theta) / L  # the mass cancels
    omega = small_angle_frequency("pendulum", "theta")
    assert omega == pytest.approx(4.43, abs=0.005)
    assert 2 * math.pi / omega == pytest.approx(1.42, abs=0.005)
    assert eom.generalized_forces[0] == 0  # no joint reaction ever appears


def test_worked_example_2_generalized_force_by_virtual_work():
    system = lagrangian.load("virtual_work_link")
    eom = system.equations_of_motion()
    theta, F, L = (system.symbol(n) for n in ("theta", "F", "L"))
    assert eom.generalized_forces[0] == F * L * sp.cos(theta)
    report = system.generalized_forces_at({"theta": math.radians(30)})
    assert report.generalized_forces["theta"] == pytest.approx(43.30, abs=0.005)
    assert report.units["theta"] == "N*m"
    # Q falls to zero at 90 deg, where the force is along the link.
    assert system.generalized_forces_at({"theta": math.pi / 2}).generalized_forces["theta"] == \
        pytest.approx(0, abs=1e-12)


def test_worked_example_3_two_mass_matrices():
    system = lagrangian.load("two_mass")
    eom = system.equations_of_motion()
    m, k, k_c = (system.symbol(n) for n in ("m", "k", "k_c"))
    x = sp.Matrix(system.coordinates)
    assert eom.mass_matrix == sp.Matrix([[m, 0], [0, m]])
    stiffness = -eom.forcing.jacobian(x)
    assert sp.expand(stiffness - sp.Matrix([[k + k_c, -k_c], [-k_c, k + k_c]])) == sp.zeros(2, 2)
    numbers = {m: 1, k: 1, k_c: 1}
    eigen = sorted(float(v) for v in (stiffness.xreplace(numbers)).eigenvals())
    assert eigen == pytest.approx([1.0, 3.0])  # omega^2 = 1 and 3


def test_ladder_level_1_two_metre_pendulum():
    assert small_angle_frequency("ladder_pendulum", "theta") == pytest.approx(2.21, abs=0.005)


def test_ladder_level_2_vertical_force_gives_no_generalized_force_at_zero():
    system = lagrangian.load("ladder_vertical_force")
    theta, F, L = (system.symbol(n) for n in ("theta", "F", "L"))
    assert system.equations_of_motion().generalized_forces[0] == -F * L * sp.sin(theta)
    assert system.generalized_forces_at({"theta": 0.0}).generalized_forces["theta"] == 0
    assert system.generalized_forces_at({"theta": 0.5}).generalized_forces["theta"] == \
        pytest.approx(-60 * 0.4 * math.sin(0.5))


def test_ladder_level_3_spring_mass():
    system = lagrangian.load("ladder_spring_mass")
    eom = system.equations_of_motion()
    x, m, k = (system.symbol(n) for n in ("x", "m", "k"))
    assert sp.expand(eom.equations[0] - (m * system.symbol("x_ddot") + k * x)) == 0
    assert eom.lagrangian == m * system.symbol("x_dot") ** 2 / 2 - k * x**2 / 2
    assert small_angle_frequency("ladder_spring_mass", "x") == pytest.approx(math.sqrt(50 / 2))
