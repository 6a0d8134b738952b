"""Model files: every error names the file, the table and key, and what is wrong."""

import pytest
import sympy as sp

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.model.reader import parse_model, read_model

pytestmark = pytest.mark.smoke  # pytest -m smoke: the quick subset

PENDULUM = """
name = "Pendulum"
[coordinates]
theta = { unit = "rad", initial = 0.3, rate = 0.0 }
[parameters]
m = { value = 1.0, unit = "kg" }
L = 0.5
g = 9.81
[energy]
T = "1/2*m*L^2*theta_dot^2"
V = "-m*g*L*cos(theta)"
"""


def error(text: str) -> str:
    with pytest.raises(ModelError) as info:
        parse_model(text, source="bad.toml")
    return str(info.value)


def test_reads_the_documented_format():
    model = parse_model(PENDULUM, source="p.toml")
    assert model.name == "Pendulum"
    assert [c.name for c in model.coordinates] == ["theta"]
    assert model.coordinate("theta").initial == 0.3
    assert model.parameter("m").value == 1.0 and model.parameter("m").unit == "kg"
    assert model.parameter("L").value == 0.5


def test_parameter_units_are_converted_to_si():
    grams = 'm = { value = 500, unit = "g" }\nalpha = { value = 30, unit = "deg" }'
    model = parse_model(PENDULUM.replace('m = { value = 1.0, unit = "kg" }', grams))
    assert model.parameter("m").value == pytest.approx(0.5)
    assert model.parameter("alpha").value == pytest.approx(sp.pi.evalf() / 6)


def test_symbolic_parameter_without_value():
    model = parse_model(PENDULUM.replace("L = 0.5", 'L = { unit = "m" }'))
    assert model.parameter("L").value is None


def test_definitions_are_usable_after_their_definition():
    text = PENDULUM.replace("[energy]", '[definitions]\nh = "L*cos(theta)"\n[energy]').replace(
        '"-m*g*L*cos(theta)"', '"-m*g*h"')
    model = parse_model(text)
    theta, m, g, L = sp.symbols("theta m g L")
    assert model.potential_energy == -m * g * L * sp.cos(theta)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("[energy]", "[energy]\nW = \"m\""),
         "bad.toml: energy.W: unknown key 'W'; expected one of: D, T, V"),
        (("name =", "nme = 1\nname ="), "bad.toml: nme: unknown key 'nme'; did you mean 'name'?"),
        (('V = "-m*g*L*cos(theta)"', 'V = "-m*g*Ln*cos(theta)"'),
         "bad.toml: energy.V: unknown name 'Ln'; did you mean 'L'?"),
        (('V = "-m*g*L*cos(theta)"', 'V = "__import__(\'os\')"'),
         "bad.toml: energy.V: unknown function '__import__'"),
        (('V = "-m*g*L*cos(theta)"', 'V = "m.__class__"'),
         "bad.toml: energy.V: attribute access ('.') is not allowed (in 'm.__class__')"),
        (('V = "-m*g*L*cos(theta)"', 'V = "2**99999"'),
         "bad.toml: energy.V: the exponent 99999 is too large (at most 1000)"),
        (('unit = "kg"', 'unit = "kilofoo"'), "bad.toml: parameters.m.unit: unknown unit 'kilofoo'"),
        (("initial = 0.3", 'initial = "x"'),
         "bad.toml: coordinates.theta.initial: expected a number, got 'x'"),
        (("g = 9.81", "g = 9.81\ntheta = 1"), "bad.toml: parameters.theta: 'theta' is declared twice"),
        (("g = 9.81", "g = 9.81\nsin = 1"),
         "bad.toml: parameters.sin: 'sin' is reserved (a function, constant or time)"),
    ],
)
def test_errors_name_file_field_and_problem(change, message):
    assert error(PENDULUM.replace(*change)) == message


def test_missing_coordinates_table():
    assert error('name = "x"') == "bad.toml: coordinates: missing table [coordinates]"


def test_invalid_toml():
    assert error("name = ").startswith("bad.toml: invalid TOML:")


def test_component_errors():
    base = '[coordinates]\nx = "m"\n[parameters]\nm = 1\n'
    assert error(base + '[[particles]]\nname = "p"\nmass = "m"\nposition = ["x", 0, 0, 1]') == \
        "bad.toml: particles[0].position: expected 2 or 3 components, got 4"
    assert error(base + '[[particles]]\nname = "p"\nmass = "m"\nposition = ["x"]') == \
        "bad.toml: particles[0].position: expected 2 or 3 components, got 1"
    assert error(base + '[[particles]]\nname = "p"\nposition = ["x", 0]') == \
        "bad.toml: particles[0]: missing key 'mass'"
    extra = '[[particles]]\nname = "p"\nmass = "m"\nposition = ["x", 0]\ncolour = 1'
    assert error(base + extra) == \
        "bad.toml: particles[0].colour: unknown key 'colour'; expected one of: mass, name, position"
    assert error(base + '[[particles]]\nname = "p"\nmass = "m"\nposition = ["x_dot", 0]') == \
        "bad.toml: particles[0].position[0]: may not depend on velocities (found x_dot)"
    assert error(base + '[[springs]]\nname = "s"\nstiffness = 1\nbetween = ["p", [0, 0]]') == \
        "bad.toml: springs[0].between[0]: 'p' is not a particle or body (declare it before use)"
    assert error(base + '[[loads]]\nname = "F"\npoint = [1, 0]\nforce = [1, 0]') == (
        "bad.toml: loads[0].point: the point of load 'F' does not depend on any coordinate, so the "
        "load does no virtual work; attach it to a moving point")
    assert error(base + '[[loads]]\nname = "F"\npoint = ["x", 0]') == \
        "bad.toml: loads[0]: missing key 'force'"
    assert error(base + '[[constraints]]\nname = "c"\nvelocity = "x_dot^2"') == \
        "bad.toml: constraints[0].velocity: a velocity constraint must be linear in the velocities"
    assert error(base + '[[constraints]]\nname = "c"\nholonomic = "x_dot"') == \
        "bad.toml: constraints[0].holonomic: may not depend on velocities (found x_dot)"
    assert error(base + '[gravity]\ng = 9.81\ndirection = [0, 0]') == \
        "bad.toml: gravity.direction: the direction is the zero vector"


def test_missing_file_is_named():
    with pytest.raises(ModelError, match="nowhere.toml: no such file"):
        read_model("nowhere.toml")


def test_every_builtin_example_loads_and_derives():
    for name in lagrangian.examples():
        eom = lagrangian.load(name).equations_of_motion()
        assert eom.mass_matrix.shape[0] == len(eom.model.coordinates)


def test_non_finite_numbers_are_refused():
    assert error(PENDULUM.replace("g = 9.81", "g = 1e400")) == \
        "bad.toml: parameters.g: the number inf is not finite"
    assert error(PENDULUM.replace('m = { value = 1.0, unit = "kg" }',
                                  'm = { value = 1e999, unit = "kg" }')) == \
        "bad.toml: parameters.m.value: the number inf is not finite"
    assert error(PENDULUM.replace("initial = 0.3", "initial = nan")) == \
        "bad.toml: coordinates.theta.initial: the number nan is not finite"


def test_unreadable_unit_strings_are_refused():
    assert error(PENDULUM.replace('unit = "kg"', 'unit = "sin("')) == \
        "bad.toml: parameters.m.unit: unknown unit 'sin('"
    assert error(PENDULUM.replace('theta = { unit = "rad"', 'theta = { unit = "m/(s"')) == \
        "bad.toml: coordinates.theta.unit: unknown unit 'm/(s'"
