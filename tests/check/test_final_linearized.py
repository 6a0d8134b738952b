"""[linearized] beyond the small unconstrained model about q = 0: about any equilibrium the
answer names, on the constraints of a constrained model (in the independent coordinates the
student writes), an equilibrium that moves with the parameters, and many coordinates."""

from __future__ import annotations

import math

import pytest
import sympy as sp
from check_helpers import check_text, finding, system

from lagrangian import ModelError, SystemBuilder
from lagrangian.model.answer import parse_answer

HANGING = """
name = "Hanging mass"
[coordinates]
x = { unit = "m", initial = 0.1, rate = 0.0 }
[parameters]
m = { value = 1.0, unit = "kg" }
k = { value = 4.0, unit = "N/m" }
g = { value = 9.81, unit = "m/s^2" }
[gravity]
g = "g"
direction = [0, -1]
[[particles]]
name = "mass"
mass = "m"
position = [0, "-x"]
[[springs]]
name = "spring"
stiffness = "k"
length = "x"
"""


def linearized(model: str, about: str, **equations: str):
    lines = "".join(f'{name} = "{text}"\n' for name, text in equations.items())
    return check_text(model, f"[linearized]\nabout = {{ {about} }}\n{lines}")


# -- a constrained model: the Cartesian pendulum, x^2 + y^2 = L^2 ------------------------------

def test_cartesian_pendulum_linearized_in_x_on_the_constraint():
    # About the bottom (0, -L), y = -L + O(x^2): x_ddot + (g/L) x = 0, omega^2 = g/L.
    report = linearized("cartesian_pendulum", "x = 0", x="x_ddot + g/L*x = 0")
    line = finding(report, "linearized.x")
    assert line.status == "correct", report
    assert "in x, the others following from the constraints" in line.message
    assert linearized("cartesian_pendulum", "x = 0",
                      x=f"x_ddot + {9.81 / 0.5:.4f}*x = 0").verdict == "correct"


def test_cartesian_pendulum_wrong_coefficient_named_with_its_value():
    line = finding(linearized("cartesian_pendulum", "x = 0", x="x_ddot + 2*g/L*x = 0"),
                   "linearized.x")
    assert line.code == "linear_coefficient"
    assert "2*g/L = 39.24 in yours, ours is 19.62" in line.message


def test_too_many_coordinates_for_the_degrees_of_freedom_refused_in_one_line():
    with pytest.raises(ModelError, match="1 degree.*of freedom.*ours: x.*got x, y") as error:
        linearized("cartesian_pendulum", "x = 0", x="x_ddot + g/L*x = 0",
                   y="y_ddot + g/L*y = 0")
    assert error.value.field == "linearized" and "\n" not in str(error.value)


def test_a_coordinate_the_constraints_do_not_fix_the_others_through_is_refused():
    # At the bottom dy = 0 to first order: y cannot be the independent coordinate.
    with pytest.raises(ModelError, match="y cannot serve as independent"):
        linearized("cartesian_pendulum", "x = 0", y="y_ddot + g/L*y = 0")


def test_four_bar_frequency_is_the_same_in_any_independent_coordinate():
    # One degree of freedom: z_ddot + omega^2 (z - z0) = 0 in theta1 or in theta3 alike.
    four_bar = system("four_bar")
    analysis = four_bar.modes()
    omega2 = analysis.modes[0].frequency ** 2
    q0 = analysis.equilibrium
    about = ", ".join(f"{k} = {v!r}" for k, v in q0.items())
    for name in ("theta1", "theta3"):
        right = f"{name}_ddot + {omega2!r}*({name} - {q0[name]!r}) = 0"
        report = linearized("four_bar", about, **{name: right})
        assert report.verdict == "correct", report
        wrong = f"{name}_ddot + {1.1 * omega2!r}*({name} - {q0[name]!r}) = 0"
        assert finding(linearized("four_bar", about, **{name: wrong}),
                       f"linearized.{name}").code == "linear_coefficient"


# -- an equilibrium that moves with the parameters: x0 = m g / k ------------------------------

@pytest.fixture(scope="module")
def hanging(tmp_path_factory):
    import lagrangian

    path = tmp_path_factory.mktemp("hanging") / "hanging.toml"
    path.write_text(HANGING)
    return lagrangian.load(path)


