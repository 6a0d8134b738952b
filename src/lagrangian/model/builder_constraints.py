"""ModelBuilder's constraints: holonomic and velocity constraints and rolling contacts of
knife-edge wheels (a mixin of builder.ModelBuilder, sharing its declarations)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Self

import sympy as sp

from ..errors import did_you_mean
from ..kinds import ConstraintKind
from .contacts import (
    RollingContact,
    contact_velocity,
    dot,
    ground_tangents,
    identically_zero,
    wheel_down_direction,
)
from .expressions import IDENTIFIER
from .model import (
    Constraint,
)
from .rotations import apply, unit_vector
from .vector import Vector

# A rolling contact's velocity coefficients are trigsimp'd only below this op count (cheap).
TIDY_LIMIT = 40



class ConstraintsMixin:
    """add_constraint, add_rolling_contact."""

    def add_constraint(
        self, name: str, *, holonomic: object = None, velocity: object = None,
        field: str | None = None,
    ) -> Self:
        """A constraint Phi(q, t) = 0 (holonomic) or A(q, t) q_dot + b(q, t) = 0 (velocity)."""
        field = field or f"constraint '{name}'"
        if not isinstance(name, str) or not IDENTIFIER.match(name):
            raise self._error(f"constraint name {name!r} must be an identifier", f"{field}.name")
        self._component(name, field)
        if (holonomic is None) == (velocity is None):
            raise self._error("give exactly one of 'holonomic' or 'velocity'", field)
        if holonomic is not None:
            expression = self.expression(holonomic, f"{field}.holonomic", velocities=False)
            kind = ConstraintKind.HOLONOMIC
        else:
            expression = self.expression(velocity, f"{field}.velocity")
            velocities = [c.velocity for c in self._coordinates]
            if not expression.free_symbols & set(velocities):
                raise self._error(
                    "a velocity constraint must contain at least one velocity (q_dot); "
                    "write a constraint on positions as 'holonomic'", f"{field}.velocity",
                )
            for v in velocities:
                if expression.diff(v).free_symbols & set(velocities):
                    raise self._error(
                        "a velocity constraint must be linear in the velocities",
                        f"{field}.velocity",
                    )
            kind = ConstraintKind.VELOCITY
        if not expression.free_symbols & set(self._all_state_symbols()):
            raise self._error("the constraint does not involve any coordinate", field)
        self._constraints.append(Constraint(name, kind, expression))
        return self

    def add_rolling_contact(
        self, name: str, body: str, radius: object, axle: object, *,
        normal: Sequence[object] | None = None, field: str | None = None,
    ) -> Self:
        """A knife-edge wheel rolling without slipping on the ground plane r . n = 0.

        ``body``: a 3D body whose origin is the wheel's centre; ``radius`` (m, > 0); ``axle``
        in body axes ("y" or a 3-vector); ``normal``: the ground's unit normal (numbers,
        pointing out of the ground; default against gravity, else +z). Adds the velocity
        constraints ``<name>_friction_<t>`` along the two ground tangents (the friction on the
        wheel along t is -lambda) and, where the contact height r_C . n is not identically
        zero in these coordinates, the holonomic ``<name>_normal`` (normal force -lambda).
        """
        field = field or f"contact '{name}'"
        if not isinstance(name, str) or not IDENTIFIER.match(name):
            raise self._error(f"contact name {name!r} must be an identifier", f"{field}.name")
        self._component(name, field)
        target = next((b for b in self._rigid_bodies if b.name == body), None)
        if target is None:
            planar = any(b.name == body for b in self._bodies)
            hint = (" (a rolling contact needs a body in space: give it 'rotation' or a "
                    "'joint')" if planar else did_you_mean(str(body),
                                                             [b.name for b in self._rigid_bodies]))
            raise self._error(f"'{body}' is not a 3D body (declare it before the contact)"
                              f"{hint}", f"{field}.body")
        r = self._parameter_expression(radius, f"{field}.radius")
        if r.is_number and not r.is_positive or self._nonpositive_at_values(r):
            raise self._error(f"the radius must be positive (it is {r})", f"{field}.radius")
        reader = self._rotation_reader()
        a_body = reader.axis(axle, f"{field}.axle")
        if any(c.free_symbols for c in a_body):
            raise self._error("the axle must be numbers (a direction fixed in the body)",
                              f"{field}.axle")
        n = self._ground_normal(normal, f"{field}.normal")
        frame = self._frames[body]
        omega = frame.world_angular_velocity
        if omega is None:
            omega = target.world_angular_velocity()
        reference = {c.symbol: (c.initial or 0.0) for c in self._coordinates}
        reference |= {p.symbol: p.value for p in self._parameters if p.value is not None}
        a = apply(target.rotation, a_body)
        down = wheel_down_direction(a, n, reference)
        arm = tuple(r * c for c in down)
        centre = target.origin
        contact = tuple(g + c for g, c in zip(centre, arm, strict=True))
        v_centre = tuple(self._time_derivative(c) for c in centre)
        slip = contact_velocity(v_centre, omega, arm)
        tangents, labels = ground_tangents([float(c) for c in n])
        names = []
        for t, label in zip(tangents, labels, strict=True):
            constraint = f"{name}_friction_{label}"
            self._component(constraint, field)
            self._constraints.append(Constraint(constraint, ConstraintKind.VELOCITY,
                                                self._tidy_velocity_row(dot(slip, t))))
            names.append(constraint)
        height = dot(contact, n)
        values = {p.symbol: p.value for p in self._parameters}
        flat = identically_zero(height, [c.symbol for c in self._coordinates], values)
        if not flat:
            constraint = f"{name}_normal"
            self._component(constraint, field)
            self._constraints.append(Constraint(constraint, ConstraintKind.HOLONOMIC, height))
            names.append(constraint)
        self._contacts.append(RollingContact(name, body, r, a_body, n, tangents, contact,
                                             tuple(names), not flat))
        return self

    def _tidy_velocity_row(self, expr: sp.Expr) -> sp.Expr:
        """sum_j A_j(q) q_dot_j with each short A_j trigsimp'd (the sin^2 + cos^2 that omega x
        arm leaves); long ones are kept as they come (no simplify on long expressions)."""
        velocities = [c.velocity for c in self._coordinates]
        rest = expr.xreplace({v: 0 for v in velocities})
        terms = [rest] if rest != 0 else []
        for v in velocities:
            coefficient = expr.diff(v)  # expr is linear in the velocities
            if coefficient == 0:
                continue
            if sp.count_ops(coefficient) <= TIDY_LIMIT:
                coefficient = sp.trigsimp(sp.expand(coefficient))
            terms.append(coefficient * v)
        return sp.Add(*terms)

    def _ground_normal(self, normal, field: str) -> Vector:
        if normal is None:
            if self._gravity is not None:
                direction = self._gravity.direction
                if not all(c.is_number for c in direction):
                    raise self._error("gravity's direction depends on parameters: give the "
                                      "ground's 'normal' as numbers", field)
                return tuple(sp.nsimplify(-c) if c.is_Rational else -c for c in direction)
            return (sp.S.Zero, sp.S.Zero, sp.S.One)
        vector = self.vector(normal, field)
        if any(c.free_symbols for c in vector):
            raise self._error("the ground normal must be numbers", field)
        unit = unit_vector(vector)
        if unit is None:
            raise self._error("the ground normal is the zero vector or not finite", field)
        return unit
