"""A disc rolling without slipping in 3D: five coordinates, two velocity constraints through
multipliers (never substituted into L), against sympy.physics.mechanics' LagrangesMethod."""

import random

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

import lagrangian
from lagrangian.model.builder import ModelBuilder
from rolling_disc_models import VALUES, sympy_disc


def _our_disc():
    b = ModelBuilder("rolling disc")
    yaw, lean, _ = (b.coordinate(n, "rad") for n in ("yaw", "lean", "spin"))
    x, y = b.coordinate("x"), b.coordinate("y")
    m, r, g = (b.parameter(k, v) for k, v in VALUES.items())
    b.set_gravity(g, (0, 0, -1))
    # the centre is r above the contact point along the disc's radius in its plane
    up = sp.Matrix([sp.sin(yaw) * sp.sin(lean), -sp.cos(yaw) * sp.sin(lean), sp.cos(lean)])
    b.add_rigid_body("disc", m, [m * r**2 / 4, m * r**2 / 2, m * r**2 / 4],
                     position=list(sp.Matrix([x, y, 0]) + r * up),
                     rotation=[["z", "yaw"], ["x", "lean"], ["y", "spin"]])
    disc = b.build_model().rigid_bodies[0]
    q = [c.symbol for c in b.build_model().coordinates]
    q_dot = [b.velocity(s) for s in q]
    # the contact point of the disc is at rest: v_G + omega x (r_C - r_G) = 0 (horizontal part)
    v_centre = sp.Matrix([sum(p.diff(s) * v for s, v in zip(q, q_dot, strict=True))
                          for p in disc.position])
    omega = sp.Matrix(disc.rotation) * sp.Matrix(disc.angular_velocity)
    contact = v_centre + omega.cross(-r * up)
    b.add_constraint("roll_x", velocity=sp.trigsimp(sp.expand(contact[0])))
    b.add_constraint("roll_y", velocity=sp.trigsimp(sp.expand(contact[1])))
    return lagrangian.System(b.build_model())


@pytest.mark.slow
def test_rolling_disc_accelerations_and_contact_forces():
    system = _our_disc()
    eom = system.equations_of_motion()
    numeric = system.numeric(backend="numpy")
    q, method = sympy_disc()
    t = dynamicsymbols._t
    constants = {sp.Symbol(k): v for k, v in VALUES.items()}
    disc = system.model.rigid_bodies[0]
    rng = random.Random(2)
    for _ in range(3):
        qv = np.array([rng.uniform(-3, 3), rng.uniform(-0.8, 0.8), rng.uniform(-3, 3),
                       rng.uniform(-1, 1), rng.uniform(-1, 1)])
        free = np.array([rng.uniform(-2, 2) for _ in range(3)])
        A = np.array(eom.constraint_jacobian.xreplace(dict(zip(system.model.q, qv, strict=True)))
                     .xreplace(constants), dtype=float)
        v = np.concatenate([free, -A[:, :3] @ free])  # x_dot, y_dot so that the disc rolls
        ours, multipliers = numeric.accelerations_and_multipliers(qv, v)
        point = {s.diff(t): value for s, value in zip(q, v, strict=True)}
        point |= dict(zip(q, qv, strict=True)) | constants
        full = np.linalg.solve(np.array(method.mass_matrix_full.xreplace(point), dtype=float),
                               np.array(method.forcing_full.xreplace(point), dtype=float).ravel())
        assert np.ravel(ours) == pytest.approx(full[5:10], rel=1e-9, abs=1e-9)
        # the multipliers are the contact (friction) forces: m a_G = F horizontally, F = -lambda
        state = dict(zip(system.model.q, qv, strict=True)) | dict(
            zip(system.model.q_dot, v, strict=True)) | constants
        accelerations = dict(zip(system.model.q_ddot, np.ravel(ours), strict=True))
        for axis in range(2):
            r = disc.position[axis]
            a = sum(r.diff(s) * qdd for s, qdd in zip(system.model.q, system.model.q_ddot,
                                                      strict=True))
            a += sum(r.diff(s1).diff(s2) * v1 * v2
                     for s1, v1 in zip(system.model.q, system.model.q_dot, strict=True)
                     for s2, v2 in zip(system.model.q, system.model.q_dot, strict=True))
            force = VALUES["m"] * float(a.xreplace(accelerations).xreplace(state))
            assert force == pytest.approx(-multipliers.ravel()[axis], rel=1e-9, abs=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("factor", [0.9, 0.99, 1.01, 1.1])
def test_upright_rolling_disc_is_stable_exactly_above_the_critical_speed(factor):
    import math

    from lagrangian.errors import ModelError

    system = _our_disc()
    r, g = VALUES["r"], VALUES["g"]
    speed = factor * math.sqrt(g * r / 3)
    about = {"yaw": 0, "lean": 0, "x": 0, "y": 0, "spin": 0}
    analysis = system.modes(about=about, steady={"spin_dot": speed / r, "x_dot": speed})
    assert analysis.stable == (factor > 1)
    # the lean-yaw mode of a thin uniform disc: s^2 = 4 g/(5 r) (1 - 3 v^2/(g r))
    s2 = 4 * g / (5 * r) * (1 - 3 * speed**2 / (g * r))
    if s2 > 0:
        assert max(m.growth_rate for m in analysis.modes) == pytest.approx(math.sqrt(s2),
                                                                             rel=1e-7)
    else:
        assert max(m.frequency for m in analysis.modes) == pytest.approx(math.sqrt(-s2),
                                                                           rel=1e-7)
    with pytest.raises(ModelError, match="break constraint 'roll_x'"):
        system.modes(about=about, steady={"spin_dot": speed / r, "x_dot": 2 * speed})
