"""Natural frequencies and mode shapes against closed forms and independent models."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import sympy as sp

import lagrangian
from lagrangian import SystemBuilder, cos, sin
from lagrangian.output.modes import modes_document


def shape(mode, *names):
    return [mode.shape[n] for n in names]


def test_two_mass_worked_example_3():
    analysis = lagrangian.load("two_mass").modes()
    assert analysis.stable
    np.testing.assert_allclose(analysis.mass_matrix, [[1, 0], [0, 1]])
    np.testing.assert_allclose(analysis.stiffness_matrix, [[2, -1], [-1, 2]])
    np.testing.assert_allclose(analysis.natural_frequencies, [1.0, math.sqrt(3)], rtol=1e-12)
    np.testing.assert_allclose(shape(analysis[0], "x1", "x2"), [1, 1], atol=1e-12)
    np.testing.assert_allclose(shape(analysis[1], "x1", "x2"), [1, -1], atol=1e-12)
    assert analysis[1].period == pytest.approx(2 * math.pi / math.sqrt(3))
    assert analysis[0].frequency_hz == pytest.approx(1 / (2 * math.pi))


def test_pendulum_4_43_rad_per_s():
    analysis = lagrangian.load("pendulum").modes()
    assert analysis.equilibrium == {"theta": 0.0}
    (mode,) = analysis.modes
    assert mode.frequency == pytest.approx(math.sqrt(9.81 / 0.5), rel=1e-12)
    assert round(mode.frequency, 2) == 4.43
    assert round(mode.period, 2) == 1.42
    assert mode.damping_ratio == 0 and mode.growth_rate == 0


def test_double_pendulum_equal_masses_and_lengths():
    analysis = lagrangian.load("double_pendulum").modes(about={"theta1": 0, "theta2": 0})
    g, l = 9.81, 1.0
    expected = [math.sqrt(g / l * (2 - math.sqrt(2))), math.sqrt(g / l * (2 + math.sqrt(2)))]
    np.testing.assert_allclose(analysis.natural_frequencies, expected, rtol=1e-12)
    # In-phase (1/sqrt 2, 1) and out-of-phase (-1/sqrt 2, 1), largest component +1.
    np.testing.assert_allclose(shape(analysis[0], "theta1", "theta2"), [1 / math.sqrt(2), 1])
    np.testing.assert_allclose(shape(analysis[1], "theta1", "theta2"), [-1 / math.sqrt(2), 1])


def spring_chain(n: int, *, gravity: bool = False):
    """n equal masses between two walls, n + 1 equal springs (fixed-fixed)."""
    b = SystemBuilder(f"{n}-mass chain")
    m = b.parameter("m", 1.0, "kg")
    k = b.parameter("k", 1.0, "N/m")
    xs = [b.coordinate(f"x{i}", unit="m") for i in range(1, n + 1)]
    if gravity:
        b.set_gravity(b.parameter("g", 9.81, "m/s^2"), (1, 0))
    for i, x in enumerate(xs, 1):
        b.add_particle(f"mass{i}", m, (x, 0))
    previous = 0
    for i, x in enumerate([*xs, 0]):
        b.add_spring(f"spring{i}", k, 0, length=x - previous)
        previous = x
    return b.build()


def test_fifty_mass_fixed_fixed_chain():
    n = 50
    system = spring_chain(n)
    analysis = system.modes(about={f"x{i}": 0.0 for i in range(1, n + 1)})
    k = np.arange(1, n + 1)
    expected = 2 * np.sqrt(1.0 / 1.0) * np.sin(k * np.pi / (2 * (n + 1)))
    np.testing.assert_allclose(analysis.natural_frequencies, expected, rtol=1e-10)
    # Mode j: sin(j i pi / (N + 1)) along the chain.
    i = np.arange(1, n + 1)
    for j in (1, 2, 50):
        exact = np.sin(j * i * np.pi / (n + 1))
        exact = exact / exact[np.argmax(np.abs(exact) >= np.abs(exact).max() * (1 - 1e-9))]
        np.testing.assert_allclose(shape(analysis[j - 1], *(f"x{v}" for v in i)), exact,
                                   atol=1e-9)


def test_damped_oscillator_damping_ratio():
    analysis = lagrangian.load("damped_oscillator").modes()
    (mode,) = analysis.modes
    m, k, c = 1.0, 4.0, 0.4
    assert mode.frequency == pytest.approx(math.sqrt(k / m))
    assert mode.damping_ratio == pytest.approx(c / (2 * math.sqrt(k * m)))
    assert mode.growth_rate == pytest.approx(-c / (2 * m))
    np.testing.assert_allclose(analysis.damping_matrix, [[c]])
    assert analysis.stable


def test_overdamped_oscillator_keeps_natural_frequency():
    system = lagrangian.load("damped_oscillator").with_parameters(c=10.0)
    (mode,) = system.modes().modes
    assert mode.frequency == pytest.approx(2.0)
    assert mode.damping_ratio == pytest.approx(10.0 / (2 * math.sqrt(4.0)))
    assert mode.kind == "overdamped"
    # The slower of the two real roots s = -zeta w +- w sqrt(zeta^2 - 1) sets the decay.
    assert mode.growth_rate == pytest.approx(-2.5 * 2 + 2 * math.sqrt(2.5**2 - 1))


def test_charged_particle_cyclotron_frequency():
    analysis = lagrangian.load("charged_particle").modes()
    q, B, m = 2.0, 1.5, 1.0
    oscillating = [mode for mode in analysis if mode.frequency > 0]
    assert len(oscillating) == 1
    assert oscillating[0].frequency == pytest.approx(q * B / m, rel=1e-12)
    assert oscillating[0].damping_ratio == pytest.approx(0, abs=1e-12)
    # The coupling is gyroscopic: skew-symmetric C, no stiffness; the orbit is a circle.
    np.testing.assert_allclose(analysis.damping_matrix, [[0, -q * B], [q * B, 0]])
    np.testing.assert_allclose(analysis.linear_model.gyroscopic_matrix, analysis.damping_matrix)
    circle = np.array(oscillating[0].complex_shape)
    assert abs(circle[0]) == pytest.approx(abs(circle[1]))
    assert abs(circle[1].real) == pytest.approx(0, abs=1e-12)
    # x = cos(w t), y = Re(i e^{i w t}) = -sin(w t): a positive charge circles clockwise about +B.
    assert np.angle(circle[1] / circle[0]) == pytest.approx(math.pi / 2)
    assert analysis.stable


def test_inverted_pendulum_on_cart_grows_at_closed_form_rate():
    analysis = lagrangian.load("cart_pendulum").modes(about={"theta": math.pi})
    M, m, l, g = 2.0, 0.5, 0.6, 9.81
    assert not analysis.stable
    unstable = [mode for mode in analysis if mode.growth_rate > 0]
    assert len(unstable) == 1
    assert unstable[0].frequency == 0 and unstable[0].period is None
    assert unstable[0].growth_rate == pytest.approx(math.sqrt(g * (M + m) / (M * l)), rel=1e-12)
    # The cart's free translation is a rigid-body mode, reported with zero frequency.
    rigid = [mode for mode in analysis if mode.kind == "rigid-body"]
    assert len(rigid) == 1 and rigid[0].shape == {"x": 1.0, "theta": 0.0}


def test_cart_pendulum_hanging_frequency():
    analysis = lagrangian.load("cart_pendulum").modes(about={"theta": 0})
    M, m, l, g = 2.0, 0.5, 0.6, 9.81
    assert analysis.stable
    assert analysis[-1].frequency == pytest.approx(math.sqrt(g * (M + m) / (M * l)), rel=1e-12)


def test_cartesian_pendulum_through_the_constraint():
    analysis = lagrangian.load("cartesian_pendulum").modes()
    assert analysis.equilibrium == pytest.approx({"x": 0.0, "y": -0.5})
    (mode,) = analysis.modes
    assert mode.frequency == pytest.approx(math.sqrt(9.81 / 0.5), rel=1e-12)
    assert round(mode.frequency, 2) == 4.43
    # Reported in the user's coordinates: the bob swings sideways.
    assert mode.shape == {"x": 1.0, "y": 0.0}
    assert analysis.coordinates == ("x",)
    # The rod tension 2 L lambda equals the weight; lambda Phi_qq = (m g / L) I is the stiffness.
    assert analysis.linear_model.multipliers["rod"] == pytest.approx(1.0 * 9.81 / (2 * 0.5))
    np.testing.assert_allclose(analysis.linear_model.full_stiffness_matrix,
                               np.eye(2) * 9.81 / 0.5)


def minimal_slider_crank():
    """The slider-crank of the example in one coordinate: phi and x follow from theta."""
    b = SystemBuilder("Slider-crank, minimal")
    theta = b.coordinate("theta", unit="rad", initial=1.4)
    r, l = b.parameter("r", 0.1, "m"), b.parameter("l", 0.3, "m")
    m1, m2, m3 = b.parameter("m1", 0.5, "kg"), b.parameter("m2", 1.0, "kg"), b.parameter("m3", 2.0, "kg")
    k, x0 = b.parameter("k", 500.0, "N/m"), b.parameter("x0", 0.3, "m")
    phi = sp.asin(r * sin(theta) / l)
    x = r * cos(theta) + l * cos(phi)
    b.add_body("crank", m1, m1 * r**2 / 12, (r / 2 * cos(theta), r / 2 * sin(theta)), theta)
    b.add_body("rod", m2, m2 * l**2 / 12,
               (r * cos(theta) + l / 2 * cos(phi), r * sin(theta) - l / 2 * sin(phi)), -phi)
    b.add_particle("slider", m3, (x, 0))
    b.add_spring("spring", k, x0, length=x)
    return b.build()


def test_slider_crank_matches_a_minimal_coordinate_model():
    constrained = lagrangian.load("slider_crank").modes()
    assert constrained.equilibrium["x"] == pytest.approx(0.3)
    minimal = minimal_slider_crank().modes()
    assert minimal.equilibrium["theta"] == pytest.approx(constrained.equilibrium["theta"])
    (mode,) = constrained.modes
    assert mode.frequency == pytest.approx(minimal[0].frequency, rel=1e-9)
    # Energy check: at x = x0 the spring force vanishes, so omega^2 = k x_theta^2 / m_eff.
    theta = constrained.equilibrium["theta"]
    r, l, k = 0.1, 0.3, 500.0
    phi = math.asin(r * math.sin(theta) / l)
    x_theta = -r * math.sin(theta) - l * math.sin(phi) * (r * math.cos(theta) / (l * math.cos(phi)))
    m_eff = minimal.mass_matrix[0, 0]
    assert mode.frequency**2 == pytest.approx(k * x_theta**2 / m_eff, rel=1e-9)
    # The shape in (theta, phi, x) is tangent to the constraints.
    q = np.array([mode.shape[n] for n in ("theta", "phi", "x")])
    jacobian = np.array([[r * math.cos(theta), -l * math.cos(phi), 0],
                         [r * math.sin(theta), l * math.sin(phi), 1]])
    np.testing.assert_allclose(jacobian @ q, 0, atol=1e-12)


def test_bead_on_hoop_frequencies_on_both_sides():
    g, R = 9.81, 0.5
    slow = lagrangian.load("bead_on_hoop").with_parameters(Omega=3.0)
    (mode,) = slow.modes(about={"theta": 0}).modes
    assert mode.frequency == pytest.approx(math.sqrt(g / R - 9.0))
    fast = lagrangian.load("bead_on_hoop").with_parameters(Omega=6.0)
    side = math.acos(g / (R * 36.0))
    (mode,) = fast.modes(about={"theta": side}).modes
    assert mode.frequency == pytest.approx(6.0 * math.sin(side))
    (bottom,) = fast.modes(about={"theta": 0}).modes
    assert bottom.growth_rate == pytest.approx(math.sqrt(36.0 - g / R))


def test_about_accepts_a_rounded_equilibrium_and_refines_it():
    fast = lagrangian.load("bead_on_hoop").with_parameters(Omega=6.0)
    analysis = fast.modes(about={"theta": 0.9944072})  # 7 digits typed by a person
    assert analysis.equilibrium["theta"] == pytest.approx(math.acos(9.81 / (0.5 * 36)), abs=1e-14)


def test_free_mass_with_damper_is_rigid_body_and_json_has_no_nan():
    b = SystemBuilder("damped free mass")
    x = b.coordinate("x", unit="m")
    b.add_particle("mass", b.parameter("m", 2.0, "kg"), (x, 0))
    b.add_damper("damper", b.parameter("c", 3.0, "N*s/m"), rate=b.velocity(x))
    (mode,) = b.build().modes().modes
    assert mode.frequency == 0 and mode.growth_rate == 0 and mode.period is None
    assert mode.damping_ratio is None  # c / (2 sqrt(k m)) with k = 0 has no finite value
    document = modes_document(b.build().modes())
    json.dumps(document, allow_nan=False)


@pytest.mark.parametrize("name", ["pendulum", "two_mass", "double_pendulum", "cartesian_pendulum",
                                  "cart_pendulum", "damped_oscillator", "charged_particle",
                                  "bead_on_hoop", "slider_crank", "virtual_work_link",
                                  "four_bar"])
def test_every_mode_report_is_finite_json_in_ascending_frequency(name):
    document = modes_document(lagrangian.load(name).modes())
    text = json.dumps(document, allow_nan=False)
    assert "NaN" not in text and "Infinity" not in text
    frequencies = [m["frequency"] for m in document["modes"]]
    assert frequencies == sorted(frequencies)
    for mode in document["modes"]:
        assert max(abs(v) for v in mode["shape"].values()) == pytest.approx(1.0)
        first = next(v for v in mode["shape"].values() if abs(v) >= 1 - 1e-9)
        assert first == 1.0
        assert (mode["period"] is None) == (mode["frequency"] == 0)


def test_tilted_gravity_uses_the_mass_matrix_at_the_equilibrium():
    """Cart on a spring with a pendulum, gravity tilted by beta: at rest theta = beta and the
    coupling m l cos(beta) of M(q0) enters; no dM/dq term may appear (q_ddot = 0 there)."""
    beta, Mc, m, l, g, k = 0.4, 2.0, 0.5, 0.6, 9.81, 30.0
    b = SystemBuilder("tilted cart pendulum")
    x = b.coordinate("x", unit="m")
    theta = b.coordinate("theta", unit="rad", range=(-math.pi, math.pi))
    b.set_gravity(g, (math.sin(beta), -math.cos(beta)))
    b.add_particle("cart", Mc, (x, 0))
    b.add_particle("bob", m, (x + l * sin(theta), -l * cos(theta)))
    b.add_spring("spring", k, 0, length=x)
    analysis = b.build().modes(about={"theta": beta})
    x0 = (Mc + m) * g * math.sin(beta) / k
    assert analysis.equilibrium["x"] == pytest.approx(x0, rel=1e-12)
    mass = np.array([[Mc + m, m * l * math.cos(beta)], [m * l * math.cos(beta), m * l**2]])
    stiffness = np.diag([k, m * g * l])
    np.testing.assert_allclose(analysis.mass_matrix, mass, rtol=1e-12)
    np.testing.assert_allclose(analysis.stiffness_matrix, stiffness, rtol=1e-12, atol=1e-12)
    import scipy.linalg

    expected = np.sqrt(scipy.linalg.eigh(stiffness, mass, eigvals_only=True))
    np.testing.assert_allclose(analysis.natural_frequencies, expected, rtol=1e-12)


def test_four_bar_against_the_energy_method():
    """Along the mechanism V(theta1) and T = 1/2 m_eff theta1_dot^2; at rest omega^2 = V'' / m_eff.
    The loop is closed numerically for each crank angle: no multiplier, no projection."""
    analysis = lagrangian.load("four_bar").modes()
    a, b, c, d = 0.1, 0.35, 0.3, 0.3
    m1, m2, m3, k, g = 0.2, 0.5, 0.4, 2.0, 9.81
    start = np.array([analysis.equilibrium[n] for n in ("theta2", "theta3")])

    def close(t1):
        t = start.copy()
        for _ in range(50):
            t2, t3 = t
            residual = np.array([a * math.cos(t1) + b * math.cos(t2) - c * math.cos(t3) - d,
                                 a * math.sin(t1) + b * math.sin(t2) - c * math.sin(t3)])
            jacobian = np.array([[-b * math.sin(t2), c * math.sin(t3)],
                                 [b * math.cos(t2), -c * math.cos(t3)]])
            t = t - np.linalg.solve(jacobian, residual)
        return t

    def centres(t1):
        t2, t3 = close(t1)
        return np.array([[a / 2 * math.cos(t1), a / 2 * math.sin(t1)],
                         [a * math.cos(t1) + b / 2 * math.cos(t2),
                          a * math.sin(t1) + b / 2 * math.sin(t2)],
                         [d + c / 2 * math.cos(t3), c / 2 * math.sin(t3)]]), np.array([t1, t2, t3])

    masses = np.array([m1, m2, m3])
    inertias = masses * np.array([a, b, c]) ** 2 / 12

    def potential(t1):
        r, _ = centres(t1)
        return k * t1**2 / 2 + g * masses @ r[:, 1]

    t1, h = analysis.equilibrium["theta1"], 1e-4
    slope = (potential(t1 + h) - potential(t1 - h)) / (2 * h)
    curvature = (potential(t1 + h) - 2 * potential(t1) + potential(t1 - h)) / h**2
    (r_plus, angles_plus), (r_minus, angles_minus) = centres(t1 + h), centres(t1 - h)
    velocity = (r_plus - r_minus) / (2 * h)
    rate = (angles_plus - angles_minus) / (2 * h)
    m_eff = masses @ np.sum(velocity**2, axis=1) + inertias @ rate**2
    assert abs(slope) < 1e-6 * abs(curvature)  # it is an equilibrium along the mechanism
    (mode,) = analysis.modes
    assert mode.frequency**2 == pytest.approx(curvature / m_eff, rel=1e-6)
    # The shape follows the loop: (1, dtheta2/dtheta1, dtheta3/dtheta1).
    np.testing.assert_allclose([mode.shape[n] for n in ("theta1", "theta2", "theta3")], rate,
                               rtol=1e-6)


def test_gyroscopic_stabilization_in_a_rotating_frame():
    """An isotropic oscillator (omega0 = sqrt(k/m)) seen from a frame turning at Omega > omega0:
    the centrifugal term makes K negative definite, yet the Coriolis coupling keeps it stable,
    with frequencies Omega -+ omega0. K - omega^2 M alone would call it unstable."""
    m, k, spin = 1.0, 1.0, 3.0
    b = SystemBuilder("oscillator in a rotating frame")
    x, y = b.coordinate("x", unit="m"), b.coordinate("y", unit="m")
    xd, yd = b.velocity(x), b.velocity(y)
    b.add_kinetic_energy(m / 2 * ((xd - spin * y) ** 2 + (yd + spin * x) ** 2))
    b.add_potential_energy(k / 2 * (x**2 + y**2))
    analysis = b.build().modes()
    np.testing.assert_allclose(analysis.stiffness_matrix, (k - m * spin**2) * np.eye(2))
    np.testing.assert_allclose(analysis.linear_model.gyroscopic_matrix,
                               [[0, -2 * m * spin], [2 * m * spin, 0]])
    assert analysis.stable
    np.testing.assert_allclose(analysis.natural_frequencies,
                               [spin - math.sqrt(k / m), spin + math.sqrt(k / m)], rtol=1e-12)
    assert all(mode.growth_rate == 0 for mode in analysis)


@pytest.mark.parametrize("c", [4e-7, 4.0, 0.4, 40.0])
def test_damping_ratio_from_tiny_to_critical_to_heavy(c):
    (mode,) = lagrangian.load("damped_oscillator").with_parameters(c=c).modes().modes
    assert mode.frequency == pytest.approx(2.0, rel=1e-6)
    assert mode.damping_ratio == pytest.approx(c / (2 * math.sqrt(4.0 * 1.0)), rel=1e-6)