@pytest.mark.parametrize(("equation", "code"), [
    ("m*x_ddot + k*(x - m*g/k) = 0", None),      # in the coordinate itself
    ("m*x_ddot + k*x = m*g", None),
    ("m*x_ddot + k*x = 0", None),                # in the deviation from x0
    ("m*x_ddot + 2*k*x = m*g", "linear_coefficient"),
    ("m*x_ddot + k*x = 2*m*g", "linear_offset"),
])
def test_hanging_mass_about_its_static_deflection(hanging, equation, code):
    x0 = 1.0 * 9.81 / 4.0
    text = f'[linearized]\nabout = {{ x = "{x0} m" }}\nx = "{equation}"\n'
    report = hanging.check(parse_answer(text, hanging.model, source="<test>"))
    assert finding(report, "linearized.x").code == code, report


# -- many coordinates: ten masses between two walls, hanging under gravity ---------------------

def chain(n: int):
    b = SystemBuilder(f"{n}-mass chain")
    m, k = b.parameter("m", 1.0, "kg"), b.parameter("k", 2.0, "N/m")
    b.set_gravity(b.parameter("g", 9.81, "m/s^2"), (1, 0))
    xs = [b.coordinate(f"x{i}", unit="m") for i in range(1, n + 1)]
    for i, x in enumerate(xs, 1):
        b.add_particle(f"mass{i}", m, (x, 0))
    previous = 0
    for i, x in enumerate([*xs, 0]):
        b.add_spring(f"spring{i}", k, 0, length=x - previous)
        previous = x
    return b.build()


def test_ten_mass_chain_linearized_about_its_sagged_equilibrium():
    # m x_i'' + 2 k x_i - k x_(i-1) - k x_(i+1) = 0 in the deviations from the sag.
    ten = chain(10)
    text = ('[linearized]\nabout = { ABOUT }\n'
            'x4 = "m*x4_ddot + 2*k*x4 - k*x3 - k*x5 = 0"\n'
            'x10 = "m*x10_ddot + 2*k*x10 - k*x9 = 0"\n')
    # the sag x_i = m g i (n + 1 - i) / (2 k) (an about that is no equilibrium is refused)
    sag = {f"x{i}": 9.81 / 4.0 * i * (11 - i) for i in range(1, 11)}
    about = ", ".join(f"{k} = {v!r}" for k, v in sag.items())
    report = ten.check(parse_answer(text.replace("ABOUT", about), ten.model, source="<t>"))
    assert report.verdict == "correct", report
    assert "x4 = 68.67" in finding(report, "linearized.x4").message
    wrong = text.replace("ABOUT", about).replace("2*k*x4", "k*x4")
    line = finding(ten.check(parse_answer(wrong, ten.model, source="<t>")), "linearized.x4")
    assert line.code == "linear_coefficient" and "coefficient of x4 is k = 2 in yours, ours is 4" \
        in line.message


# -- a pendulum pushed sideways: its equilibrium tan(theta0) = F/(m g) moves with F ----------

def pushed():
    b = SystemBuilder("pushed pendulum")
    theta = b.coordinate("theta", unit="rad", initial=0.4)
    m, L, g, F = (b.parameter(n, v, u) for n, v, u in (("m", 1.0, "kg"), ("L", 0.5, "m"),
                                                        ("g", 9.81, "m/s^2"), ("F", 5.0, "N")))
    b.set_gravity(g, (0, -1))
    bob = (L * sp.sin(theta), -L * sp.cos(theta))
    b.add_particle("bob", m, bob)
    b.add_force("push", bob, (F, 0))
    return b.build()


def test_matrices_and_equation_about_an_equilibrium_that_moves_with_a_parameter():
    # K = m g L cos(theta0) + F L sin(theta0) = L sqrt((m g)^2 + F^2), M = m L^2
    system = pushed()
    theta0 = math.atan2(5.0, 9.81)
    text = (f'[linearized]\nabout = {{ theta = {theta0!r} }}\n'
            'theta = "m*L^2*theta_ddot + L*sqrt((m*g)^2 + F^2)*(theta - atan(F/(m*g))) = 0"\n'
            '[matrices]\nM = [["m*L^2"]]\nK = [["L*sqrt((m*g)^2 + F^2)"]]\n')
    report = system.check(parse_answer(text, system.model, source="<t>"))
    assert report.verdict == "correct", report
    wrong = text.replace('K = [["L*sqrt', 'K = [["2*L*sqrt')
    found = system.check(parse_answer(wrong, system.model, source="<t>"))
    assert finding(found, "K").code == "matrix_entry"
