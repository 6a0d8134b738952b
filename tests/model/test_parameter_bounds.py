"""A parameter's `range` and `integer` (a count: the rimless wheel's spokes) bound every value
it is given (the file's own, with_parameters, --set, a study's), each refused in one line
naming the parameter and its range; a value inside is taken, and the physics follows it (the
wheel's return multiplier cos^2(2 pi / spokes), McGeer)."""

from __future__ import annotations

import math
import re

import pytest

import lagrangian
from lagrangian.model.reader import parse_model

SPRING = """
[coordinates]
x = {{ unit = "m", initial = 0.1 }}
[parameters]
k = {{ {k} }}
m = 1
[energy]
T = "m*x_dot^2/2"
V = "k*x^2/2"
"""


@pytest.mark.parametrize(("spec", "message"), [
    ('value = -1, range = [0, inf], unit = "N/m"', "parameters.k: 'k' = -1 is outside its range [0, inf]"),
    ("value = 2.5, integer = true", "parameters.k: 'k' is a whole number (a count), not 2.5"),
    ("value = 1, range = [2, 1]", "parameters.k.range: lower must not be above upper"),
    ('value = 1, range = [0, "a"]', "parameters.k.range: a bound is a number"),
    ("value = 1, range = [0]", "parameters.k.range: expected [lower, upper]"),
    ('value = 1, integer = "yes"', "parameters.k.integer: integer is true or false"),
])
def test_a_file_value_outside_its_bounds_is_one_line(spec, message):
    with pytest.raises(lagrangian.ModelError) as caught:
        parse_model(SPRING.format(k=spec), source="spring.toml")
    assert str(caught.value) == f"spring.toml: {message}" or message in str(caught.value)
    assert "\n" not in str(caught.value)


def test_a_range_in_a_unit_is_converted_to_si():
    model = parse_model(SPRING.format(k='value = 2, range = [1, 3], unit = "N/cm"'))
    (k,) = [p for p in model.parameters if p.name == "k"]
    assert k.value == pytest.approx(200.0) and k.range == pytest.approx((100.0, 300.0))


def test_the_wheel_takes_a_whole_number_of_spokes_and_refuses_the_rest(cli):
    wheel = lagrangian.load("rimless_wheel")
    for bad, words in ((6.5, "whole number"), (2, "outside its range [3, inf]")):
        with pytest.raises(lagrangian.ModelError, match=re.escape(words)):
            wheel.with_parameters(spokes=bad)
        result = cli("cycle", "rimless_wheel", "--set", f"spokes={bad:g}")
        assert result.code == 2 and len(result.err.strip().splitlines()) == 1, result.err
        assert words in result.err and "'spokes'" in result.err
    cycle = wheel.with_parameters(spokes=8).limit_cycle()
    (multiplier,) = cycle.multipliers
    assert abs(multiplier) == pytest.approx(math.cos(2 * math.pi / 8) ** 2, abs=1e-8)


def test_a_restitution_parameter_is_held_to_zero_one_where_it_is_given(tmp_path, cli):
    """The parameter that is an impact's restitution: its file value refused naming the impact
    (it was reported under --set, which the user never gave), --set and with_parameters by
    its range [0, 1]; inside, the ball rebounds at e times its speed."""
    from lagrangian.model.examples import example_text

    text = example_text("bouncing_ball")
    path = tmp_path / "ball.toml"
    path.write_text(text.replace("e = 0.8", "e = -0.5"))
    with pytest.raises(lagrangian.ModelError) as caught:
        lagrangian.load(path)
    assert "ball.toml: impacts[0].restitution: the restitution 'e' = -0.5" in str(caught.value)
    result = cli("simulate", "bouncing_ball", "--t-end", "1", "--set", "e=1.5")
    assert result.code == 2 and result.err.strip() == (
        "error: --set: 'e' = 1.5 is outside its range [0, 1]")
    ball = lagrangian.load("bouncing_ball")
    with pytest.raises(lagrangian.ModelError, match=re.escape("outside its range [0, 1]")):
        ball.with_parameters(e=-0.1)
    run = ball.with_parameters(e=0.5).simulate(1.0)
    (first, *_) = run.impacts
    assert first.after["y_dot"] == pytest.approx(-0.5 * first.before["y_dot"], rel=1e-9)
