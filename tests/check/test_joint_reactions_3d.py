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
def test_heavy_top_pivot_carries_no_moment_at_the_initial_state(cli):
    """A spherical pivot cannot carry a moment: its reaction moment is zero at the initial
    state, while the force it carries is not; the text prints the numbers, not 10^4
    characters of expression, and the JSON keeps both."""
    import json

    system = lagrangian.load("heavy_top")
    reaction = system.crosscheck().reaction("top")
    values = dict(zip(reaction.labels, reaction.at_initial_state, strict=True))
    force = np.array([values["R_x"], values["R_y"], values["R_z"]])
    assert np.linalg.norm(force) > 1.0
    assert max(abs(values[k]) for k in ("M_x", "M_y", "M_z")) < 1e-9 * np.linalg.norm(force)
    code, out, _ = cli("crosscheck", "heavy_top")
    assert code == 0 and max(len(line) for line in out.splitlines()) < 400
    code, out, _ = cli("crosscheck", "heavy_top", "--json")
    document = json.loads(out)["reactions"][0]
    assert len(document["moment"]["x"]) > 1000
    assert document["at_initial_state"]["force"]["z"] == pytest.approx(values["R_z"])
