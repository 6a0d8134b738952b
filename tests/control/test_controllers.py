"""Controllers in the loop: the cart-pole balanced by LQR (closed-loop eigenvalues as promised,
the nonlinear run following them), computed torque tracking within its closed-loop bound, and
bad input refused in one line."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

import lagrangian
from lagrangian.control import computed_torque, lqr
from lagrangian.errors import InputError, ModelError

G, M_CART, M_BOB, L = 9.81, 2.0, 0.5, 0.6
UPRIGHT = {"x": 0.0, "theta": np.pi}


@pytest.fixture(scope="module")
def cart_pole():
    return lagrangian.load("cart_pendulum")


@pytest.fixture(scope="module")
def upright(cart_pole):
    return cart_pole.linearize(UPRIGHT, inputs=["F"])


def test_upright_cart_pole_linear_model_is_the_textbook_one(upright):
    """Point masses, upright: x_ddot = m g/M theta + F/M, theta_ddot = (M+m) g/(M l) theta +
    F/(M l) (theta measured from upright, the sign of the hanging angle's perturbation)."""
    a = upright.A
    assert a[2, 1] == pytest.approx(M_BOB * G / M_CART, rel=1e-12)
    assert a[3, 1] == pytest.approx((M_CART + M_BOB) * G / (M_CART * L), rel=1e-12)
    assert upright.B[2, 0] == pytest.approx(1 / M_CART, rel=1e-12)
    assert abs(upright.B[3, 0]) == pytest.approx(1 / (M_CART * L), rel=1e-12)


def test_lqr_closed_loop_eigenvalues_are_the_stable_half_of_the_hamiltonian(upright):
    """The Riccati solution's promise: eig(A - B K) are the n stable eigenvalues of
    [[A, -B R^-1 B^T], [-Q, -A^T]], computed here without the Riccati equation."""
    Q, R = np.diag([1.0, 10.0, 1.0, 1.0]), np.array([[0.1]])
    design = lqr(upright, Q, R)
    A, B = upright.A, upright.B
    hamiltonian = np.block([[A, -B @ np.linalg.solve(R, B.T)], [-Q, -A.T]])
    stable = np.array([v for v in np.linalg.eigvals(hamiltonian) if v.real < 0])
    ours = design.closed_loop_eigenvalues
    assert len(stable) == 4 and np.all(ours.real < 0)
    assert np.sort_complex(ours) == pytest.approx(np.sort_complex(stable), rel=1e-9)
    # K = R^-1 B^T S with S the Riccati solution: its residual vanishes
    S = design.S
    residual = A.T @ S + S @ A - S @ B @ np.linalg.solve(R, B.T @ S) + Q
    assert np.abs(residual).max() < 1e-9 * np.abs(S).max()


def test_lqr_balances_the_simulated_cart_pole_as_the_eigenvalues_promise(cart_pole, upright):
    """A small tilt: the nonlinear closed loop follows x(t) = expm((A - B K) t) x0 to second
    order in the tilt; a larger one (0.2 rad) is brought upright and back to x = 0."""
    design = lqr(upright, [1, 10, 1, 1], 0.1)
    tilt = 1e-4
    run = cart_pole.simulate(4, initial={"x": 0.0, "theta": np.pi + tilt}, controller=design,
                             samples=41, rtol=1e-11, atol=1e-13)
    x0 = np.array([0.0, tilt, 0.0, 0.0])
    predicted = np.array([scipy.linalg.expm(design.closed_loop * t) @ x0 for t in run.t])
    simulated = design.state(run.q, run.q_dot)
    assert np.abs(simulated - predicted).max() < 1e-3 * tilt
    big = cart_pole.simulate(10, initial={"theta": np.pi - 0.2}, controller=design,
                             samples=1001)
    assert big.status == "finished"
    assert np.abs(design.state(big.q[-1], big.q_dot[-1])).max() < 1e-2
    assert big.controls.shape == (1001, 1) and big.control_names == ("F",)
    # the controller's work closes the energy balance: E - E0 = int F x_dot dt (Simpson's rule
    # on the samples: 1.7e-2 on 101 of them, 4e-6 on 1001, 2e-8 on 4001)
    assert big.invariant == "work_balance" and big.invariant_drift < 1e-5


def test_computed_torque_error_is_the_critically_damped_closed_form(cart_pole):
    """e_ddot + 2 w e_dot + w^2 e = 0 exactly on the model: e(t) = e0 (1 + w t) exp(-w t)."""
    w = 4.0
    target = np.array([0.5, 0.3])
    control = computed_torque(cart_pole, target, w * w, 2 * w)
    run = cart_pole.simulate(3, initial={"x": 0.0, "theta": 0.0}, controller=control,
                             samples=61, rtol=1e-11, atol=1e-12)
    e0 = target - np.zeros(2)
    expected = e0 * ((1 + w * run.t) * np.exp(-w * run.t))[:, None]
    np.testing.assert_allclose(target - run.q, expected, atol=1e-8)
    assert np.sort(control.error_eigenvalues.real) == pytest.approx([-w] * 4, rel=1e-6)


def _panda():
    pin = pytest.importorskip("pinocchio")
    pytest.importorskip("yourdfpy")
    for parent in Path(pin.__file__).resolve().parents:
        path = parent / "share/example-robot-data/robots/panda_description/urdf/panda.urdf"
        if path.is_file():
            return lagrangian.load(path, lock={"panda_finger_joint1": 0.0,
                                               "panda_finger_joint2": 0.0})
    pytest.skip("example-robot-data is not installed")


@pytest.mark.slow
def test_computed_torque_tracks_on_the_panda_within_its_closed_loop_bound():
    """A sinusoid per joint from an offset start: each joint's error stays under the critically
    damped envelope |e0| (1 + w t) exp(-w t) (plus the integration tolerance)."""
    panda = _panda()
    names = panda.dynamics().coordinates
    w, amplitude = 10.0, 0.3
    phase = np.linspace(0, 1, 7)

    def reference(t):
        return (amplitude * np.sin(t + phase), amplitude * np.cos(t + phase),
                -amplitude * np.sin(t + phase))

    control = computed_torque(panda, reference, w * w, 2 * w)
    start = reference(0.0)[0] + 0.05
    run = panda.simulate(2, initial={**dict(zip(names, start, strict=True)),
                                     **{f"{c}_dot": amplitude * np.cos(p)
                                        for c, p in zip(names, phase, strict=True)}},
                         controller=control, samples=101, limits=False)
    assert run.status == "finished"
    error = np.abs(np.array([reference(t)[0] for t in run.t]) - run.q)
    bound = 0.05 * (1 + w * run.t) * np.exp(-w * run.t)
    assert np.all(error <= bound[:, None] + 1e-7)
    assert error[-1].max() < 1e-6


def test_bad_controllers_and_designs_are_refused_in_one_line(cart_pole, upright):
    with pytest.raises(InputError, match=r"shape \(3,\); expected \(2,\)") as caught:
        cart_pole.simulate(1, controller=lambda t, q, v: [1.0, 2.0, 3.0])
    assert caught.value.field == "controller" and "\n" not in str(caught.value)
    with pytest.raises(InputError, match="callable"):
        cart_pole.simulate(1, controller=3.0)
    with pytest.raises(InputError, match="not stabilizable") as caught:
        lqr(replace(upright, B=np.zeros_like(upright.B)), 1, 1)
    assert "\n" not in str(caught.value)
    with pytest.raises(InputError, match="no inputs"):
        lqr(lagrangian.load("cart_pendulum").linearize(UPRIGHT), 1, 1)
    with pytest.raises(InputError, match="positive definite") as caught:
        lqr(upright, 1, 0.0)
    assert caught.value.field == "R"
    with pytest.raises(InputError, match="4 x 4"):
        lqr(upright, np.eye(3), 1)
    with pytest.raises(ModelError, match="not a parameter, load or coordinate"):
        cart_pole.simulate(1, controller=lambda t, q, v: 0.0, inputs=["G"])
    with pytest.raises(InputError, match="three arrays"):
        computed_torque(cart_pole, lambda t: (np.zeros(3), np.zeros(2), np.zeros(2)), 1, 1)


def test_a_constant_motor_torque_on_a_constrained_crank_does_work_tau_delta_theta():
    """The slider-crank (two loop constraints, multipliers) driven by a constant torque on the
    crank through ``inputs=["theta"]``: E(t) - E0 = tau (theta(t) - theta0), and the run stays
    on its constraints."""
    crank = lagrangian.load("slider_crank")
    torque = 2.0
    run = crank.simulate(0.5, controller=lambda t, q, v: torque, inputs=["theta"], samples=101,
                         rtol=1e-11, atol=1e-12)
    assert run.status == "finished" and run.control_names == ("theta",)
    np.testing.assert_allclose(run.energy - run.energy[0], torque * (run.q[:, 0] - run.q[0, 0]),
                               atol=1e-7)
    assert run.max_residual < 1e-8
    assert run.control_forces.shape == (101, 3)
    np.testing.assert_allclose(run.control_forces[:, 0], torque)


def test_lqr_from_the_modes_linearization_is_the_same_and_balances(cart_pole, upright):
    """modes(about, inputs=["F"]) carries the same A, B as linearize: the same K, and it
    balances the nonlinear cart-pole; without inputs lqr refuses in one line naming both."""
    modal = cart_pole.modes(UPRIGHT, inputs=["F"])
    from_modes = lqr(modal, [1, 10, 1, 1], 0.1)
    assert from_modes.K == pytest.approx(lqr(upright, [1, 10, 1, 1], 0.1).K, rel=1e-10)
    assert lqr(modal.linear_model, [1, 10, 1, 1], 0.1).K == pytest.approx(from_modes.K)
    run = cart_pole.simulate(10, initial={"theta": np.pi - 0.1}, controller=from_modes,
                             samples=201)
    assert np.abs(from_modes.state(run.q[-1], run.q_dot[-1])).max() < 1e-2
    with pytest.raises(InputError, match="modes"):
        lqr(cart_pole.modes(UPRIGHT), [1, 10, 1, 1], 0.1)


def test_computed_torque_on_a_floating_base_is_refused_in_one_line(cli):
    """tau = M q_ddot_d + b would command the base's wrench, which nothing applies: refused,
    in Python and on the command line (was a numpy shapes error, q of 9 against v of 8)."""
    pytest.importorskip("yourdfpy")
    robot = lagrangian.load("two_link_arm", floating_base=True)
    with pytest.raises(ModelError, match="computed torque needs every coordinate actuated"):
        lagrangian.computed_torque(robot, np.zeros(9), 100.0, 20.0)
    code, out, err = cli("simulate", "two_link_arm", "--floating-base", "--control",
                         "computed-torque", "--t-end", "0.1")
    assert code == 2 and out == ""
    (line,) = err.strip().splitlines()
    assert line.startswith("error: --floating-base: computed torque needs every coordinate")
