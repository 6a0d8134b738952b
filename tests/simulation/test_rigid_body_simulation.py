"""Simulating bodies in space: conservation laws, and gimbal lock named."""

import numpy as np
import sympy as sp

import lagrangian


def test_torque_free_body_keeps_its_energy_and_angular_momentum():
    system = lagrangian.load("torque_free_body")
    run = system.simulate(10.0, samples=201, initial={"theta_dot": 1.5, "phi_dot": 1.0})
    assert run.completed
    model = system.model
    body = model.rigid_bodies[0]
    values = {p.symbol: p.value for p in model.parameters}
    # H = R I omega in world axes, by sympy at each sample (independent of the equations)
    I = sp.Matrix(body.inertia).xreplace(values)
    H = sp.Matrix(body.rotation) * I * sp.Matrix(body.angular_velocity)
    h = sp.lambdify([*model.q, *model.q_dot], list(H))
    momenta = np.array([h(*q, *v) for q, v in zip(run.q, run.q_dot, strict=True)],
                       dtype=float)
    assert np.max(np.abs(momenta - momenta[0])) < 1e-7 * np.linalg.norm(momenta[0])
    energy = run.energy
    assert np.max(np.abs(energy - energy[0])) < 1e-8 * abs(energy[0])
    # and the body really tumbles (the check is not trivial)
    assert np.ptp(run.q[:, 1]) > 0.1


def test_gimbal_lock_is_named_with_the_angles_and_where(cli):
    run = lagrangian.load("heavy_top").simulate(1.0, initial={"theta": 0.0})
    assert run.status == "failed"
    message = run.message
    assert "gimbal lock" in message and "z-x-z angles (phi, theta, psi)" in message
    assert "theta = 0" in message and "'top'" in message
    code, out, err = cli("simulate", "heavy_top", "--initial", "theta=0", "--t-end", "1")
    assert code != 0 and "gimbal lock" in out + err
