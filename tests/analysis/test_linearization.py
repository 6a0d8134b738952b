"""Linear models for control: M, C, K, state-space A, B with inputs; symbolic matrices; speed."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

import lagrangian
from lagrangian import ModelError, SystemBuilder

M_CART, M_BOB, L, G = 2.0, 0.5, 0.6, 9.81


def test_cart_pendulum_state_space_with_the_push_as_input():
    lm = lagrangian.load("cart_pendulum").linearize(about={"theta": math.pi}, inputs=["push"])
    assert lm.state_names == ("x", "theta", "x_dot", "theta_dot")
    assert lm.inputs == ("push",)
    # Closed form about the upright position (phi = theta - pi):
    # (M + m) x'' - m l phi'' = F,  -m l x'' + m l^2 phi'' - m g l phi = 0.
    mass = np.array([[M_CART + M_BOB, -M_BOB * L], [-M_BOB * L, M_BOB * L**2]])
    stiffness = np.array([[0, 0], [0, -M_BOB * G * L]])
    np.testing.assert_allclose(lm.M, mass, atol=1e-12)
    np.testing.assert_allclose(lm.K, stiffness, atol=1e-12)
    np.testing.assert_allclose(lm.C, 0)
    A = np.block([[np.zeros((2, 2)), np.eye(2)],
                  [-np.linalg.solve(mass, stiffness), np.zeros((2, 2))]])
    B = np.concatenate([[0, 0], np.linalg.solve(mass, [1.0, 0.0])])[:, None]
    np.testing.assert_allclose(lm.A, A, atol=1e-12)
    np.testing.assert_allclose(lm.B, B, atol=1e-12)
    # Textbook entries: x'' = m g / M phi + F / M,  phi'' = (M + m) g / (M l) phi + F / (M l).
    assert lm.A[2, 1] == pytest.approx(M_BOB * G / M_CART)
    assert lm.A[3, 1] == pytest.approx((M_CART + M_BOB) * G / (M_CART * L))
    assert lm.B[2, 0] == pytest.approx(1 / M_CART)
    assert lm.B[3, 0] == pytest.approx(1 / (M_CART * L))


def test_parameter_and_generalized_force_inputs_agree_with_the_load():
    system = lagrangian.load("cart_pendulum")
    by_load = system.linearize(about={"theta": math.pi}, inputs=["push"])
    by_parameter = system.linearize(about={"theta": math.pi}, inputs=["F"])
    by_coordinate = system.linearize(about={"theta": math.pi}, inputs=["x", "theta"])
    np.testing.assert_allclose(by_parameter.B, by_load.B)
    np.testing.assert_allclose(by_coordinate.B[:, :1], by_load.B)
    # A torque on theta: B column M^-1 e_theta.
    mass = by_load.M
    np.testing.assert_allclose(by_coordinate.B[2:, 1], np.linalg.solve(mass, [0.0, 1.0]))


def test_state_space_works_with_scipy_signal():
    import scipy.signal

    lm = lagrangian.load("damped_oscillator").linearize(inputs=["x"])
    A, B, C, D = lm.state_space()
    system = scipy.signal.StateSpace(A, B, C, D)
    # x'' + 0.4 x' + 4 x = u: poles -0.2 +- i sqrt(4 - 0.04), static gain 1/k on x.
    poles = np.sort_complex(np.linalg.eigvals(system.A))
    np.testing.assert_allclose(poles, [-0.2 - 1j * math.sqrt(3.96), -0.2 + 1j * math.sqrt(3.96)])
    gain = -(C @ np.linalg.solve(A, B) - D)
    np.testing.assert_allclose(gain[:, 0], [1 / 4.0, 0.0], atol=1e-12)


def test_bad_inputs_are_named():
    system = lagrangian.load("cart_pendulum")
    with pytest.raises(ModelError, match="'thrust' is not a parameter, load or coordinate"):
        system.linearize(about={"theta": 0}, inputs=["thrust"])


def test_constrained_linear_model_is_in_independent_coordinates():
    lm = lagrangian.load("cartesian_pendulum").linearize()
    assert lm.coordinates == ("x",) and lm.user_coordinates == ("x", "y")
    np.testing.assert_allclose(lm.basis, [[1.0], [0.0]], atol=1e-15)
    np.testing.assert_allclose(lm.M, [[1.0]])
    np.testing.assert_allclose(lm.K, [[9.81 / 0.5]])
    assert lm.constrained


def test_symbolic_linear_matrices_for_a_small_model():
    lm = lagrangian.load("cart_pendulum").linearize(about={"theta": math.pi}, symbolic=True)
    M, m, l, g = sp.symbols("M m l g")
    assert lm.equilibrium["theta"] == sp.pi  # pi recognised, so sin(pi) is exactly 0
    assert sp.simplify(lm.mass_matrix - sp.Matrix([[M + m, -l * m], [-l * m, l**2 * m]])) == \
        sp.zeros(2, 2)
    assert lm.stiffness_matrix == sp.Matrix([[0, 0], [0, -g * l * m]])
    assert lm.damping_matrix == sp.zeros(2, 2)
    assert "$" in lm._repr_latex_()


def test_symbolic_damping_and_gyroscopic_terms():
    lm = lagrangian.load("charged_particle").linearize(about={"x": 0, "y": 0}, symbolic=True)
    q, B = sp.symbols("q B")
    assert lm.damping_matrix == sp.Matrix([[0, -B * q], [B * q, 0]])


def test_symbolic_refuses_constrained_models():
    with pytest.raises(ModelError, match="unconstrained models only"):
        lagrangian.load("cartesian_pendulum").linearize(symbolic=True)


def test_thirty_dof_linearization_avoids_symbolic_inversion(monkeypatch):
    """A 30-link chain of pendulum-coupled masses: numeric evaluation only."""
    n = 30
    b = SystemBuilder("30 coupled pendulums")
    g = b.parameter("g", 9.81, "m/s^2")
    b.set_gravity(g, (0, -1))
    thetas = [b.coordinate(f"theta{i}", unit="rad", range=(-math.pi, math.pi))
              for i in range(1, n + 1)]
    for i, theta in enumerate(thetas):
        b.add_particle(f"bob{i}", 1.0, (i + lagrangian.sin(theta), -lagrangian.cos(theta)))
    for i in range(n - 1):
        b.add_spring(f"coupling{i}", 2.0, 0, length=thetas[i + 1] - thetas[i])
    system = b.build()
    system.equations_of_motion()

    def forbidden(*args, **kwargs):
        raise AssertionError("symbolic inversion or simplification in linearize")

    for name in ("simplify", "trigsimp", "cancel", "factor"):
        monkeypatch.setattr(sp, name, forbidden)
    monkeypatch.setattr(sp.MatrixBase, "inv", forbidden)
    monkeypatch.setattr(sp.MatrixBase, "LUsolve", forbidden)
    lm = system.linearize(about={t.name: 0.0 for t in thetas})
    analysis = system.modes(about={t.name: 0.0 for t in thetas})
    # Coupled pendulums: omega_k^2 = g + 2 k (1 - cos(k pi / n)) / (m l^2), k = 0..n-1.
    k = np.arange(n)
    expected = np.sqrt(9.81 + 2 * 2.0 * (1 - np.cos(k * np.pi / n)))
    np.testing.assert_allclose(analysis.natural_frequencies, expected, rtol=1e-10)
    assert lm.A.shape == (2 * n, 2 * n)


@pytest.mark.slow
def test_thirty_link_pendulum_against_its_known_linear_matrices(monkeypatch):
    """n unit masses on n unit links: M_ij = n - max(i, j) (0-based), K = diag(g (n - i))."""
    n, g = 30, 9.81
    b = SystemBuilder("30-link pendulum")
    b.set_gravity(b.parameter("g", g, "m/s^2"), (0, -1))
    x = y = 0
    thetas = [b.coordinate(f"theta{i}", unit="rad") for i in range(n)]
    for i, theta in enumerate(thetas):
        x, y = x + lagrangian.sin(theta), y - lagrangian.cos(theta)
        b.add_particle(f"bob{i}", 1.0, (x, y))
    system = b.build()
    system.equations_of_motion()

    def forbidden(*args, **kwargs):
        raise AssertionError("symbolic inversion or simplification in linearize")

    monkeypatch.setattr(sp, "simplify", forbidden)
    monkeypatch.setattr(sp.MatrixBase, "inv", forbidden)
    monkeypatch.setattr(sp.MatrixBase, "LUsolve", forbidden)
    lm = system.linearize(about={t.name: 0.0 for t in thetas})
    i = np.arange(n)
    mass = (n - np.maximum.outer(i, i)).astype(float)
    stiffness = np.diag(g * (n - i).astype(float))
    np.testing.assert_allclose(lm.M, mass, rtol=1e-12)
    np.testing.assert_allclose(lm.K, stiffness, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(lm.C, 0)


def test_about_values_must_be_numbers():
    system = lagrangian.load("pendulum")
    assert system.modes(about={"theta": sp.pi})[0].growth_rate == pytest.approx(math.sqrt(9.81 / 0.5))
    with pytest.raises(ModelError, match="the value of 'theta' must be a number in SI units"):
        system.linearize(about={"theta": "pi"})
    with pytest.raises(ModelError, match="'phi' is not a coordinate of this model"):
        system.linearize(about={"phi": 0.0})


def test_double_pendulum_state_matrix_agrees_with_sympy_mechanics():
    """An independent derivation: sympy.physics.mechanics LagrangesMethod.linearize."""
    from sympy.physics.mechanics import (
        LagrangesMethod,
        Lagrangian,
        Particle,
        Point,
        ReferenceFrame,
        dynamicsymbols,
    )

    q1, q2 = dynamicsymbols("q1 q2")
    u1, u2 = dynamicsymbols("q1 q2", 1)
    m1, m2, l1, l2, g = sp.symbols("m1 m2 l1 l2 g")
    frame, origin = ReferenceFrame("N"), Point("O")
    origin.set_vel(frame, 0)
    p1 = origin.locatenew("P1", l1 * sp.sin(q1) * frame.x - l1 * sp.cos(q1) * frame.y)
    p2 = p1.locatenew("P2", l2 * sp.sin(q2) * frame.x - l2 * sp.cos(q2) * frame.y)
    for point in (p1, p2):
        point.set_vel(frame, point.pos_from(origin).dt(frame))
    bob1, bob2 = Particle("bob1", p1, m1), Particle("bob2", p2, m2)
    bob1.potential_energy = m1 * g * p1.pos_from(origin).dot(frame.y)
    bob2.potential_energy = m2 * g * p2.pos_from(origin).dot(frame.y)
    method = LagrangesMethod(Lagrangian(frame, bob1, bob2), [q1, q2])
    method.form_lagranges_equations()
    point = {q1: 0, q2: 0, u1: 0, u2: 0, u1.diff(): 0, u2.diff(): 0}
    A, _, _ = method.linearize(q_ind=[q1, q2], qd_ind=[u1, u2], A_and_B=True, op_point=point)
    values = {m1: 1.0, m2: 1.0, l1: 1.0, l2: 1.0, g: 9.81}
    expected = np.array(A.subs(values), dtype=float)
    ours = lagrangian.load("double_pendulum").linearize(about={"theta1": 0, "theta2": 0})
    np.testing.assert_allclose(ours.A, expected, atol=1e-12)


def test_both_linear_models_split_C_the_same_way():
    """The Lorentz force q v x B does no work: its C is all gyroscopic, exactly (symbolic) and in
    numbers, and neither model has a dissipative part."""
    system = lagrangian.load("charged_particle")
    exact = system.linearize(about={"x": 0, "y": 0}, symbolic=True)
    q, B = sp.symbols("q B")
    assert exact.gyroscopic_matrix == exact.C == sp.Matrix([[0, -B * q], [B * q, 0]])
    assert exact.dissipation_matrix == sp.zeros(2, 2)
    assert exact.M == exact.mass_matrix and exact.K == exact.stiffness_matrix
    numeric = system.linearize(about={"x": 0, "y": 0})
    np.testing.assert_allclose(numeric.dissipation_matrix, 0, atol=1e-12)
    np.testing.assert_allclose(numeric.gyroscopic_matrix, numeric.C)
