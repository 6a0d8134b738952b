"""[momenta], [conserved], [routhian] and [hamiltonian] answers judged against closed forms
(issue 40): the spherical pendulum's Routhian (Goldstein's sign), the pendulum's H, the hoop's
Jacobi integral, each wrong form with its own diagnosis."""

from __future__ import annotations

import pytest
from check_helpers import check_text, finding

import lagrangian
from conserved_models import DAMPED_PAIR, PUSHED_PAIR, SPHERICAL_PENDULUM
from lagrangian.errors import ModelError
from lagrangian.model.answer import parse_answer


@pytest.fixture(scope="module")
def spherical(tmp_path_factory):
    path = tmp_path_factory.mktemp("spherical") / "spherical.toml"
    path.write_text(SPHERICAL_PENDULUM)
    return lagrangian.load(path)


def _check(system, text):
    return system.check(parse_answer(text, system.model, source="<test>"))


# R = p_phi^2/(2 m l^2 sin^2 theta) - 1/2 m l^2 theta_dot^2 - m g l cos(theta) (Goldstein)
ROUTHIAN = "p_phi^2/(2*m*l^2*sin(theta)^2) - 1/2*m*l^2*theta_dot^2 - m*g*l*cos(theta)"


@pytest.mark.parametrize(("key", "text", "code"), [
    ("R", ROUTHIAN, None),
    ("L_R", f"-({ROUTHIAN})", None),
    ("R", f"-({ROUTHIAN})", "routhian_sign"),
    ("R", ROUTHIAN.replace("p_phi^2/(2*", "p_phi^2/("), "effective_potential"),
])
def test_the_spherical_pendulums_routhian(spherical, key, text, code):
    report = _check(spherical, f'[routhian]\ncyclic = ["phi"]\n{key} = "{text}"\n')
    item = finding(report, key)
    assert item.code == code, item
    assert (item.status == "correct") == (code is None)


def test_a_routhian_about_a_coordinate_that_is_not_cyclic_says_why(spherical):
    report = _check(spherical, f'[routhian]\ncyclic = ["theta"]\nR = "{ROUTHIAN}"\n')
    item = finding(report, "cyclic[theta]")
    assert item.code == "not_cyclic" and "L depends on it through" in item.message


def test_the_spherical_pendulums_momenta_and_what_is_conserved(spherical):
    report = _check(spherical, '''
[momenta]
phi = "m l² sin²θ φ̇"
theta = "m l² θ̇"
[conserved]
cyclic = ["phi"]
quantities = ["m l² sin²θ φ̇", "½ m l² (θ̇² + sin²θ φ̇²) − m g l cosθ", "m l² θ̇"]
''')
    assert finding(report, "p[phi]").status == "correct"
    assert finding(report, "p[theta]").status == "correct"
    assert finding(report, "cyclic[phi]").status == "correct"
    assert finding(report, "conserved[1]").status == "correct"
    assert finding(report, "conserved[2]").status == "correct"
    assert finding(report, "conserved[3]").code == "not_cyclic"


@pytest.mark.parametrize(("H", "code"), [
    ("p_theta^2/(2*m*L^2) - m*g*L*cos(theta)", None),
    ("1/2*m*L^2*theta_dot^2 - m*g*L*cos(theta)", "hamiltonian_in_velocities"),
    ("1/2*m*L^2*p_theta^2 - m*g*L*cos(theta)", "hamiltonian_inverse"),
    ("p_theta^2/(2*m*L^2) + m*g*L*cos(theta)", "hamiltonian_wrong"),
])
def test_the_pendulums_hamiltonian(H, code):
    item = finding(check_text("pendulum", f'[hamiltonian]\nH = "{H}"\n'), "H")
    assert item.code == code, item


def test_t_plus_v_on_the_driven_hoop_is_not_conserved_but_h_is():
    report = check_text("bead_on_hoop", '''
[conserved]
quantities = ["1/2*m*R^2*(theta_dot^2 + Omega^2*sin(theta)^2) - m*g*R*cos(theta)",
              "1/2*m*R^2*(theta_dot^2 - Omega^2*sin(theta)^2) - m*g*R*cos(theta)"]
''')
    energy = finding(report, "conserved[1]")
    assert energy.code == "energy_not_conserved"
    assert energy.message.startswith("T + V is not conserved here: the drive does work")
    assert finding(report, "conserved[2]").status == "correct"


def test_bad_tables_name_the_field():
    with pytest.raises(ModelError, match="conserved.cyclic: 'psi' is not a coordinate"):
        check_text("pendulum", '[conserved]\ncyclic = ["psi"]\n')
    with pytest.raises(ModelError, match="hamiltonian.H"):
        check_text("pendulum", '[hamiltonian]\nH = 3\n')


def test_total_momentum_claimed_where_a_load_breaks_it_says_which_load(tmp_path):
    """m1 x1_dot + m2 x2_dot is the quantity of the translation xi = (1, 1): a dashpot on the
    stretch does no work along it (still conserved), a push k on x1 does (Q . xi = k)."""
    claim = '[conserved]\nquantities = ["m₁ ẋ₁ + m₂ ẋ₂"]\n'
    for name, text in (("damped", DAMPED_PAIR), ("pushed", PUSHED_PAIR)):
        (tmp_path / f"{name}.toml").write_text(text)
    damped = _check(lagrangian.load(tmp_path / "damped.toml"), claim)
    assert finding(damped, "conserved[1]").status == "correct"
    pushed = finding(_check(lagrangian.load(tmp_path / "pushed.toml"), claim), "conserved[1]")
    assert pushed.code == "momentum_not_conserved", pushed
    assert "virtual work along it: Q . xi = k" in pushed.message
    # the pair's x1 is in L through its spring: the terms named with their own signs
    cyclic = finding(_check(lagrangian.load(tmp_path / "damped.toml"),
                            '[conserved]\ncyclic = ["x1"]\n'), "cyclic[x1]")
    assert cyclic.code == "not_cyclic" and "+ -" not in cyclic.message
    assert "k*x1*x2 - k*l0*x1" in cyclic.message


def test_a_magnetic_fields_potential_is_named_not_a_drive():
    """A charge in a uniform field B (V = -q v . A, A = B/2 (-y, x)): the force does no work,
    so 1/2 m v^2 is conserved and T + V is not, for V's rates, not a drive; the canonical
    angular momentum m (x y_dot - y x_dot) + q B (x^2 + y^2)/2 is conserved, the kinetic one
    alone is not."""
    claims = ["½ m (ẋ² + ẏ²) − q B/2 (x ẏ − y ẋ)", "½ m (ẋ² + ẏ²)",
              "m (x ẏ − y ẋ) + ½ q B (x² + y²)", "m (x ẏ − y ẋ)"]
    text = "[conserved]\nquantities = [" + ", ".join(f'"{c}"' for c in claims) + "]\n"
    report = check_text("charged_particle", text)
    energy = finding(report, "conserved[1]")
    assert energy.code == "energy_not_conserved", energy
    assert "velocity-dependent potential" in energy.message and "drive" not in energy.message
    assert [finding(report, f"conserved[{k}]").status for k in (2, 3, 4)] == \
        ["correct", "correct", "wrong"]
