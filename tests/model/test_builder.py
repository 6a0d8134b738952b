"""The builder's checks on vectors and gravity: every vector has the model's dimension, and
gravity may be given by expressions in parameters (an incline angle)."""

from __future__ import annotations

import math

import pytest
import sympy as sp

from lagrangian.derivation.lagrange import derive
from lagrangian.errors import ModelError
from lagrangian.model.builder import ModelBuilder
from lagrangian.model.reader import parse_model

BASE = '[coordinates]\nx = "m"\n[parameters]\nm = 1\n'
PARTICLE = '[[particles]]\nname = "p"\nmass = "m"\nposition = ["x", 0]\n'


def error(text: str) -> str:
    with pytest.raises(ModelError) as info:
        parse_model(text, source="bad.toml")
    return str(info.value)


def test_a_3_component_force_in_a_planar_model_is_refused():
    load = '[[loads]]\nname = "F"\npoint = "p"\nforce = [1, 0, 0]\n'
    assert error(BASE + PARTICLE + load) == \
        "bad.toml: loads[0].force: 3 components in a planar model"


def test_a_2_component_vector_in_a_3d_model_is_refused():
    particle = '[[particles]]\nname = "p"\nmass = "m"\nposition = ["x", 0, 0]\n'
    load = '[[loads]]\nname = "F"\npoint = [0, "x"]\nforce = [1, 0, 0]\n'
    assert error(BASE + particle + load) == "bad.toml: loads[0].point: 2 components in a 3D model"
    spring = '[[springs]]\nname = "s"\nstiffness = 1\nbetween = ["p", [0, 0]]\n'
    assert error(BASE + particle + spring) == \
        "bad.toml: springs[0].between[1]: 2 components in a 3D model"


def test_particles_must_agree_and_gravity_given_before_them_is_checked():
    second = '[[particles]]\nname = "q"\nmass = "m"\nposition = ["x", 0, 1]\n'
    assert error(BASE + PARTICLE + second) == \
        "bad.toml: particles[1].position: 3 components in a planar model"
    gravity = '[gravity]\ng = 9.81\ndirection = [0, 0, -1]\n'
    assert error(BASE + gravity + PARTICLE) == \
        "bad.toml: gravity.direction: 3 components in a planar model"


def test_a_3d_model_names_the_direction_of_gravity():
    particle = '[[particles]]\nname = "p"\nmass = "m"\nposition = [0, 0, "x"]\n'
    assert error(BASE + '[gravity]\ng = 9.81\n' + particle) == \
        "bad.toml: gravity.direction: give the direction of gravity in a 3D model (3 components)"
    model = parse_model(BASE + '[gravity]\ng = 9.81\ndirection = [0, 0, -2]\n' + particle)
    assert model.gravity.direction == (0, 0, -1)


def test_a_body_is_planar():
    body = ('[[bodies]]\nname = "b"\nmass = "m"\ninertia = 1\nposition = ["x", 0, 0]\n'
            'angle = "x"\n')
    assert error(BASE + body) == (
        "bad.toml: bodies[0].position: 3 components: a body is planar (it turns about z); "
        "give its position as [x, y]")
    offset = ('[[bodies]]\nname = "b"\nmass = "m"\ninertia = 1\nposition = ["x", 0]\n'
              'angle = "x"\n[[loads]]\nname = "F"\npoint = {body = "b", offset = [1, 0, 0]}\n'
              'force = [1, 0]\n')
    assert error(BASE + offset) == "bad.toml: loads[0].point.offset: 3 components in a planar model"


def test_gravity_may_depend_on_parameters_but_not_on_the_state():
    assert error(BASE + '[gravity]\ng = "9.81*x"\n' + PARTICLE) == \
        "bad.toml: gravity.g: may depend on parameters only (found x)"
    assert error(BASE + '[gravity]\ng = 9.81\ndirection = ["sin(t)", -1]\n' + PARTICLE) == \
        "bad.toml: gravity.direction[0]: may depend on parameters only (found t)"
    assert error(BASE + '[gravity]\ng = 9.81\ndirection = ["m - 1", 0]\n' + PARTICLE) == \
        "bad.toml: gravity.direction: the direction is the zero vector"


INCLINE = """
name = "Block on an incline (gravity tilted by the incline angle)"
[coordinates]
s = "m"
[parameters]
m = 2.0
g = 9.81
alpha = { value = 30, unit = "deg" }
[gravity]
g = "g"
direction = ["sin(alpha)", "-cos(alpha)"]
[[particles]]
name = "block"
mass = "m"
position = ["s", 0]
"""


def test_an_incline_angle_as_a_parameter_gives_g_sin_alpha():
    model = parse_model(INCLINE)
    eom = derive(model)
    m, g, alpha = (model.parameter(n).symbol for n in ("m", "g", "alpha"))
    # The direction is already a unit vector: no sqrt(sin^2 + cos^2) is left in the equations.
    assert model.gravity.direction[:2] == (sp.sin(alpha), -sp.cos(alpha))
    assert sp.expand(eom.forcing[0] - m * g * sp.sin(alpha)) == 0
    assert eom.accelerations[0] == g * sp.sin(alpha)
    assert float(eom.accelerations[0].subs({g: 9.81, alpha: math.radians(30)})) == \
        pytest.approx(9.81 / 2)


def test_a_symbolic_direction_that_is_not_a_unit_vector_is_normalized():
    b = ModelBuilder("tilted")
    x = b.coordinate("x")
    a = b.parameter("a", 3.0)
    b.set_gravity(10, (a, -4))
    b.add_particle("p", 1, (x, 0))
    model = b.build_model()
    norm = sp.sqrt(a**2 + 16)
    assert model.gravity.direction[:2] == (a / norm, -4 / norm)
    assert float(derive(model).forcing[0].subs(a, 3.0)) == pytest.approx(10 * 3 / 5)


def test_python_builder_default_gravity_points_down_in_a_plane():
    b = ModelBuilder("drop")
    y = b.coordinate("y")
    b.set_gravity(9.81)
    b.add_particle("p", 1, (0, y))
    assert b.build_model().gravity.direction == (0, -1, 0)
