"""ModelBuilder's steady motion: the motion a model (a bicycle, a rolling coin) is studied about
by default, its speed parameter, steady rates, kept equations and configuration (a mixin of
builder.ModelBuilder, sharing its declarations)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Self

from ..errors import did_you_mean
from .model import SteadyMotion


class SteadyMotionMixin:
    """set_steady_motion, mixed into ModelBuilder (its _parameters, _coordinates, expression
    and _error)."""

    def set_steady_motion(self, speed: str, rates: Mapping[str, object], keep: Sequence[str],
                          about: Mapping[str, object] | None = None,
                          field: str = "steady") -> Self:
        """The steady motion the model is studied about by default: ``speed`` a parameter (m/s),
        ``rates`` NAME_dot -> a number or expression in the parameters, ``keep`` the coordinates
        whose equations are kept, ``about`` coordinate values (the rest solved for)."""
        parameters = [p.name for p in self._parameters]
        if not isinstance(speed, str) or speed not in parameters:
            raise self._error(f"{speed!r} is not a parameter{did_you_mean(str(speed), parameters)}",
                              f"{field}.speed")
        velocities = {c.velocity.name: c for c in self._coordinates}
        names = [c.name for c in self._coordinates]
        if not isinstance(rates, Mapping) or not rates:
            raise self._error("expected a table of steady rates, NAME_dot = expression",
                              f"{field}.rates")
        texts = []
        for name, value in rates.items():
            where = f"{field}.rates.{name}"
            if name not in velocities:
                raise self._error(f"'{name}' is not a velocity of this model"
                                  f"{did_you_mean(name, list(velocities))}", where)
            expr = self.expression(value, where, velocities=False)
            stray = expr.free_symbols - {p.symbol for p in self._parameters}
            if stray:
                raise self._error(f"a steady rate is written in the parameters only (found "
                                  f"{sorted(map(str, stray))[0]})", where)
            texts.append((name, str(value) if isinstance(value, str) else str(float(value))))
        if isinstance(keep, str) or not isinstance(keep, Sequence) or not keep:
            raise self._error("expected a list of coordinate names", f"{field}.keep")
        for name in keep:
            if name not in names:
                raise self._error(f"{name!r} is not a coordinate{did_you_mean(str(name), names)}",
                                  f"{field}.keep")
        point = []
        for name, value in (about or {}).items():
            if name not in names:
                raise self._error(f"'{name}' is not a coordinate{did_you_mean(name, names)}",
                                  f"{field}.about.{name}")
            value = self.expression(value, f"{field}.about.{name}")
            if value.free_symbols or not value.is_real:
                raise self._error(f"the value of '{name}' must be a number (SI), got "
                                  f"'{value}'", f"{field}.about.{name}")
            point.append((name, float(value)))
        self._steady_motion = SteadyMotion(speed, tuple(texts), tuple(keep), tuple(point))
        return self
