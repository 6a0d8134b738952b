"""Mode shapes are verified before they are printed (issue 21): round-off entries of the state
matrix are cleaned, every eigenpair satisfies its equation to 1e-9 relative, a pair that cannot
be made accurate is refused, and the rolling coin's lean-yaw mode matches its closed form."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import lagrangian
from lagrangian.analysis.modes import (
    EIGEN_RESIDUAL_TOLERANCE,
    modal_analysis,
    structural_zeros_cleaned,
    verified_eigenvectors,
)

M, R, G = 2.0, 0.3, 9.81
I_DIAMETER, I_AXIS = M * R**2 / 4, M * R**2 / 2


def coin_modes(spin_rate: float):
    coin = lagrangian.load("rolling_coin")
    return coin.modes({"lean": 0.0}, steady={"spin_dot": spin_rate, "x_dot": spin_rate * R})


@pytest.mark.parametrize("spin_rate", [4.0, 6.0, 10.0])
def test_the_rolling_coins_lean_yaw_mode_is_its_closed_form(spin_rate):
    """Upright thin disc rolling at spin rate W: (I_d + m r^2) lean'' + (I_a (I_a + m r^2) W^2
    / I_d - m g r) lean = 0 after eliminating yaw (I_d yaw'' = -I_a W lean'), so
    omega^2 = (I_a (I_a + m r^2) W^2 / I_d - m g r) / (I_d + m r^2), and the lean amplitude over
    the yaw amplitude is omega I_d / (I_a W), a quarter period behind."""
    omega = math.sqrt((I_AXIS * (I_AXIS + M * R**2) * spin_rate**2 / I_DIAMETER - M * G * R)
                      / (I_DIAMETER + M * R**2))
    analysis = coin_modes(spin_rate)
    (mode,) = [m for m in analysis.modes if m.frequency > 0]
    assert mode.frequency == pytest.approx(omega, rel=1e-10)
    shape = dict(zip(analysis.linear_model.user_coordinates, mode.complex_shape, strict=True))
    ratio = shape["lean"] / shape["yaw"]
    assert abs(ratio) == pytest.approx(omega * I_DIAMETER / (I_AXIS * spin_rate), rel=1e-9)
    assert np.angle(ratio, deg=True) == pytest.approx(-90.0, abs=1e-6)


def test_every_eigenpair_of_the_coin_satisfies_its_equation():
    analysis = coin_modes(4.0)
    linear = analysis.linear_model
    A = linear.A
    values, vectors = np.linalg.eig(structural_zeros_cleaned(A))
    vectors = verified_eigenvectors(A, values, vectors)
    for k, s in enumerate(values):
        v = vectors[:, k]
        assert np.linalg.norm(A @ v - s * v) <= EIGEN_RESIDUAL_TOLERANCE * np.linalg.norm(A, 2) \
            * np.linalg.norm(v)


def test_round_off_entries_do_not_change_the_modes():
    """The coin's state matrix with 1e-31 and 1e-16 noise where it holds exact zeros gives the
    same frequencies and shapes: the noise is cleaned before LAPACK sees it."""
    analysis = coin_modes(4.0)
    linear = analysis.linear_model
    rng = np.random.default_rng(1)
    noisy_A = linear.A.copy()
    zeros = noisy_A == 0
    noisy_A[zeros] = rng.choice([1e-31, -1e-31, 1e-16, -1e-16], size=zeros.sum())
    noisy = modal_analysis(dataclasses.replace(linear, A=noisy_A))
    for clean_mode, noisy_mode in zip(analysis.modes, noisy.modes, strict=True):
        assert noisy_mode.frequency == pytest.approx(clean_mode.frequency, abs=1e-9)
        if clean_mode.frequency > 0:
            np.testing.assert_allclose(noisy_mode.complex_shape, clean_mode.complex_shape,
                                       atol=1e-9)


def test_a_refined_vector_replaces_a_wrong_one():
    """A deliberately wrong eigenvector is replaced by the null vector of A - s I."""
    A = np.array([[2.0, 1.0], [0.0, 3.0]])
    values = np.array([2.0, 3.0])
    wrong = np.array([[1.0, 1.0], [1.0, 0.0]])  # neither column is an eigenvector
    fixed = verified_eigenvectors(A, values, wrong)
    for k, s in enumerate(values):
        assert np.linalg.norm(A @ fixed[:, k] - s * fixed[:, k]) < 1e-12


def test_an_eigenvalue_that_is_not_one_is_refused():
    A = np.array([[2.0, 1.0], [0.0, 3.0]])
    with pytest.raises(lagrangian.DerivationError, match="cannot be computed accurately"):
        verified_eigenvectors(A, np.array([2.5, 3.0]), np.eye(2))


@pytest.mark.parametrize("name, steady", [
    ("rolling_coin", {"spin_dot": 4.0, "x_dot": 1.2}),
    ("whipple_bicycle", None),  # its [steady] table: straight ahead at v = 5 m/s
])
def test_every_mode_keeps_the_linearized_rolling_constraints(name, steady):
    """About steady rolling the constraints linearize to H dq + G dq_dot = 0; a mode
    dq = v e^(st) satisfies (H + s G) v = 0 (a heading offset alone does not: the contact point
    then drifts sideways, so it is no mode), and (s^2 M + s C + K) v lies in the span of G^T."""
    system = lagrangian.load(name)
    about = {"lean": 0.0} if steady else None
    analysis = system.modes(about, steady=steady)
    linear = analysis.linear_model
    rows = linear.state_constraints
    n = len(linear.user_coordinates)
    H, G = rows[:, :n], rows[:, n:]
    M, C, K = linear.mass_matrix, linear.damping_matrix, linear.stiffness_matrix
    constraint_rows = linear.velocity_constraints
    for mode in analysis.modes:
        v = np.array(mode.complex_shape)
        for s in {*mode.eigenvalues, *np.conj(mode.eigenvalues)}:
            scale = (abs(s) + 1) * (np.linalg.norm(H) + np.linalg.norm(G)) * np.linalg.norm(v)
            if np.linalg.norm((H + s * G) @ v) <= 1e-9 * scale:
                break
        else:
            pytest.fail(f"mode {mode} breaks the linearized constraints")
        force = (s * s * M + s * C + K) @ v
        outside = force - constraint_rows.T @ np.linalg.lstsq(constraint_rows.T, force,
                                                              rcond=None)[0]
        size = (abs(s) ** 2 * np.linalg.norm(M) + abs(s) * np.linalg.norm(C)
                + np.linalg.norm(K)) * np.linalg.norm(v)
        assert np.linalg.norm(outside) <= 1e-9 * size


@pytest.mark.parametrize("theta", [0.0, 1e-7, 1e-4])
def test_a_steady_motion_at_gimbal_lock_is_refused_by_name(theta):
    """z-x-z angles lose a rate where sin(theta) = 0: a steady top there has no linear model in
    these coordinates (the sleeping top's x-y-z angles do), whatever Cholesky says of M."""
    top = lagrangian.load("heavy_top")
    with pytest.raises(lagrangian.DerivationError, match="gimbal lock: the z-x-z angles"):
        top.modes({"theta": theta}, steady={"psi_dot": 60.0, "phi_dot": 0.0})
    # the same top upright in x-y-z angles: stable above psi_dot = 51.1 rad/s (its description)
    sleeping = lagrangian.load("sleeping_top")
    assert sleeping.modes({"a": 0.0, "b": 0.0}, steady={"psi_dot": 60.0}).stable
    assert not sleeping.modes({"a": 0.0, "b": 0.0}, steady={"psi_dot": 45.0}).stable
