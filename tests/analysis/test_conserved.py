"""System.conserved(), routhian() and hamiltonian() against closed forms of textbook systems."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

import lagrangian
from conserved_models import (
    CENTRAL_WELL,
    DAMPED_PAIR,
    FREE_PAIR,
    KEPLER,
    PUSHED_PAIR,
    SPHERICAL_PENDULUM,
)
from lagrangian.errors import ModelError


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    folder = tmp_path_factory.mktemp("conserved")
    systems = {}
    for name, text in (("spherical", SPHERICAL_PENDULUM), ("kepler", KEPLER),
                       ("pair", FREE_PAIR), ("central", CENTRAL_WELL),
                       ("damped_pair", DAMPED_PAIR), ("pushed_pair", PUSHED_PAIR)):
        path = folder / f"{name}.toml"
        path.write_text(text)
        systems[name] = lagrangian.load(path)
    return systems


def _symbols(system, *names):
    return [system.symbol(n) for n in names]


def _proportional(expression, reference) -> bool:
    """expression = c reference with c a nonzero constant (parameters only, no state)."""
    ratio = sp.simplify(expression / reference)
    names = {s.name for s in ratio.free_symbols}
    return ratio != 0 and all(not (n.endswith("_dot") or n in {"x", "y", "x1", "x2"}) for n in names)


def test_spherical_pendulum_conserves_m_l2_sin2_theta_phi_dot(models):
    system = models["spherical"]
    m, l, theta, phi_dot = _symbols(system, "m", "l", "theta", "phi_dot")
    momenta = system.conserved().of_kind("momentum")
    assert [q.name for q in momenta] == ["p_phi"]
    assert sp.simplify(momenta[0].expression - m * l**2 * sp.sin(theta)**2 * phi_dot) == 0
    assert momenta[0].value([0.6, 0.0], [0.0, 2.0]) == pytest.approx(
        1.3 * 0.8**2 * math.sin(0.6)**2 * 2.0, rel=1e-12)


def test_spherical_pendulum_routhian_conical_frequency(models):
    reduced = models["spherical"].routhian("phi")
    assert [c.name for c in reduced.model.coordinates] == ["theta"]
    m, l, g, theta0 = 1.3, 0.8, 9.81, 0.6
    rate = math.sqrt(g / (l * math.cos(theta0)))  # the conical motion at theta0
    p_phi = m * l**2 * math.sin(theta0)**2 * rate
    modes = reduced.with_parameters(p_phi=p_phi).modes(about={"theta": theta0})
    expected = math.sqrt(g * (1 + 3 * math.cos(theta0)**2) / (l * math.cos(theta0)))
    assert modes.natural_frequencies[0] == pytest.approx(expected, rel=0, abs=1e-7)


def test_the_routhian_steps_and_balances_as_the_full_pendulum(models):
    """The reduced model at the start's p_phi swings theta as the full one does, and the
    conical motion at theta0 = 0.6 rad (phi_dot^2 = g/(l cos theta0)) is its equilibrium."""
    full, reduced = models["spherical"], models["spherical"].routhian("phi")
    m, l, g, theta0 = 1.3, 0.8, 9.81, 0.6
    assert reduced.parameters["p_phi"] == pytest.approx(m * l**2 * math.sin(theta0)**2 * 1.0)
    a, b = full.simulate(1.0), reduced.simulate(1.0)
    swing = np.interp(np.asarray(b["t"]), np.asarray(a["t"]), np.asarray(a["theta"]))
    assert np.abs(swing - np.asarray(b["theta"])).max() < 1e-7
    p_phi = m * l**2 * math.sin(theta0)**2 * math.sqrt(g / (l * math.cos(theta0)))
    found = reduced.with_parameters(p_phi=p_phi).equilibria()
    assert any(abs(e.coordinates["theta"] - theta0) < 1e-9 and e.stable for e in found), found


def test_routhian_refuses_a_coordinate_that_is_not_cyclic(models):
    with pytest.raises(ModelError, match="'theta' is not cyclic: L depends on it through"):
        models["spherical"].routhian("theta")
    with pytest.raises(ModelError, match="not a coordinate"):
        models["spherical"].routhian("psi")


def test_spinning_hoop_lists_the_jacobi_integral_not_t_plus_v():
    hoop = lagrangian.load("bead_on_hoop").with_parameters(Omega=5.0)
    found = hoop.conserved()
    jacobi = found.named("h")
    assert jacobi.kind == "jacobi" and jacobi.equals_energy is False
    m, R, g, Omega = 0.1, 0.5, 9.81, 5.0
    theta, rate = 0.7, 1.3
    expected = 0.5 * m * R**2 * (rate**2 - Omega**2 * math.sin(theta)**2) \
        - m * g * R * math.cos(theta)
    assert jacobi.value([theta], [rate]) == pytest.approx(expected, rel=1e-12)
    eom = hoop.equations_of_motion()
    energy = eom.kinetic_energy + eom.potential_energy
    assert all(sp.simplify(q.expression - energy) != 0 for q in found)


def test_the_heavy_tops_quantities_print_as_goldsteins():
    """Its T is built from body rates (psi in every term): h and p_phi are shown in their
    readable forms, equal to Goldstein's (Sec. 5.7, I1 = A + m l^2 about the pivot, I3 = C)
    and free of psi."""
    top = lagrangian.load("heavy_top")
    A, C, m, l, g, theta, wp, wt, ws = _symbols(top, "A", "C", "m", "l", "g", "theta",
                                               "phi_dot", "theta_dot", "psi_dot")
    I1, s, c = A + m * l**2, sp.sin(theta), sp.cos(theta)
    found = top.conserved()
    h, p_phi = found.named("h"), found.named("p_phi")
    book_h = (I1 * (wt**2 + wp**2 * s**2) + C * (ws + wp * c) ** 2) / 2 + m * g * l * c
    assert sp.simplify(h.expression - book_h) == 0 and h.equals_energy
    assert sp.simplify(p_phi.expression - (I1 * wp * s**2 + C * c * (ws + wp * c))) == 0
    assert top.symbol("psi") not in h.expression.free_symbols | p_phi.expression.free_symbols
    assert sp.count_ops(h.expression) <= 1.3 * sp.count_ops(book_h)


def test_kepler_conserves_m_r2_phi_dot(models):
    system = models["kepler"]
    m, r, phi_dot = _symbols(system, "m", "r", "phi_dot")
    momentum = system.conserved().named("p_phi")
    assert sp.simplify(momentum.expression - m * r**2 * phi_dot) == 0


def test_two_masses_on_a_spring_conserve_total_momentum(models):
    system = models["pair"]
    m1, m2, v1, v2 = _symbols(system, "m1", "m2", "x1_dot", "x2_dot")
    noether = system.conserved().of_kind("noether")
    assert len(noether) == 1
    assert _proportional(noether[0].expression, m1 * v1 + m2 * v2)


def test_central_well_conserves_angular_momentum(models):
    system = models["central"]
    x, y, vx, vy = _symbols(system, "x", "y", "x_dot", "y_dot")
    noether = system.conserved().of_kind("noether")
    assert len(noether) == 1
    assert _proportional(noether[0].expression, x * vy - y * vx)


def test_loads_break_a_quantity_only_by_their_virtual_work_along_it(models):
    m1, m2, v1, v2 = _symbols(models["pair"], "m1", "m2", "x1_dot", "x2_dot")
    damped = models["damped_pair"].conserved()  # the dashpot acts on the stretch only
    assert _proportional(damped.of_kind("noether")[0].expression, m1 * v1 + m2 * v2)
    assert [b.name for b in damped.broken] == ["h"]
    pushed = models["pushed_pair"].conserved()  # a push on x1 does work along (1, 1)
    assert not pushed.of_kind("noether")
    assert any(b.kind == "noether" and "virtual work" in b.reason for b in pushed.broken)


def test_double_pendulum_hamilton_equations_match_the_closed_form():
    system = lagrangian.load("double_pendulum").with_parameters(m1=1.2, m2=0.7, l1=0.9,
                                                                 l2=0.6)
    m1, m2, l1, l2, g = 1.2, 0.7, 0.9, 0.6, 9.81
    t1, t2, p1, p2 = sp.symbols("t1 t2 p1 p2")
    c = sp.cos(t1 - t2)
    M = sp.Matrix([[(m1 + m2) * l1**2, m2 * l1 * l2 * c], [m2 * l1 * l2 * c, m2 * l2**2]])
    p = sp.Matrix([p1, p2])
    H = (p.T * M.inv() * p)[0, 0] / 2 - (m1 + m2) * g * l1 * sp.cos(t1) \
        - m2 * g * l2 * sp.cos(t2)
    point = {t1: 0.8, t2: -0.4, p1: 0.3, p2: -0.25}
    q_dot = [float(H.diff(x).subs(point)) for x in (p1, p2)]
    p_dot = [float(-H.diff(x).subs(point)) for x in (t1, t2)]
    hamiltonian = system.hamiltonian()
    got_q_dot, got_p_dot = hamiltonian.rhs([0.8, -0.4], [0.3, -0.25])
    np.testing.assert_allclose(got_q_dot, q_dot, rtol=1e-12)
    np.testing.assert_allclose(got_p_dot, p_dot, rtol=1e-12)
    np.testing.assert_allclose(hamiltonian.momenta_of([0.8, -0.4], got_q_dot), [0.3, -0.25],
                               rtol=1e-12)
    symbolic = hamiltonian.H.subs({system.symbol("theta1"): 0.8, system.symbol("theta2"): -0.4,
                                   sp.Symbol("p_theta1"): 0.3, sp.Symbol("p_theta2"): -0.25,
                                   **{system.symbol(k): v for k, v in
                                      system.parameters.items()}})
    assert float(symbolic) == pytest.approx(float(H.subs(point)), rel=1e-12)


def test_hamiltonian_refuses_constraints_and_bad_shapes():
    with pytest.raises(ModelError, match="unconstrained"):
        lagrangian.load("cartesian_pendulum").hamiltonian()
    with pytest.raises(ModelError, match="p takes 1 values"):
        lagrangian.load("pendulum").hamiltonian().rhs([0.1], [0.1, 0.2])


def test_a_real_eigenvalue_has_no_damping_ratio_in_the_modes_table():
    """The inverted pendulum grows without oscillating: zeta is shown as '–', not a number."""
    from lagrangian.output.modes import modes_text

    analysis = lagrangian.load("pendulum").modes(about={"theta": math.pi})
    row = [line for line in modes_text(analysis).splitlines() if "grows" in line][0]
    assert row.split()[4] == "–"


def test_a_cyclic_coordinate_that_l_still_shows_leaves_the_reduced_model(models, tmp_path):
    """sin^2 phi + cos^2 phi in T: phi is cyclic (by value), and the Routhian of Kepler's
    problem has the effective potential p^2/(2 m r^2) - k/r in r alone."""
    from conserved_models import KEPLER

    path = tmp_path / "kepler_dressed.toml"
    path.write_text(KEPLER.replace('T = "1/2*m*(r_dot^2 + r^2*phi_dot^2)"',
                                   'T = "1/2*m*(r_dot^2 + r^2*phi_dot^2)*(sin(phi)^2 + cos(phi)^2)"'))
    reduced = lagrangian.load(path).routhian("phi")
    m, k, r = _symbols(models["kepler"], "m", "k", "r")
    p = sp.Symbol("p_phi")
    assert reduced.model.potential_energy.free_symbols <= {m, k, r, p}
    assert sp.simplify(reduced.model.potential_energy - (p**2 / (2 * m * r**2) - k / r)) == 0
    circular = reduced.with_parameters(p_phi=math.sqrt(2.0 * 3.0 * 1.5))  # r0 = p^2/(m k)
    assert circular.equilibria()[0].coordinates["r"] == pytest.approx(1.5, rel=1e-9)
