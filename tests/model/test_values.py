"""State and ParameterValues: values by name resolved against the model's defaults, in one place."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import sympy as sp

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.model.values import (
    ParameterValues,
    State,
    resolve_parameters,
    resolve_state,
    state_units,
)


@pytest.fixture(scope="module")
def double():
    return lagrangian.load("double_pendulum").model


def test_state_takes_the_model_defaults_where_nothing_is_given():
    builder = lagrangian.SystemBuilder("two")
    builder.coordinate("x", initial=0.25, rate=-1.5)
    builder.coordinate("y")  # no initial value, no rate: 0
    model = builder.build().model
    state = resolve_state(model)
    assert state.coordinates == ("x", "y") and state.velocities == ("x_dot", "y_dot")
    assert state.q == (0.25, 0.0) and state.q_dot == (-1.5, 0.0) and state.t == 0.0
    assert state.given == frozenset()
    given = resolve_state(model, {"y": 2.0, "x_dot": 3.0, "t": 1.0})
    assert given.q == (0.25, 2.0) and given.q_dot == (3.0, 0.0) and given.t == 1.0
    assert given.given_values() == {"y": 2.0, "x_dot": 3.0, "t": 1.0}
    assert given.as_dict() == {"x": 0.25, "y": 2.0, "x_dot": 3.0, "y_dot": 0.0, "t": 1.0}
    symbols = given.symbol_values(model)
    assert symbols[model.coordinates[1].symbol] == 2.0 and symbols[model.time] == 1.0


def test_state_is_immutable_and_ordered_by_the_model(double):
    state = resolve_state(double, {"theta2": 0.5, "theta1": 0.1})
    assert state.coordinates == tuple(c.name for c in double.coordinates)
    np.testing.assert_array_equal(state.q_array(), [0.1, 0.5])
    with pytest.raises(dataclasses.FrozenInstanceError):
        state.t = 2.0  # type: ignore[misc]
    assert resolve_state(double, state) is state


def test_exact_numbers_are_accepted_in_si_units(double):
    state = resolve_state(double, {"theta1": sp.pi / 2, "theta2": np.float64(1.0)})
    assert state.q[0] == pytest.approx(math.pi / 2)


@pytest.mark.parametrize(("values", "field", "message"), [
    ({"phi": 1.0}, "initial", "'phi' is not a coordinate, velocity or t of this model"),
    ({"thetaa1": 1.0}, "about", "did you mean 'theta1'?"),
    ({"theta1": "30deg"}, "configuration", "the value of 'theta1' must be a number in SI units"),
    ({"theta1": float("nan")}, "initial", "must be a finite number"),
])
def test_bad_state_names_and_values_name_the_python_field(double, values, field, message):
    with pytest.raises(ModelError) as info:
        resolve_state(double, values, field=field)
    assert info.value.field == field and message in info.value.message


def test_a_state_limited_to_coordinates_refuses_velocities(double):
    with pytest.raises(ModelError, match="'theta1_dot' is not a coordinate of this model"):
        resolve_state(double, {"theta1_dot": 0.0}, field="about", velocities=False, time=False)


def test_state_units_are_the_declared_ones_per_second_for_velocities():
    model = lagrangian.load("cart_pendulum").model
    units = state_units(model)
    assert units["t"] == "s"
    for c in model.coordinates:
        assert units[c.name] == c.unit and units[c.velocity.name] == f"({c.unit})/s"


def test_parameters_resolve_against_the_model_values(double):
    defaults = {p.name: p.value for p in double.parameters}
    values = resolve_parameters(double, {"g": 1.62})  # on the Moon
    assert isinstance(values, ParameterValues)
    assert values["g"] == 1.62
    assert values.as_dict() == {**defaults, "g": 1.62}
    substitution = values.symbol_values(double)
    assert substitution[double.parameter("g").symbol] == sp.Float(1.62)
    assert resolve_parameters(double, values) == values


def test_bad_parameters_name_the_python_field(double):
    with pytest.raises(ModelError) as info:
        resolve_parameters(double, {"m11": 1.0})
    assert info.value.field == "parameters"
    assert "'m11' is not a parameter of this model; did you mean 'm1'?" in info.value.message
    builder = lagrangian.SystemBuilder("symbolic")
    x = builder.coordinate("x")
    k = builder.parameter("k")  # no value
    builder.add_potential_energy(k * x**2 / 2)
    model = builder.build().model
    with pytest.raises(ModelError, match="parameter 'k' has no value") as info:
        resolve_parameters(model)
    assert info.value.field == "parameters.k"
    assert resolve_parameters(model, require=False).as_dict() == {}
    assert resolve_parameters(model, {"k": 2.0})["k"] == 2.0


def test_one_resolution_serves_the_facade_and_the_analyses(double):
    """with_parameters, forces, simulation and linearization refuse the same unknown name."""
    system = lagrangian.System(double)
    with pytest.raises(ModelError, match="'G' is not a parameter") as info:
        system.with_parameters(G=1.0)
    assert info.value.field == "parameters"
    with pytest.raises(ModelError) as info:
        system.generalized_forces_at({"phi": 0.0})
    assert info.value.field == "configuration"
    with pytest.raises(ModelError) as info:
        system.simulate(0.1, initial={"phi": 0.0})
    assert info.value.field == "initial"
    with pytest.raises(ModelError) as info:
        system.linearize(about={"phi": 0.0})
    assert info.value.field == "about"
    assert State(("a",), (1.0,), (0.0,)).names == ("a", "a_dot")
