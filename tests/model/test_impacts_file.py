"""[[impacts]] in a model file: what it declares, and each bad entry refused in one line naming
the file, the field and the fault (model/impacts.py, model/reader.py)."""

from __future__ import annotations

import pytest
import sympy as sp

from lagrangian.errors import ModelError
from lagrangian.model.reader import parse_model

BALL = """
[coordinates]
x = { unit = "m", initial = 0.0, rate = 1.0 }
y = { unit = "m", initial = 1.0 }
[parameters]
m = 1.0
e = 0.5
[gravity]
g = 9.81
[[particles]]
name = "ball"
mass = "m"
position = ["x", "y"]
"""
IMPACT = """
[[impacts]]
name = "floor"
guard = "y"
point = "ball"
normal = [0, 2]
restitution = "e"
"""


def test_an_impact_as_declared():
    impact, = parse_model(BALL + IMPACT + 'tangential = "stick"\n', source="ball.toml").impacts
    x, y = sp.symbols("x y")
    assert impact.name == "floor" and impact.guard == y
    assert impact.point == (x, y, 0)
    assert impact.normal == (0, 1, 0)  # made unit
    assert impact.restitution == sp.Symbol("e") and impact.tangential == "stick"
    assert impact.release == () and impact.relabel == ()


def test_defaults_slip_and_plastic():
    text = BALL + IMPACT.replace('restitution = "e"\n', "")
    impact, = parse_model(text).impacts
    assert impact.tangential == "slip" and impact.restitution == 0


def test_a_body_point_and_a_relabel():
    text = BALL + IMPACT.replace('point = "ball"', 'point = ["x + 0.1", "y"]') + \
        'relabel = { x = "x - 1" }\n'
    impact, = parse_model(text).impacts
    x = sp.Symbol("x")
    assert impact.point[0] == x + sp.Rational(1, 10) and impact.relabel == (("x", x - 1),)


@pytest.mark.parametrize(("change", "field", "fault"), [
    (("restitution = \"e\"", "restitution = 1.5"), "impacts[0].restitution", "[0, 1]"),
    (("restitution = \"e\"", "restitution = \"y\""), "impacts[0].restitution",
     "parameters only"),
    (("guard = \"y\"", "guard = \"m\""), "impacts[0].guard", "does not depend"),
    (("guard = \"y\"", "guard = \"y_dot\""), "impacts[0].guard", "velocities"),
    (("normal = [0, 2]", "normal = [0, 0]"), "impacts[0].normal", "zero vector"),
    (("normal = [0, 2]", "normal = [0, 0, 1]"), "impacts[0].normal", "3 components"),
    (("point = \"ball\"", "point = \"wheel\""), "impacts[0].point", "not a particle"),
    (("name = \"floor\"", "name = \"floor\"\nbounce = 1"), "impacts[0].bounce", "unknown key"),
    (("name = \"floor\"", "name = \"floor\"\ntangential = \"sticky\""),
     "impacts[0].tangential", "did you mean"),
    (("name = \"floor\"", "name = \"floor\"\ntangential = 3"), "impacts[0].tangential",
     "expected a string"),
    (("name = \"floor\"", "name = \"floor\"\nrelease = \"foot\""), "impacts[0].release",
     "pivot"),
    (("name = \"floor\"", "name = \"floor\"\nrelease = \"pivot\""),
     "impacts[0].tangential", "stick"),
    (("name = \"floor\"", "name = \"floor\"\nrelabel = { z = \"x\" }"),
     "impacts[0].relabel.z", "not a coordinate"),
    (("name = \"floor\"", "name = \"floor\"\nrelabel = [1]"), "impacts[0].relabel",
     "expected a table"),
    (("guard = \"y\"\n", ""), "impacts[0]", "missing key 'guard'"),
])
def test_bad_entries_refused_in_one_line(change, field, fault):
    old, new = change
    text = BALL + IMPACT.replace(old, new, 1)
    with pytest.raises(ModelError) as caught:
        parse_model(text, source="ball.toml")
    message = str(caught.value)
    assert "\n" not in message and message.startswith("ball.toml: ")
    assert caught.value.field == field and fault in message, message


def test_a_released_pivot_needs_no_bounce():
    text = BALL + IMPACT + 'tangential = "stick"\nrelease = "pivot"\n'
    with pytest.raises(ModelError, match="restitution = 0"):
        parse_model(text.replace('restitution = "e"', "restitution = 0.5"))
    assert parse_model(text.replace('restitution = "e"', "restitution = 0")).impacts[0].release \
        == ("pivot",)


def test_impacts_must_be_an_array_of_tables():
    with pytest.raises(ModelError, match=r"array of tables \[\[impacts\]\]"):
        parse_model("impacts = 3\n" + BALL)
