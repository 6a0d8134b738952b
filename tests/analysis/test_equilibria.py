"""Equilibria found numerically, against closed forms; stability; constraints; bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

import lagrangian
from lagrangian import ModelError, SystemBuilder, cos
from lagrangian.output.modes import equilibria_document

G, R = 9.81, 0.5


def angles(found, name="theta"):
    return [e.coordinates[name] for e in found]


def test_bead_on_hoop_below_the_pitchfork():
    # Omega^2 = 9 < g/R = 19.62: only the bottom is stable (the top is always unstable).
    found = lagrangian.load("bead_on_hoop").with_parameters(Omega=3.0).equilibria()
    assert angles(found) == pytest.approx([0.0, math.pi], abs=1e-12)
    assert [e.stable for e in found] == [True, False]


def test_bead_on_hoop_above_the_pitchfork():
    # Omega^2 = 36 > g/R: the bottom turns unstable, two stable equilibria at cos = g/(R W^2).
    found = lagrangian.load("bead_on_hoop").with_parameters(Omega=6.0).equilibria()
    side = math.acos(G / (R * 36.0))
    assert angles(found) == pytest.approx([-side, 0.0, side, math.pi], abs=1e-12)
    assert [e.stable for e in found] == [True, False, True, False]


@pytest.mark.parametrize("omega", [4.3, 4.5])  # sqrt(g/R) = 4.429 lies between
def test_bead_on_hoop_just_either_side(omega):
    found = lagrangian.load("bead_on_hoop").with_parameters(Omega=omega).equilibria()
    bottom = next(e for e in found if e.coordinates["theta"] == 0.0)
    assert bottom.stable == (omega**2 < G / R)
    assert len(found) == (2 if omega**2 < G / R else 4)


def test_angles_that_differ_by_two_pi_are_one_equilibrium():
    found = lagrangian.load("pendulum").equilibria()
    assert angles(found) == pytest.approx([0.0, math.pi], abs=1e-12)
    assert [e.stable for e in found] == [True, False]
    # The double pendulum: four, one of them stable.
    found = lagrangian.load("double_pendulum").equilibria()
    assert len(found) == 4
    assert sum(e.stable for e in found) == 1
    assert found[0].coordinates == {"theta1": 0.0, "theta2": 0.0}


def test_a_torsion_spring_breaks_the_periodicity():
    """V = 1/2 k theta^2 - m g L cos(theta) is not 2 pi-periodic: theta and theta + 2 pi differ."""
    b = SystemBuilder("pendulum on a weak torsion spring")
    theta = b.coordinate("theta", unit="rad", range=(-8.0, 8.0))
    b.add_kinetic_energy(b.velocity(theta) ** 2 / 2)
    k = 0.1
    b.add_potential_energy(k * theta**2 / 2 - cos(theta))
    found = b.build().equilibria()
    values = np.array(angles(found))
    # Equilibria solve k theta = -sin(theta); each is found once, none folded by 2 pi.
    np.testing.assert_allclose(k * values, -np.sin(values), atol=1e-12)
    assert len(values) == len(np.unique(np.round(values, 6)))
    assert any(v > math.pi for v in values) and any(v < -math.pi for v in values)


def test_cartesian_pendulum_multiplier_is_the_rod_tension():
    found = lagrangian.load("cartesian_pendulum").equilibria()
    bottom, top = found  # sorted by coordinates: y = -L first
    assert bottom.coordinates == pytest.approx({"x": 0.0, "y": -0.5})
    assert top.coordinates == pytest.approx({"x": 0.0, "y": 0.5})
    assert bottom.stable and not top.stable
    # f = Phi_q^T lambda: (0, -m g) = (2x, 2y) lambda, so lambda = m g / (2 L) at the bottom.
    assert bottom.multipliers["rod"] == pytest.approx(9.81 / (2 * 0.5))
    assert top.multipliers["rod"] == pytest.approx(-9.81 / (2 * 0.5))


def test_slider_crank_equilibria_satisfy_the_constraints():
    found = lagrangian.load("slider_crank").equilibria()
    r, l, k, x0 = 0.1, 0.3, 500.0, 0.3
    for e in found:
        theta, phi, x = (e.coordinates[n] for n in ("theta", "phi", "x"))
        assert r * math.sin(theta) - l * math.sin(phi) == pytest.approx(0, abs=1e-12)
        assert x - r * math.cos(theta) - l * math.cos(phi) == pytest.approx(0, abs=1e-12)
        # The spring pushes the slider; only loop_x carries it: lambda_x = -k (x - x0).
        assert e.multipliers["loop_x"] == pytest.approx(-k * (x - x0), abs=1e-9)
    stable = [e for e in found if e.stable]
    # The spring at rest length (two mirror images), or the far branch as close as it gets.
    assert sorted(round(e.coordinates["x"], 9) for e in stable) == [-0.2, 0.3, 0.3]
    # Dead centres (x = r + l and l - r on the near branch) are unstable.
    dead = [e for e in found if round(e.coordinates["x"], 9) in (0.4, 0.2)]
    assert len(dead) == 2 and not any(e.stable for e in dead)


def test_neutral_coordinate_is_reported_once():
    found = lagrangian.load("cart_pendulum").equilibria()
    assert len(found) == 2
    assert all(e.neutral == ("x",) for e in found)
    assert [e.coordinates["theta"] for e in found] == pytest.approx([0.0, math.pi])


def test_velocity_constraints_do_not_restrict_configurations():
    # On a level floor (alpha = 0) the rolling cylinder rests anywhere.
    found = lagrangian.load("rolling_cylinder").with_parameters(alpha=0.0).equilibria()
    assert len(found) == 1 and set(found[0].neutral) == {"x", "phi"}
    assert found[0].multipliers == {"no_slip": 0.0}
    # On the incline the friction cannot hold it: no equilibrium at all.
    assert len(lagrangian.load("rolling_cylinder").equilibria()) == 0


def test_no_equilibrium_is_an_empty_list_and_modes_say_so():
    system = lagrangian.load("atwood")
    assert len(system.equilibria()) == 0
    with pytest.raises(ModelError, match="no equilibrium found"):
        system.modes()


def test_explicit_time_models_have_no_fixed_equilibrium():
    with pytest.raises(ModelError, match="depend on time t explicitly"):
        lagrangian.load("support_pendulum").equilibria()


def test_a_hanging_spring_chain_of_thirty_masses():
    """30 DOF under gravity: each spring carries the weight below it (closed form)."""
    n, m, k, g = 30, 0.2, 50.0, 9.81
    b = SystemBuilder("hanging chain")
    ys = [b.coordinate(f"y{i}", unit="m", initial=-0.1 * i) for i in range(1, n + 1)]
    b.set_gravity(g, (0, -1))
    previous = 0
    for i, y in enumerate(ys, 1):
        b.add_particle(f"mass{i}", m, (0, y))
        b.add_spring(f"spring{i}", k, 0.1, length=previous - y)
        previous = y
    found = b.build().equilibria()
    assert len(found) == 1 and found[0].stable
    stretch = np.array([(n - i) * m * g / k for i in range(n)])  # spring i+1 holds n - i masses
    expected = -np.cumsum(0.1 + stretch)
    np.testing.assert_allclose([found[0].coordinates[f"y{i}"] for i in range(1, n + 1)],
                               expected, rtol=1e-10)


def test_json_contract():
    document = equilibria_document(lagrangian.load("bead_on_hoop").equilibria())
    assert set(document) == {"equilibria"}
    for item in document["equilibria"]:
        assert set(item) == {"coordinates", "stable"}
        assert isinstance(item["stable"], bool)
    constrained = equilibria_document(lagrangian.load("cartesian_pendulum").equilibria())
    assert set(constrained["equilibria"][0]) == {"coordinates", "stable", "multipliers"}
    assert set(constrained["equilibria"][0]["multipliers"]) == {"rod"}


def test_link_pulled_by_its_tip_force():
    # No gravity, horizontal tip force F: the link rests along the force (stable) or against it.
    system = lagrangian.load("virtual_work_link")
    found = system.equilibria()
    assert angles(found) == pytest.approx([-math.pi / 2, math.pi / 2])
    assert [e.stable for e in found] == [False, True]
    # About theta = pi/2 it swings like a pendulum in the field F: omega^2 = F L / (m L^2 / 3).
    (mode,) = system.modes(about={"theta": math.pi / 2}).modes
    assert mode.frequency == pytest.approx(math.sqrt(3 * 100.0 / (1.0 * 0.5)))


def test_four_bar_rests_on_both_assembly_branches():
    found = lagrangian.load("four_bar").equilibria()
    a, b, c, d = 0.1, 0.35, 0.3, 0.3
    assert len(found) == 2 and all(e.stable for e in found)
    branches = set()
    for e in found:
        t1, t2, t3 = (e.coordinates[n] for n in ("theta1", "theta2", "theta3"))
        assert a * math.cos(t1) + b * math.cos(t2) - c * math.cos(t3) - d == pytest.approx(0, abs=1e-12)
        assert a * math.sin(t1) + b * math.sin(t2) - c * math.sin(t3) == pytest.approx(0, abs=1e-12)
        branches.add(t3 > 0)  # open (rocker up) and crossed (rocker down) assembly
    assert branches == {True, False}
