"""The report page's conserved quantities and limit cycle against closed forms, its expected
column as MathML, and the one plain sentence of a model with nothing to draw.

Sections are built on their own (report/invariants.py, sections.py) where the rest of the page
(a simulation, its animation) is not the point; one whole page checks their place on it."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from test_report import Page

import lagrangian
from conserved_models import spherical_pendulum
from lagrangian.analysis.limit_cycle import CYCLE_STEPS
from lagrangian.model.reader import parse_model
from lagrangian.model.values import resolve_parameters
from lagrangian.report import invariants, sections
from lagrangian.report.expected import expected_markup
from lagrangian.report.mathml import MathWriter
from lagrangian.report.media import NOTHING_TO_DRAW
from lagrangian.report.page import _Page
from lagrangian.simulation.poincare import PoincareMap

G = 9.81
ANSWERS = Path(__file__).resolve().parents[1] / "check" / "answers"
SPHERICAL = spherical_pendulum(theta_dot=0.4, phi_dot=1.5)


def _text(markup: str) -> str:
    """The markup's text (tags dropped, spaces collapsed)."""
    return " ".join(re.sub(r"<[^>]+>", " ", markup).split())


def _numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?", text)]


def _section(system, build):
    body, status = build(_Page(system))
    return str(body), status


def test_the_spinning_hoops_jacobi_integral_and_not_t_plus_v():
    """Omega = 5 rad/s: h = 1/2 m R^2 (theta_dot^2 - Omega^2 sin^2 theta) - m g R cos theta,
    which is not T + V (the drive keeping Omega does work), at theta = 0.5, theta_dot = 0."""
    hoop = lagrangian.load("bead_on_hoop").with_parameters(Omega=5.0)
    body, status = _section(hoop, invariants.conserved_section)
    m, R, omega, theta = 0.1, 0.5, 5.0, 0.5
    h = 0.5 * m * R**2 * (0 - omega**2 * math.sin(theta) ** 2) - m * G * R * math.cos(theta)
    text = _text(body)
    assert status == "shown" and "Jacobi integral" in text
    assert any(abs(x - h) < 1e-6 * abs(h) for x in _numbers(text)), (h, text)
    assert "not T + V" in text and "equal to T + V" not in text
    assert "<math" in body and "<mi>Ω</mi>" in body


def test_the_spherical_pendulums_cyclic_momentum_has_its_value():
    """p_phi = m l^2 sin^2 theta phi_dot, and h = T + V, at the initial state."""
    system = lagrangian.System(parse_model(SPHERICAL))
    body, status = _section(system, invariants.conserved_section)
    m, l, theta, theta_dot, phi_dot = 1.3, 0.8, 0.6, 0.4, 1.5
    p_phi = m * l**2 * math.sin(theta) ** 2 * phi_dot
    energy = 0.5 * m * l**2 * (theta_dot**2 + math.sin(theta) ** 2 * phi_dot**2) \
        - m * G * l * math.cos(theta)
    text = _text(body)
    shown = _numbers(text)
    assert status == "shown" and "cyclic coordinate" in text and "equal to T + V" in text
    for value in (p_phi, energy):
        assert any(abs(x - value) < 1e-5 * abs(value) for x in shown), (value, shown)
    assert "<msub><mi>p</mi><mi>φ</mi></msub>" in body


def rimless(spokes: int, gamma: float, l: float = 1.0) -> tuple[float, float, float]:
    """McGeer's wheel: (omega+, period, multiplier cos^2(2 alpha)), alpha = pi/spokes."""
    from scipy import integrate

    alpha = math.pi / spokes
    c = math.cos(2 * alpha)
    after = c * math.sqrt(4 * G / l * math.sin(alpha) * math.sin(gamma) / (1 - c * c))
    period = integrate.quad(
        lambda phi: 1 / math.sqrt(after**2 + 2 * G / l * (math.cos(gamma - alpha)
                                                          - math.cos(phi))),
        gamma - alpha, gamma + alpha, epsabs=1e-13, epsrel=1e-13)[0]
    return after, period, c * c


def test_the_rimless_wheels_cycle_is_mcgeers():
    body, status = _section(lagrangian.load("rimless_wheel"), invariants.limit_cycle_section)
    omega, period, multiplier = rimless(8, 0.08)
    text = _text(body)
    shown = _numbers(text)
    assert status == "shown" and "stable" in text and "unstable" not in text
    for value in (omega, period, multiplier, -math.pi / 8):
        assert any(abs(x - value) < 1e-7 * abs(value) for x in shown), (value, shown)


@pytest.fixture(scope="module")
def gait():
    return lagrangian.load("compass_gait")


