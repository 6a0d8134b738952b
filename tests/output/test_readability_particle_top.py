"""A symmetric top built of four (or three) particles (no rigid body: its T holds products of its rotation
matrix's entries) prints within 1.3x the operation count of the textbook heavy top's M and f
(Goldstein, Sec. 5.7, with I1 = 4 m h^2 + 2 m r^2 about the pivot and I3 = 4 m r^2), and
equal to them; the exact sin^2 + cos^2 = 1 normal form behind it (derivation/trig_normal.py)."""

from __future__ import annotations

import pytest
import sympy as sp

import lagrangian
from lagrangian.derivation.readable import readable
from lagrangian.derivation.trig_normal import trig_normal_form
from lagrangian.model.expressions import parse_expression
from lagrangian.output.derivation import derivation_document

AXES = {  # the body axes in world: the columns of Rz(phi) Rx(theta) Rz(psi)
    "e1": ["cos(phi)*cos(psi) - sin(phi)*cos(theta)*sin(psi)",
           "sin(phi)*cos(psi) + cos(phi)*cos(theta)*sin(psi)", "sin(theta)*sin(psi)"],
    "e2": ["-cos(phi)*sin(psi) - sin(phi)*cos(theta)*cos(psi)",
           "-sin(phi)*sin(psi) + cos(phi)*cos(theta)*cos(psi)", "sin(theta)*cos(psi)"],
    "e3": ["sin(phi)*sin(theta)", "-cos(phi)*sin(theta)", "cos(theta)"],
}


def particle_top(ring: int = 4) -> str:
    """``ring`` particles m evenly on a ring of radius r at height h on the symmetry axis
    (z-x-z); four at right angles, three at 120 degrees (cos and sin of 2 pi/3 in the text)."""
    definitions = "\n".join(f'{axis}{"xyz"[i]} = "{text}"' for axis, column in AXES.items()
                            for i, text in enumerate(column))
    if ring == 4:
        places = [("r*e1{x}"), ("r*e2{x}"), ("-r*e1{x}"), ("-r*e2{x}")]
    else:
        places = ["r*e1{x}", "-1/2*r*e1{x} + sqrt(3)/2*r*e2{x}", "-1/2*r*e1{x} - sqrt(3)/2*r*e2{x}"]
    particles = "".join(
        f'[[particles]]\nname = "p{k}"\nmass = "m"\nposition = ['
        + ", ".join(f'"{place.format(x=x)} + h*e3{x}"' for x in "xyz") + "]\n"
        for k, place in enumerate(places))
    return f'''name = "Particle top"
[coordinates]
phi = {{ unit = "rad", initial = 0.0, rate = 0.0 }}
theta = {{ unit = "rad", initial = 0.3, rate = 0.0 }}
psi = {{ unit = "rad", initial = 0.0, rate = 60.0 }}
[parameters]
m = {{ value = 0.1, unit = "kg" }}
r = {{ value = 0.03, unit = "m" }}
h = {{ value = 0.04, unit = "m" }}
g = {{ value = 9.81, unit = "m/s^2" }}
[definitions]
{definitions}
[gravity]
g = "g"
direction = [0, 0, -1]
{particles}'''


def _printed(ring: int):
    system = lagrangian.System(lagrangian.parse_model(particle_top(ring)))
    eom = system.equations_of_motion()
    document = derivation_document(eom)
    model = eom.model
    names = {p.name: p.symbol for p in model.parameters}
    for c in model.coordinates:
        names.update({c.name: c.symbol, c.velocity.name: c.velocity,
                      c.acceleration.name: c.acceleration})
    return document, names, eom


@pytest.fixture(scope="module")
def printed():
    return _printed(4)


def textbook(n, ring: int = 4):
    m, r, h, g = n["m"], n["r"], n["h"], n["g"]
    th, wp, wt, ws = n["theta"], n["phi_dot"], n["theta_dot"], n["psi_dot"]
    N = ring  # I1 = N m h^2 + N m r^2/2 about the pivot, I3 = N m r^2, N m g h
    I1, I3, mgl = N * m * h**2 + sp.Rational(N, 2) * m * r**2, N * m * r**2, N * m * g * h
    s, c = sp.sin(th), sp.cos(th)
    mass = [I1 * s**2 + I3 * c**2, 0, I3 * c, 0, I1, 0, I3 * c, 0, I3]
    forcing = [2 * (I3 - I1) * wp * wt * s * c + I3 * ws * wt * s,
               I1 * wp**2 * s * c - I3 * wp * s * (ws + wp * c) + mgl * s, I3 * wp * wt * s]
    energy = (I1 * (wt**2 + wp**2 * s**2) + I3 * (ws + wp * c) ** 2) / 2
    return mass, forcing, energy


