"""Impacts ([[impacts]] in a model file): where a point strikes a surface, and how it bounces.

An impact happens when its guard g(q, t) falls through 0. The striking point r(q) (m, world
axes) meets a surface of unit normal n: its normal velocity is reversed and scaled by the
restitution e (v_n+ = -e v_n-); with "stick" its tangential velocity stops, with "slip" it is
kept (frictionless). ``release = "pivot"``: the model is pinned at the world origin (a walker's
stance foot) and that pin lets go at the impact, the striking point becoming the new pivot;
``relabel`` gives the coordinates after the impact in those before (a walker swaps its legs).
The impact map itself is derived (derivation/impact_map.py), never written by the user.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Self

import sympy as sp

from ..errors import did_you_mean
from .expressions import IDENTIFIER
from .rotations import floated, unit_vector
from .vector import Vector

TANGENTIAL_LAWS = ("slip", "stick")
RELEASES = ("pivot",)


@dataclass(frozen=True)
class Impact:
    """An impact: guard g(q, t) (impact when it falls through 0), striking point r(q) (m),
    surface unit normal n, restitution e (parameters only), tangential law "stick" or "slip",
    the contacts released ("pivot") and the coordinates after it (name, expression in q)."""

    name: str
    guard: sp.Expr
    point: Vector
    normal: Vector
    restitution: sp.Expr
    tangential: str = "slip"
    release: tuple[str, ...] = ()
    relabel: tuple[tuple[str, sp.Expr], ...] = ()


class ImpactsMixin:
    """add_impact, mixed into ModelBuilder (its coordinates, parameters, expression, point and
    _error)."""

    def add_impact(
        self, name: str, guard: object, point: object, normal: Sequence[object], *,
        restitution: object = 0, tangential: str = "slip",
        release: str | Sequence[str] | None = None, relabel: Mapping[str, object] | None = None,
        field: str | None = None,
    ) -> Self:
        """An impact when ``guard`` g(q, t) falls through 0: the striking ``point`` (a vector,
        a particle or body name, or {body, offset}) on a surface of ``normal`` n (pointing out
        of it), restitution e in [0, 1], tangential law "stick" or "slip"; ``release="pivot"``
        lets the model's pin at the origin go, ``relabel`` {q: expression} the new coordinates."""
        field = field or f"impact '{name}'"
        if not isinstance(name, str) or not IDENTIFIER.match(name):
            raise self._error(f"impact name {name!r} must be an identifier", f"{field}.name")
        self._component(name, field)
        g = self.expression(guard, f"{field}.guard", velocities=False)
        coordinates = {c.symbol for c in self._coordinates}
        if not g.free_symbols & coordinates:
            raise self._error("the guard does not depend on any coordinate, so it never "
                              "crosses 0 as the model moves", f"{field}.guard")
        where = self.point(point, field=f"{field}.point")
        if not any(c.free_symbols & coordinates for c in where):
            raise self._error("the striking point does not depend on any coordinate",
                              f"{field}.point")
        n = self._impact_normal(normal, f"{field}.normal")
        e = self._parameter_expression(restitution, f"{field}.restitution")
        if isinstance(e, sp.Symbol):  # a parameter: every value it is given held to [0, 1]
            self._restitution_parameter(e, f"{field}.restitution")
        if not e.free_symbols:
            value = float(e)
            if not 0 <= value <= 1:
                raise self._error(f"the restitution must be in [0, 1], got {value:g}",
                                  f"{field}.restitution")
        if tangential not in TANGENTIAL_LAWS:
            raise self._error(f"the tangential law is \"stick\" or \"slip\", got {tangential!r}"
                              f"{did_you_mean(str(tangential), TANGENTIAL_LAWS)}",
                              f"{field}.tangential")
        released = self._released(release, f"{field}.release")
        if released and tangential != "stick":
            raise self._error("a released pivot needs tangential = \"stick\": the striking "
                              "point becomes the new pivot, at rest", f"{field}.tangential")
        if released and not e.free_symbols and float(e) != 0:
            raise self._error("a released pivot needs restitution = 0: the striking point "
                              "becomes the new pivot, at rest", f"{field}.restitution")
        new = self._relabel(relabel, f"{field}.relabel")
        impact = Impact(name, g, where, n, e, tangential, released, new)
        if not hasattr(self, "_impacts"):
            self._impacts = []
        self._impacts.append(impact)
        return self

    def _restitution_parameter(self, symbol: sp.Symbol, field: str) -> None:
        """The parameter that is an impact's restitution takes values in [0, 1] only (its
        range narrowed to that): its value in the file checked here, naming the impact, and
        every later one (--set, with_parameters) by the parameter's range."""
        from dataclasses import replace

        for k, parameter in enumerate(self._parameters):
            if parameter.symbol != symbol:
                continue
            low, high = parameter.range or (-math.inf, math.inf)
            bounds = (max(low, 0.0), min(high, 1.0))
            if parameter.value is not None and not bounds[0] <= parameter.value <= bounds[1]:
                raise self._error(f"the restitution '{parameter.name}' = {parameter.value:g} "
                                  "must be in [0, 1]", field)
            self._parameters[k] = replace(parameter, range=bounds)

    def _impact_normal(self, normal: object, field: str) -> Vector:
        vector = self.vector(normal, field, velocities=False)
        for i, component in enumerate(vector):
            self._parameter_expression(component, f"{field}[{i}]")
        if not any(c.free_symbols for c in vector):
            unit = unit_vector(vector)
            if unit is None:
                raise self._error("the normal is the zero vector", field)
            return unit
        vector = tuple(floated(c) for c in vector)
        squared = sp.trigsimp(sp.Add(*(c**2 for c in vector)))
        if squared == 0 or self._zero_at_values(squared):
            raise self._error("the normal is the zero vector", field)
        return tuple(c / sp.sqrt(squared) for c in vector)

    def _released(self, release: object, field: str) -> tuple[str, ...]:
        if release is None:
            return ()
        items = [release] if isinstance(release, str) else release
        if not isinstance(items, Sequence) or not all(isinstance(r, str) for r in items):
            raise self._error("expected \"pivot\" (the model's pin at the world origin)", field)
        for item in items:
            if item not in RELEASES:
                raise self._error(f"only the model's pivot at the world origin releases "
                                  f"(release = \"pivot\"), got {item!r}", field)
        return tuple(dict.fromkeys(items))

    def _relabel(self, relabel: object, field: str) -> tuple[tuple[str, sp.Expr], ...]:
        if relabel is None:
            return ()
        if not isinstance(relabel, Mapping):
            raise self._error("expected a table { coordinate = \"its value after, in q\" }",
                              field)
        names = [c.name for c in self._coordinates]
        out = []
        for key, value in relabel.items():
            if key not in names:
                raise self._error(f"'{key}' is not a coordinate{did_you_mean(key, names)}",
                                  f"{field}.{key}")
            expr = self.expression(value, f"{field}.{key}", velocities=False)
            if self._time_in(expr):
                raise self._error("may not depend on time t", f"{field}.{key}")
            out.append((key, expr))
        return tuple(out)

    def _time_in(self, expr: sp.Expr) -> bool:
        return any(s.name == "t" for s in expr.free_symbols)

    def _impact_list(self) -> tuple[Impact, ...]:
        return tuple(getattr(self, "_impacts", ()))


__all__ = ["RELEASES", "TANGENTIAL_LAWS", "Impact", "ImpactsMixin"]
