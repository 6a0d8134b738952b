"""Joint reactions of bodies in space from the Newton-Euler crosscheck, against closed forms: the
heavy top's pivot force in steady precession, the moment a spherical pivot or a revolute joint
cannot carry, and the weights a hanging chain's joints hold."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

import lagrangian


def _at(system, state: dict[str, float]):
    """Each reaction component (by joint and label) as a number at ``state`` (q and q_dot by
    name), with q_ddot solved from the Lagrange equations M q_ddot = f there."""
    model, eom = system.model, system.equations_of_motion()
    values = {p.symbol: sp.Float(p.value) for p in model.parameters}
    for c in model.coordinates:
        values[c.symbol] = sp.Float(state[c.name])
        values[c.velocity] = sp.Float(state.get(f"{c.name}_dot", 0.0))
    mass = np.array(eom.mass_matrix.xreplace(values).evalf(), dtype=float)
    forcing = np.array(eom.forcing.xreplace(values).evalf(), dtype=float).ravel()
    q_ddot = np.linalg.solve(mass, forcing)
    values.update({a: sp.Float(x) for a, x in zip(model.q_ddot, q_ddot, strict=True)})
    report = system.crosscheck()
    assert report.agree
    return q_ddot, {r.joint: {label: float(v.xreplace(values).evalf())
                              for label, v in zip(r.labels, r.components, strict=True)}
                    for r in report.reactions}


@pytest.mark.slow
def test_heavy_top_pivot_in_steady_precession():
    system = lagrangian.load("heavy_top")
    p = {q.name: q.value for q in system.model.parameters}
    m, g, l, A, C = p["m"], p["g"], p["l"], p["A"], p["C"]
    theta, spin, phi = 0.3, 60.0, 0.7
    # Steady precession at nutation theta: (A + m l^2) Omega^2 cos th - C w3 Omega + m g l = 0,
    # w3 = psi_dot + Omega cos th, i.e. (A + m l^2 - C) cos th Omega^2 - C psi_dot Omega + m g l = 0;
    # the slow root.
    a, b, c = (A + m * l**2 - C) * math.cos(theta), -C * spin, m * g * l
    omega = min(np.roots([a, b, c]), key=abs).real
    q_ddot, reactions = _at(system, {"phi": phi, "theta": theta, "psi": 1.1, "phi_dot": omega,
                                     "psi_dot": spin})
    assert np.allclose(q_ddot, 0.0, atol=1e-9)  # it is steady
    pivot = reactions["top"]
    # The pivot holds the weight (m g up) and turns the centre of mass on its horizontal circle
    # of radius l sin th: m l sin th Omega^2 towards the vertical axis, -(sin phi, -cos phi, 0).
    radial = m * l * math.sin(theta) * omega**2
    assert pivot["R_z"] == pytest.approx(m * g, rel=1e-10)
    assert pivot["R_x"] == pytest.approx(-radial * math.sin(phi), rel=1e-9)
    assert pivot["R_y"] == pytest.approx(radial * math.cos(phi), rel=1e-9)
    # a spherical pivot carries no moment
    for label in ("M_x", "M_y", "M_z"):
        assert pivot[label] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.slow
def test_heavy_top_pivot_carries_no_moment_in_any_motion():
    rng = np.random.default_rng(3)
    state = dict(zip(["phi", "theta", "psi", "phi_dot", "theta_dot", "psi_dot"],
                     [*rng.uniform(0.3, 1.2, 3), *rng.uniform(-5, 5, 3)], strict=True))
    _, reactions = _at(lagrangian.load("heavy_top"), state)
    pivot = reactions["top"]
    for label in ("M_x", "M_y", "M_z"):
        assert pivot[label] == pytest.approx(0.0, abs=1e-12)


CHAIN = """
name = "Two links"
[coordinates]
a = { unit = "rad" }
b = { unit = "rad" }
[parameters]
L = { value = 0.5, unit = "m" }
m1 = { value = 1.5, unit = "kg" }
m2 = { value = 0.7, unit = "kg" }
g = { value = 9.81, unit = "m/s^2" }
[gravity]
g = "g"
direction = [0, 0, -1]
[[bodies]]
name = "upper"
mass = "m1"
inertia = [0.03, 0.028, 0.003]
joint = { type = "revolute", axis = "x", angle = "a" }
center = [0, 0, "-L/2"]
[[bodies]]
name = "lower"
parent = "upper"
mass = "m2"
inertia = [0.02, 0.018, 0.003]
joint = { type = "revolute", axis = "y", angle = "b", at = [0, 0, "-L"] }
center = [0, 0, "-L/2"]
"""


def test_a_hanging_chain_holds_its_weights_and_its_revolute_joints_no_moment_on_their_axes(
        tmp_path):
    (tmp_path / "chain.toml").write_text(CHAIN)
    system = lagrangian.load(tmp_path / "chain.toml")
    m1, m2, g = 1.5, 0.7, 9.81
    _, rest = _at(system, {"a": 0.0, "b": 0.0})
    # at rest the upper joint holds both links' weight, the lower joint the lower link's
    assert [rest["upper"][k] for k in ("R_x", "R_y", "R_z")] == pytest.approx(
        [0, 0, (m1 + m2) * g], abs=1e-12)
    assert [rest["lower"][k] for k in ("R_x", "R_y", "R_z")] == pytest.approx(
        [0, 0, m2 * g], abs=1e-12)
    # moving: a revolute joint carries no moment about its own axis (x for the upper joint,
    # the upper link's y = (0, cos a, sin a) for the lower)
    a = 0.4
    _, moving = _at(system, {"a": a, "b": -0.9, "a_dot": 1.3, "b_dot": -2.1})
    assert moving["upper"]["M_x"] == pytest.approx(0.0, abs=1e-12)
    lower = moving["lower"]
    assert lower["M_y"] * math.cos(a) + lower["M_z"] * math.sin(a) == pytest.approx(0.0, abs=1e-12)
    # while the upper joint does carry moment about the other axes (a hinge holds the link)
    assert abs(moving["upper"]["M_y"]) + abs(moving["upper"]["M_z"]) > 1e-3


@pytest.mark.slow
@pytest.mark.parametrize("lean, yaw_rate, lean_rate", [(0.3, 1.1, -0.7), (0.0, 0.0, 0.0)])
def test_rolling_disc_contact_force_passes_through_the_contact_point_and_matches_the_multipliers(
        lean, yaw_rate, lean_rate):
    # the disc built in tests/derivation (checked there against sympy's LagrangesMethod)
    import importlib.util
    from pathlib import Path

    path = Path(__file__).parents[1] / "derivation" / "test_rolling_disc_3d.py"
    spec = importlib.util.spec_from_file_location("rolling_disc_3d_model", path)
    disc = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(disc)
    VALUES = disc.VALUES
    system = disc._our_disc()
    model, eom = system.model, system.equations_of_motion()
    m, r, g = VALUES["m"], VALUES["r"], VALUES["g"]
    values = {p.symbol: sp.Float(p.value) for p in model.parameters}
    state = {"yaw": 0.4, "lean": lean, "spin": 1.0, "x": 0.2, "y": -0.1}
    rates = {"yaw": yaw_rate, "lean": lean_rate, "spin": 4.0}
    for c in model.coordinates:
        values[c.symbol] = sp.Float(state[c.name])
        values[c.velocity] = sp.Float(rates.get(c.name, 0.0))
    # the x, y rates that keep the contact point at rest: A q_dot = 0 solved for them
    jacobian = np.array(eom.constraint_jacobian.xreplace(values).evalf(), dtype=float)
    free = [i for i, c in enumerate(model.coordinates) if c.name in ("x", "y")]
    known = [i for i in range(5) if i not in free]
    given = np.array([rates[model.coordinates[i].name] for i in known])
    xy = np.linalg.solve(jacobian[:, free], -jacobian[:, known] @ given)
    for i, v in zip(free, xy, strict=True):
        values[model.coordinates[i].velocity] = sp.Float(v)
    mass = np.array(eom.mass_matrix.xreplace(values).evalf(), dtype=float)
    forcing = np.array(eom.forcing.xreplace(values).evalf(), dtype=float).ravel()
    rhs = np.array(sp.Matrix(eom.acceleration_rhs).xreplace(values).evalf(), dtype=float).ravel()
    # M q_ddot + A^T lambda = f, A q_ddot = rhs: the contact force on the disc is -lambda
    kkt = np.block([[mass, jacobian.T], [jacobian, np.zeros((2, 2))]])
    solution = np.linalg.solve(kkt, np.concatenate([forcing, rhs]))
    values.update({a: sp.Float(x) for a, x in zip(model.q_ddot, solution[:5], strict=True)})
    report = system.crosscheck()
    assert report.agree
    reaction = report.reaction("disc")
    got = {label: float(v.xreplace(values).evalf())
           for label, v in zip(reaction.labels, reaction.components, strict=True)}
    force = np.array([got["R_x"], got["R_y"], got["R_z"]])
    assert force[:2] == pytest.approx(-solution[5:], rel=1e-9, abs=1e-12)
    # the whole reaction acts at the contact point: its moment about the centre G is
    # (r_C - r_G) x R, with r_C - r_G = -r (sin yaw sin lean, -cos yaw sin lean, cos lean)
    yaw, lean = state["yaw"], state["lean"]
    arm = -r * np.array([math.sin(yaw) * math.sin(lean), -math.cos(yaw) * math.sin(lean),
                         math.cos(lean)])
    moment = np.array([got["M_x"], got["M_y"], got["M_z"]])
    assert moment == pytest.approx(np.cross(arm, force), rel=1e-9, abs=1e-12)
    if lean == 0 and yaw_rate == 0 and lean_rate == 0:
        # upright, rolling straight at constant speed: the ground holds the weight, no friction
        assert force == pytest.approx([0, 0, m * g], abs=1e-12)
