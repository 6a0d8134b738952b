"""Numbers for a model: a State (t, q, q_dot) and ParameterValues, resolved against its defaults.

The one place where values given by name (a mapping, SI units) meet the model's defaults:
coordinates take their ``initial`` value, velocities their ``rate``, t 0, and parameters their
``value``. Errors name the Python field the values came from (``initial``, ``about``,
``configuration``, ``parameters``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..errors import ModelError
from .checked import si_number, unknown_name
from .model import Model, velocity_name


@dataclass(frozen=True)
class State:
    """Time t (s), coordinates q and velocities q_dot (SI), in the model's coordinate order.

    ``given`` names the entries that were given explicitly (the rest are the model's defaults).
    """

    coordinates: tuple[str, ...]
    q: tuple[float, ...]
    q_dot: tuple[float, ...]
    t: float = 0.0
    given: frozenset[str] = frozenset()

    @property
    def velocities(self) -> tuple[str, ...]:
        return tuple(velocity_name(c) for c in self.coordinates)

    @property
    def names(self) -> tuple[str, ...]:
        """Coordinates then velocities: the order of y = [q, q_dot]."""
        return (*self.coordinates, *self.velocities)

    def q_array(self) -> np.ndarray:
        return np.array(self.q, dtype=float)

    def q_dot_array(self) -> np.ndarray:
        return np.array(self.q_dot, dtype=float)

    def as_dict(self) -> dict[str, float]:
        """Name -> value: every coordinate, every velocity and t."""
        return {**dict(zip(self.coordinates, self.q, strict=True)),
                **dict(zip(self.velocities, self.q_dot, strict=True)), "t": self.t}

    def given_values(self) -> dict[str, float]:
        """Only the entries given explicitly, name -> value."""
        return {k: v for k, v in self.as_dict().items() if k in self.given}

    def symbol_values(self, model: Model) -> dict[sp.Symbol, float]:
        """Symbol -> value for q, q_dot and t of ``model``."""
        values = {model.time: self.t}
        for c, q, v in zip(model.coordinates, self.q, self.q_dot, strict=True):
            values[c.symbol] = q
            values[c.velocity] = v
        return values


@dataclass(frozen=True)
class ParameterValues:
    """Parameter name -> SI value, in the model's order; None for a symbolic-only parameter."""

    names: tuple[str, ...]
    values: tuple[float | None, ...]

    def __getitem__(self, name: str) -> float | None:
        return self.values[self.names.index(name)]

    def as_dict(self) -> dict[str, float]:
        """Name -> value of every parameter that has one."""
        return {n: v for n, v in zip(self.names, self.values, strict=True) if v is not None}

    def symbol_values(self, model: Model) -> dict[sp.Symbol, sp.Float]:
        """Symbol -> value (a sympy Float) of every parameter that has one, for substitution."""
        given = self.as_dict()
        return {p.symbol: sp.Float(given[p.name]) for p in model.parameters if p.name in given}


# -- resolution -------------------------------------------------------------------------------

def resolve_state(
    model: Model,
    values: Mapping[str, object] | State | None = None,
    *,
    field: str = "initial",
    velocities: bool = True,
    time: bool = True,
    what: str | None = None,
) -> State:
    """The state given by ``values`` (name -> SI number) over the model's defaults: initial
    values for q, rates for q_dot, 0 for t (and 0 where the model gives none).

    ``velocities``/``time`` say whether velocity names and t may be given; ``what`` words the
    accepted names in the error (default: from those flags).
    """
    coordinates = tuple(c.name for c in model.coordinates)
    if isinstance(values, State):
        if values.coordinates != coordinates:
            raise ModelError(f"the state's coordinates {list(values.coordinates)} are not the "
                             f"model's {list(coordinates)}", field=field)
        return values
    values = dict(values or {})
    known = list(coordinates)
    if velocities:
        known += [c.velocity.name for c in model.coordinates]
    if time:
        known.append("t")
    if what is None:
        what = "coordinate" + (", velocity" if velocities else "") + (" or t" if time else "")
        if velocities and not time:
            what = "coordinate or velocity"
    for name in values:
        if name not in known:
            raise unknown_name(name, known, what, field)
    numbers = {name: si_number(name, value, field) for name, value in values.items()}
    q = tuple(numbers.get(c.name, _default(c.initial)) for c in model.coordinates)
    q_dot = tuple(numbers.get(c.velocity.name, _default(c.rate)) for c in model.coordinates)
    return State(coordinates, q, q_dot, numbers.get("t", 0.0), frozenset(numbers))


def resolve_parameters(
    model: Model,
    overrides: Mapping[str, object] | ParameterValues | None = None,
    *,
    field: str = "parameters",
    require: bool = True,
) -> ParameterValues:
    """The model's parameter values overridden by ``overrides`` (name -> SI number).

    With ``require`` every parameter must end up with a value.
    """
    names = tuple(p.name for p in model.parameters)
    if isinstance(overrides, ParameterValues):
        if overrides.names != names:
            raise ModelError(f"the parameter values are for {list(overrides.names)}, not for "
                             f"this model's {list(names)}", field=field)
        overrides = overrides.as_dict()
    overrides = dict(overrides or {})
    for name in overrides:
        if name not in names:
            raise unknown_name(name, list(names), "parameter", field)
    values: list[float | None] = []
    for p in model.parameters:
        if p.name in overrides:
            values.append(p.checked(si_number(p.name, overrides[p.name], field),
                                    f"{field}.{p.name}"))
        elif p.value is None and require:
            raise ModelError(f"parameter '{p.name}' has no value; give one",
                             field=f"{field}.{p.name}")
        else:
            values.append(None if p.value is None else float(p.value))
    return ParameterValues(names, tuple(values))


def state_units(model: Model) -> dict[str, str | None]:
    """The unit of every name a state may be given by: q (declared), q_dot (per second), t (s)."""
    units: dict[str, str | None] = {"t": "s"}
    for c in model.coordinates:
        units[c.name] = c.unit
        units[c.velocity.name] = None if not c.unit else f"({c.unit})/s"
    return units


def _default(value: float | None) -> float:
    return 0.0 if value is None else float(value)
