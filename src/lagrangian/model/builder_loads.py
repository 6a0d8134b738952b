"""ModelBuilder's springs, dampers and loads: V = 1/2 k (l - l0)^2, D = 1/2 c rate^2, a force
at a point and a torque through an angle by virtual work (Q_i = F . dr/dq_i, tau dtheta/dq_i),
and a generalized force given on a coordinate (a mixin of builder.ModelBuilder, sharing its
declarations; SI units)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Self

import sympy as sp

from .model import Damper, PointForce, Spring, Torque


class LoadsMixin:
    """add_spring, add_damper, add_force, add_torque and add_generalized_force, mixed into
    ModelBuilder (its _springs, _dampers, _loads, _generalized, expression, vector, point,
    _extent, _component, _coordinate, _error)."""

    def add_spring(
        self, name: str, stiffness: object, rest_length: object = 0, *, length: object = None,
        between: Sequence[object] | None = None, field: str | None = None,
    ) -> Self:
        """A linear spring, V = 1/2 k (length - rest_length)^2; give ``length`` or ``between``."""
        field = field or f"spring '{name}'"
        self._component(name, field)
        extent, ends = self._extent(length, between, "length", field)
        self._springs.append(
            Spring(
                name,
                self.expression(stiffness, f"{field}.stiffness", velocities=False),
                self.expression(rest_length, f"{field}.rest_length", velocities=False),
                extent,
                ends,
            )
        )
        return self

    def add_damper(
        self, name: str, coefficient: object, *, rate: object = None,
        between: Sequence[object] | None = None, field: str | None = None,
    ) -> Self:
        """A linear viscous damper, D = 1/2 c rate^2; give ``rate`` or ``between`` (two points)."""
        field = field or f"damper '{name}'"
        self._component(name, field)
        if (rate is None) == (between is None):
            raise self._error("give exactly one of 'rate' or 'between'", field)
        ends = None
        if rate is not None:
            value = self.expression(rate, f"{field}.rate")
        else:
            extent, ends = self._extent(None, between, "rate", field)
            # d|a - b|/dt = (a - b).(a_dot - b_dot) / |a - b|: a 1-D chain gets x1_dot - x2_dot
            # instead of the derivative of sqrt((x1 - x2)^2).
            a, b = ends[0].point, ends[1].point
            value = sp.Add(*((ai - bi) * self._time_derivative(ai - bi)
                             for ai, bi in zip(a, b, strict=True) if ai != bi)) / extent
        self._dampers.append(
            Damper(name, self.expression(coefficient, f"{field}.coefficient", velocities=False),
                   value, ends)
        )
        return self

    def add_force(
        self, name: str, point: object, force: Sequence[object], *, field: str | None = None
    ) -> Self:
        """A force (N) at a point; enters by virtual work, Q_i = F . dr/dq_i."""
        field = field or f"load '{name}'"
        self._component(name, field)
        where = self.point(point, field=f"{field}.point")
        self._require_coordinate_dependence(where, name, f"{field}.point", "point")
        self._loads.append(PointForce(name, where, self.vector(force, f"{field}.force")))
        return self

    def add_torque(
        self, name: str, torque: object, angle: object, *, field: str | None = None
    ) -> Self:
        """A torque (N m) turning through angle theta(q); Q_i = tau dtheta/dq_i."""
        field = field or f"load '{name}'"
        self._component(name, field)
        if isinstance(angle, str) and any(b.name == angle for b in self._rigid_bodies):
            raise self._error(f"'{angle}' is a 3D body: put a moment on it "
                              "({name, body, moment = [Mx, My, Mz]})", f"{field}.angle")
        if isinstance(angle, str) and any(b.name == angle for b in self._bodies):
            turned = next(b.angle for b in self._bodies if b.name == angle)
        else:
            turned = self.expression(angle, f"{field}.angle", velocities=False)
        self._require_coordinate_dependence((turned,), name, f"{field}.angle", "angle")
        self._loads.append(Torque(name, self.expression(torque, f"{field}.torque"), turned))
        return self

    def add_generalized_force(
        self, coordinate: sp.Symbol | str, Q: object, *, field: str | None = None
    ) -> Self:
        """A generalized force given directly on one coordinate (N or N m)."""
        name = str(coordinate)
        field = field or f"generalized_forces.{name}"
        self._coordinate(name, field)
        self._generalized.setdefault(name, []).append(self.expression(Q, field))
        return self