def _zero(expr) -> bool:
    """Exactly 0 (sympy's simplify, an independent route: the tests' expressions are small)."""
    return sp.simplify(sp.expand_trig(expr)) == 0


def test_the_printed_m_and_f_are_the_textbooks_within_1_3(printed):
    document, names, _ = printed
    forcing = [parse_expression(x, names) for x in document["forcing"]]
    mass = [parse_expression(x, names) for row in document["mass_matrix"] for x in row]
    book_mass, book_forcing, _ = textbook(names)
    assert all(_zero(a - b) for a, b in zip(mass, book_mass, strict=True))
    assert all(_zero(a - b) for a, b in zip(forcing, book_forcing, strict=True))
    ops = lambda xs: sum(map(sp.count_ops, xs))  # noqa: E731
    assert ops(mass) <= 1.3 * ops(book_mass), document["mass_matrix"]
    assert ops(forcing) <= 1.3 * ops(book_forcing), document["forcing"]


def test_a_ring_of_three_prints_as_the_textbook_too():
    """Three particles at 120 degrees: the derived M, f and T pass 20,000 nodes (sqrt(3)'s
    products), which printed them in 107 named quantities at 35x; their readable forms are the
    textbook's (output/derivation_display.py _collapses)."""
    document, names, _ = _printed(3)
    assert not document.get("intermediates")
    forcing = [parse_expression(x, names) for x in document["forcing"]]
    mass = [parse_expression(x, names) for row in document["mass_matrix"] for x in row]
    book_mass, book_forcing, _ = textbook(names, 3)
    assert all(_zero(a - b) for a, b in zip(mass, book_mass, strict=True))
    assert all(_zero(a - b) for a, b in zip(forcing, book_forcing, strict=True))
    ops = lambda xs: sum(map(sp.count_ops, xs))  # noqa: E731
    assert ops(mass) <= 1.3 * ops(book_mass) and ops(forcing) <= 1.3 * ops(book_forcing)


def test_the_printed_t_is_the_textbooks(printed):
    document, names, eom = printed
    T = parse_expression(document["kinetic_energy"], names)
    _, _, book = textbook(names)
    assert _zero(T - book) and _zero(T - eom.kinetic_energy)
    assert sp.count_ops(T) <= 1.3 * sp.count_ops(book)  # it printed 13x before
    assert "phi" not in str(T).replace("phi_dot", "")  # the precession angle is cyclic


def test_the_normal_form_applies_the_identity_exactly():
    a, b, k = sp.symbols("a b k")
    s, c = sp.sin, sp.cos
    assert trig_normal_form(s(a) ** 2 + c(a) ** 2) == 1
    assert trig_normal_form((s(a) * s(b) - c(a) * c(b)) ** 2
                            + (s(a) * c(b) + c(a) * s(b)) ** 2) == 1
    assert trig_normal_form(k * (s(a) ** 4 - c(a) ** 4) + k * (c(a) ** 2 - s(a) ** 2)) == 0
    assert trig_normal_form(1 / c(a)) is None  # not a polynomial in the sine and cosine
    assert trig_normal_form(k**2) is None  # no angle


def test_a_rates_terms_gathered_into_a_square():
    """The symmetric top's T as Goldstein writes it: C (psi_dot + phi_dot cos theta)^2 / 2
    beside I1 (theta_dot^2 + phi_dot^2 sin^2 theta) / 2, not its expanded cross term."""
    I1, C, th = sp.symbols("I1 C theta")
    wp, wt, ws = sp.symbols("phi_dot theta_dot psi_dot")
    T = sp.expand((I1 * (wt**2 + wp**2 * sp.sin(th) ** 2) + C * (ws + wp * sp.cos(th)) ** 2) / 2)
    shown = readable(T, [wp, wt, ws])
    assert sp.expand(shown - T) == 0
    assert _squares(shown, ws, wp) and sp.count_ops(shown) < sp.count_ops(T)
    # a form with no square to gain keeps its rates' products (the double pendulum's T)
    a, b, v1, v2 = sp.symbols("a b a_dot b_dot")
    pendulum = readable(v1**2 + v1 * v2 * sp.cos(a - b) + v2**2 / 2, [v1, v2])
    assert not _squares(pendulum, v1, v2)


def _squares(expr, u, w) -> bool:
    """Whether expr holds a square of a sum with both rates u and w."""
    return any(p.exp == 2 and p.base.is_Add and p.base.has(u) and p.base.has(w)
               for p in expr.atoms(sp.Pow))