def test_the_compass_gaits_multipliers_are_the_differenced_maps(gait):
    """The multipliers shown equal the eigenvalues of the Poincare map differenced by central
    differences (the library's map without its Jacobian), less the flow direction's 0."""
    body, status = _section(gait, invariants.limit_cycle_section)
    cycle = gait.limit_cycle()
    eom = gait.equations_of_motion()
    values = resolve_parameters(gait.model, None).symbol_values(gait.model)
    poincare = PoincareMap(eom, values, gait._numeric, CYCLE_STEPS, gait.impact_maps())
    x = np.array(list(cycle.state.values()))
    # on the section theta_st + theta_sw = 0 (a start off it strikes at once): coordinates
    # (theta_st, theta_st_dot, theta_sw_dot), theta_sw = -theta_st, in which P maps it to itself
    tangent = np.array([[1.0, -1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]).T
    step = 1e-6
    columns = [(poincare(x + step * e)[0] - poincare(x - step * e)[0])[[0, 2, 3]] / (2 * step)
               for e in tangent.T]
    eigenvalues = np.linalg.eigvals(np.array(columns).T)
    differenced = sorted(eigenvalues, key=lambda m: -abs(m))
    table = body.split("Multipliers")[1]
    moduli = [float(x) for x in re.findall(r"<td>([0-9.e-]+)</td></tr>", table)]
    assert status == "shown" and len(moduli) == 3
    for shown, theirs in zip(moduli, differenced, strict=True):
        assert shown == pytest.approx(abs(theirs), abs=1e-5)
    assert ("stable" if max(moduli) < 1 else "unstable") in _text(body)
    assert any(abs(v - cycle.period) < 1e-8 for v in _numbers(_text(body)))


def test_a_model_without_impacts_says_so_in_one_line():
    body, status = _section(lagrangian.load("pendulum"), invariants.limit_cycle_section)
    assert status == "not applicable: no impacts" and body.count("<p") == 1


def test_the_bouncing_ball_has_no_cycle_and_says_why():
    """e = 0.8 < 1: every bounce is lower, so no periodic motion; one line with the reason."""
    body, status = _section(lagrangian.load("bouncing_ball"), invariants.limit_cycle_section)
    assert status == "not applicable: no cycle found" and body.count("<p") == 1
    assert "No limit cycle found" in body


def test_the_expected_column_is_mathml():
    pendulum = lagrangian.load("pendulum")
    page = _Page(pendulum)
    body, _ = sections.check_section(page, pendulum.check(ANSWERS /
                                                          "pendulum_wrong_potential.toml"))
    rows = re.findall(r"<tr>(.*?)</tr>", str(body))[1:]
    expected = [re.findall(r"<td>(.*?)</td>", row)[-1] for row in rows]
    wrong = [cell for cell in expected if cell]
    assert wrong and all(cell.startswith("<math>") for cell in wrong), wrong
    assert not any("**" in cell or "*" in _text(cell) for cell in wrong)
    # our V = -m g L cos(theta), as the rest of the page writes it (MathWriter's markup)
    ours = MathWriter(pendulum.model)(pendulum.equations_of_motion().potential_energy)
    assert f"<math>{ours}</math>" in expected


def test_expected_text_reads_through_the_grammar_only():
    model = lagrangian.load("pendulum").model
    writer = MathWriter(model)
    equation = expected_markup(writer, model, "L^2*m*theta_ddot = -L*g*m*sin(theta)")
    assert equation.count("<mo>=</mo>") == 1 and "<mover accent=\"true\">" in equation
    assert expected_markup(writer, model, "none") == "none"  # a word, not a model name
    hostile = "__import__('os').system('x') = <script>"
    assert expected_markup(writer, model, hostile) == hostile  # left as text, escaped by h()
    assert "<mi>p</mi>" in expected_markup(writer, model, "p_theta^2/(2*m*L^2)")


def test_a_model_with_nothing_to_draw_says_so_in_one_sentence():
    two_mass = lagrangian.load("two_mass")
    report = two_mass.report(t_end=0.3)
    page = Page(report.html)
    assert page.section("model").count(NOTHING_TO_DRAW) == 1
    assert NOTHING_TO_DRAW in page.section("simulation")
    assert NOTHING_TO_DRAW in page.section("modes")
    assert "animation: nothing to animate" not in report.html
    statuses = {s.key: s.status for s in report.sections}
    assert statuses["conserved"] == "shown" and statuses["cycle"] == "not applicable: no impacts"


def test_a_divergent_mode_has_no_damping_ratio():
    """The rimless wheel's upright spoke: a real, growing eigenvalue, so zeta is '–'."""
    body, _ = _section(lagrangian.load("rimless_wheel"), sections.modes_section)
    row = re.findall(r"<tr>(.*?)</tr>", str(body))[1]
    cells = re.findall(r"<td>(.*?)</td>", row)
    assert cells[5] == "divergent" and cells[3] == "–", cells
