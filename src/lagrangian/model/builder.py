"""Build a :class:`Model` step by step from Python (sympy expressions, numbers or strings).

Strings are parsed with the model-file grammar; sympy expressions may use the symbols this
builder returns, or ``dynamicsymbols`` of the same names (``q(t)`` and ``q(t).diff(t)``).
"""

from __future__ import annotations

import keyword
import math
from collections.abc import Iterable, Sequence
from dataclasses import replace

import sympy as sp

from ..errors import ModelError, did_you_mean
from .builder_bodies import RigidBodiesMixin
from .builder_constraints import ConstraintsMixin
from .builder_control import ControlLawsMixin
from .builder_loads import LoadsMixin
from .builder_steady import SteadyMotionMixin
from .contacts import (
    RollingContact,
)
from .expressions import IDENTIFIER, MAX_TREE_NODES, RESERVED, parse_expression, tree_size
from .impacts import ImpactsMixin
from .model import (
    TIME,
    Attachment,
    Body,
    Constraint,
    Coordinate,
    Damper,
    Gravity,
    Model,
    Parameter,
    Particle,
    PointForce,
    Spring,
    SteadyMotion,
    Torque,
    acceleration_name,
    multiplier_name,
    velocity_name,
)
from .rotations import RigidBody, floated, unit_vector
from .vector import Vector


class ModelBuilder(LoadsMixin, RigidBodiesMixin, ConstraintsMixin, SteadyMotionMixin,
                   ControlLawsMixin, ImpactsMixin):
    """Mutable shell that validates each piece as it is added and builds an immutable Model."""

    def __init__(self, name: str = "", description: str = "", *, source: str | None = None):
        self.name = name
        self.description = description
        self.source = source
        self._coordinates: list[Coordinate] = []
        self._parameters: list[Parameter] = []
        self._definitions: list[tuple[str, sp.Expr]] = []
        self._names: dict[str, sp.Expr] = {"t": TIME}
        self._kinetic: list[sp.Expr] = []
        self._potential: list[sp.Expr] = []
        self._dissipation: list[sp.Expr] = []
        self._gravity: Gravity | None = None
        self._particles: list[Particle] = []
        self._bodies: list[Body] = []
        self._rigid_bodies: list[RigidBody] = []
        self._frames: dict = {}  # 3D body name -> its rotations.Frame, for joints on it
        self._rotations: dict[str, int] = {}  # 3D body name -> elementary rotations from ground
        self._springs: list[Spring] = []
        self._dampers: list[Damper] = []
        self._loads: list[PointForce | Torque] = []
        self._generalized: dict[str, list[sp.Expr]] = {}
        self._constraints: list[Constraint] = []
        self._contacts: list[RollingContact] = []
        self._steady_motion: SteadyMotion | None = None
        self._control: dict[str, tuple[sp.Expr, str]] = {}  # input -> (law, its field)
        self._component_names: set[str] = set()
        # Every vector given, in order: (field, components, what it places: "particle", "body"
        # or None). The first particle or body position fixes the model's dimension; every
        # vector must match it.
        self._vectors: list[tuple[str, int, str | None]] = []
        self._gravity_field: str | None = None

    # -- declarations ---------------------------------------------------------------------

    def coordinate(
        self,
        name: str,
        unit: str = "m",
        *,
        initial: float | None = None,
        rate: float | None = None,
        range: tuple[float, float] | None = None,
        field: str | None = None,
    ) -> sp.Symbol:
        """Declare a generalized coordinate; returns its symbol (its velocity is ``name_dot``)."""
        field = field or f"coordinates.{name}"
        self._declare(name, field)
        for derived in (velocity_name(name), acceleration_name(name)):
            self._declare(derived, field)
        symbol, velocity = sp.Symbol(name), sp.Symbol(velocity_name(name))
        coordinate = Coordinate(
            name, symbol, velocity, sp.Symbol(acceleration_name(name)), unit,
            _optional_float(initial, f"{field}.initial", self.source),
            _optional_float(rate, f"{field}.rate", self.source),
            _range(range, f"{field}.range", self.source),
        )
        self._coordinates.append(coordinate)
        self._names[name] = symbol
        self._names[velocity_name(name)] = velocity
        return symbol

    def parameter(
        self, name: str, value: float | None = None, unit: str | None = None, *,
        field: str | None = None, range: Sequence[float] | None = None,  # noqa: A002
        integer: bool = False,
    ) -> sp.Symbol:
        """Declare a named constant (SI value, or None to keep it symbolic), the values it may
        take (``range`` [lower, upper] inclusive, SI; ``integer``: a count); returns its
        symbol."""
        field = field or f"parameters.{name}"
        self._declare(name, field)
        symbol = sp.Symbol(name)
        if not isinstance(integer, bool):
            raise ModelError("integer is true or false", field=f"{field}.integer",
                             source=self.source)
        parameter = Parameter(name, symbol, _optional_float(value, field, self.source), unit,
                              _closed_range(range, f"{field}.range", self.source), integer)
        if parameter.value is not None:
            try:
                parameter.checked(parameter.value, field)
            except ModelError as error:  # the file's own value: named with its source
                raise ModelError(error.message, field=field, source=self.source) from None
        self._parameters.append(parameter)
        self._names[name] = symbol
        return symbol

    def define(self, name: str, expression: object, *, field: str | None = None) -> sp.Expr:
        """A named sub-expression, usable in everything added after it; returns its value."""
        field = field or f"definitions.{name}"
        value = self.expression(expression, field)
        self._declare(name, field)
        self._definitions.append((name, value))
        self._names[name] = value
        return value

    def velocity(self, coordinate: sp.Symbol | str) -> sp.Symbol:
        """The velocity symbol q_dot of a declared coordinate."""
        return self._coordinate(str(coordinate), "velocity").velocity

    # -- energies -------------------------------------------------------------------------

    def add_kinetic_energy(self, T: object, *, field: str = "energy.T") -> ModelBuilder:
        """Add a kinetic-energy term T(q, q_dot, t) in J."""
        self._kinetic.append(self.expression(T, field))
        return self

    def add_potential_energy(self, V: object, *, field: str = "energy.V") -> ModelBuilder:
        """Add a potential-energy term V(q, t) in J (may depend on velocities: generalized potential)."""
        self._potential.append(self.expression(V, field))
        return self

    def add_dissipation(self, D: object, *, field: str = "energy.D") -> ModelBuilder:
        """Add a Rayleigh dissipation term D(q, q_dot, t) in W; Q_i = -dD/dq_dot_i."""
        self._dissipation.append(self.expression(D, field))
        return self

    # -- components -----------------------------------------------------------------------

    def set_gravity(
        self, g: object, direction: Sequence[object] | None = None, *, field: str = "gravity"
    ) -> ModelBuilder:
        """Uniform gravity of magnitude g (m/s^2) along ``direction`` (normalized here; default
        (0, -1) in a planar model). Both may be expressions in parameters (an incline angle)."""
        magnitude = self._parameter_expression(g, f"{field}.g")
        self._gravity_field = field
        if direction is None:
            self._gravity = Gravity(magnitude, (sp.S.Zero, -sp.S.One, sp.S.Zero))
            return self
        vector = self.vector(direction, f"{field}.direction")
        for i, component in enumerate(vector):
            self._parameter_expression(component, f"{field}.direction[{i}]")
        if not any(c.free_symbols for c in vector):
            unit = unit_vector(vector)
            if unit is None:
                raise self._error("the direction is the zero vector", f"{field}.direction")
            self._gravity = Gravity(magnitude, unit)
            return self
        vector = tuple(floated(c) for c in vector)
        squared = sp.Add(*(c**2 for c in vector))
        if squared.free_symbols:
            # sin(a)^2 + cos(a)^2 and the like: small, parameters only, so trigsimp is cheap.
            squared = sp.trigsimp(squared)
        if squared == 0 or self._zero_at_values(squared):
            raise self._error("the direction is the zero vector", f"{field}.direction")
        norm = sp.sqrt(squared)
        self._gravity = Gravity(magnitude, tuple(c / norm for c in vector))
        return self

    def add_particle(
        self, name: str, mass: object, position: Sequence[object], *, field: str | None = None
    ) -> ModelBuilder:
        """A point mass (kg) at position r(q, t) (m)."""
        field = field or f"particle '{name}'"
        self._component(name, field)
        self._particles.append(
            Particle(
                name,
                self.expression(mass, f"{field}.mass", velocities=False),
                self.vector(position, f"{field}.position", velocities=False,
                            places="particle"),
            )
        )
        return self

    def add_body(
        self, name: str, mass: object, inertia: object, position: Sequence[object], angle: object,
        *, field: str | None = None,
    ) -> ModelBuilder:
        """A planar rigid body: mass (kg), inertia about its centre of mass (kg m^2), centre, angle."""
        field = field or f"body '{name}'"
        self._component(name, field)
        self._bodies.append(
            Body(
                name,
                self.expression(mass, f"{field}.mass", velocities=False),
                self.expression(inertia, f"{field}.inertia", velocities=False),
                self.vector(position, f"{field}.position", velocities=False, places="body"),
                self.expression(angle, f"{field}.angle", velocities=False),
            )
        )
        return self

    def point(self, reference: object, *, field: str = "point") -> Vector:
        """Resolve a point: a particle or body name (its centre), a vector, or (body, offset)."""
        if isinstance(reference, str):
            for particle in self._particles:
                if particle.name == reference:
                    return particle.position
            for body in (*self._bodies, *self._rigid_bodies):
                if body.name == reference:
                    return body.position
            names = [p.name for p in self._particles] + [b.name for b in self._bodies] + \
                [b.name for b in self._rigid_bodies]
            raise self._error(f"'{reference}' is not a particle or body (declare it before use)"
                              f"{did_you_mean(reference, names)}", field)
        if isinstance(reference, dict):
            unknown = set(reference) - {"body", "offset"}
            if unknown or "body" not in reference:
                raise self._error(
                    "a body point is a table {body = \"name\", offset = [x, y]}"
                    + (f"; unknown key '{sorted(unknown)[0]}'" if unknown else ""),
                    field,
                )
            return self.body_point(reference["body"], reference.get("offset"), field=field)
        return self.vector(reference, field, velocities=False)

    def _nonpositive_at_values(self, expr: sp.Expr) -> bool:
        values = {p.symbol: p.value for p in self._parameters if p.value is not None}
        if not expr.free_symbols or not expr.free_symbols <= set(values):
            return False
        try:
            return float(expr.xreplace(values)) <= 0
        except (TypeError, ValueError):
            return False

    # -- expressions ----------------------------------------------------------------------

    def expression(self, value: object, field: str, *, velocities: bool = True) -> sp.Expr:
        """Turn a string, number or sympy expression into a validated sympy expression."""
        if isinstance(value, sp.Basic):
            expr = self._adopt(value, field)
        else:
            expr = parse_expression(value, self._names, field=field, source=self.source)
        if not isinstance(expr, sp.Expr):
            raise self._error("expected a scalar expression", field)
        size = tree_size(expr, limit=MAX_TREE_NODES)
        if size > MAX_TREE_NODES:
            raise self._error(f"written out in full this expression has more than "
                              f"{MAX_TREE_NODES:,} terms and functions (definitions that use "
                              "one another several times grow exponentially); keep it smaller",
                              field)
        if not velocities:
            used = expr.free_symbols & {c.velocity for c in self._coordinates}
            if used:
                raise self._error(
                    f"may not depend on velocities (found {sorted(map(str, used))[0]})", field
                )
        return expr

    def vector(
        self, values: Sequence[object], field: str, *, velocities: bool = True,
        places: str | None = None,
    ) -> Vector:
        """A 2- or 3-component vector of expressions (a planar one gets z = 0); its number of
        components must be the model's (``places``: "particle" or "body" it positions)."""
        if isinstance(values, str | bytes) or not isinstance(values, Sequence | sp.MatrixBase):
            raise self._error("expected a vector: a list of 2 or 3 components", field)
        items = list(values)
        if len(items) not in (2, 3):
            raise self._error(f"expected 2 or 3 components, got {len(items)}", field)
        self._vectors.append((field, len(items), places))
        self._check_dimensions()
        parsed = [
            self.expression(v, f"{field}[{i}]", velocities=velocities) for i, v in enumerate(items)
        ]
        if len(parsed) == 2:
            parsed.append(sp.S.Zero)
        return tuple(parsed)

    def _adopt(self, value: sp.Basic, field: str) -> sp.Expr:
        replacements: dict[sp.Basic, sp.Basic] = {}
        for derivative in value.atoms(sp.Derivative):
            base = derivative.expr
            if (
                isinstance(base, sp.core.function.AppliedUndef)
                and str(base.func) in self._names
                and derivative.variables == (TIME,)
            ):
                replacements[derivative] = self.velocity(str(base.func))
            else:
                raise self._error(f"unsupported derivative {derivative}", field)
        value = value.xreplace(replacements)
        for applied in value.atoms(sp.core.function.AppliedUndef):
            name = str(applied.func)
            if name in self._names and applied.args == (TIME,):
                replacements[applied] = self._names[name]
            else:
                raise self._error(f"unknown function {applied}", field)
        value = value.xreplace(replacements)
        declared = set(self._names.values())
        for symbol in value.free_symbols:
            if symbol not in declared:
                raise self._error(
                    f"unknown symbol '{symbol}': declare it with coordinate() or parameter()",
                    field,
                )
        return value

    # -- build ----------------------------------------------------------------------------

    def build_model(self) -> Model:
        """Validate the whole and return the immutable Model."""
        if not self._coordinates:
            raise self._error("a model needs at least one generalized coordinate", "coordinates")
        self._check_dimensions()
        model = Model(
            name=self.name or "Unnamed model",
            description=self.description,
            coordinates=tuple(self._coordinates),
            parameters=tuple(self._parameters),
            definitions=tuple(self._definitions),
            kinetic_energy=sp.Add(*self._kinetic),
            potential_energy=sp.Add(*self._potential),
            dissipation=sp.Add(*self._dissipation),
            gravity=self._gravity,
            particles=tuple(self._particles),
            bodies=tuple(self._bodies),
            rigid_bodies=tuple(self._rigid_bodies),
            springs=tuple(self._springs),
            dampers=tuple(self._dampers),
            loads=tuple(self._loads),
            generalized_forces=tuple((k, sp.Add(*v)) for k, v in self._generalized.items()),
            constraints=tuple(self._constraints),
            source=self.source,
            contacts=tuple(self._contacts),
            steady_motion=self._steady_motion,
            impacts=self._impact_list(),
        )
        return replace(model, control=self._control_laws(model)) if self._control else model

    # -- helpers --------------------------------------------------------------------------

    def dimension(self) -> int | None:
        """2 (planar) or 3: the components of the first particle or body position (of the first
        vector where there are none); None before any vector."""
        placing = [n for _, n, places in self._vectors if places]
        if placing:
            return placing[0]
        return self._vectors[0][1] if self._vectors else None

    def _check_dimensions(self) -> None:
        dimension = self.dimension()
        if dimension is None:
            return
        what = "a planar" if dimension == 2 else "a 3D"
        for field, n, places in self._vectors:
            if n != dimension:
                raise self._error(f"{n} components in {what} model", field)
            if places == "body" and n == 3:
                raise self._error("3 components: a body is planar (it turns about z); "
                                  "give its position as [x, y]", field)
        if dimension == 3 and self._gravity is not None and self._gravity_field is not None \
                and not any(f == f"{self._gravity_field}.direction" for f, _, _ in self._vectors):
            raise self._error("give the direction of gravity in a 3D model (3 components)",
                              f"{self._gravity_field}.direction")

    def _parameter_expression(self, value: object, field: str) -> sp.Expr:
        """An expression in parameters only (not coordinates, velocities or time)."""
        expr = self.expression(value, field)
        state = {c.symbol for c in self._coordinates} | {c.velocity for c in self._coordinates}
        used = expr.free_symbols & (state | {TIME})
        if used:
            raise self._error(
                f"may depend on parameters only (found {sorted(map(str, used))[0]})", field)
        return expr

    def _zero_at_values(self, expr: sp.Expr) -> bool:
        """True where every symbol of ``expr`` is a parameter with a value that makes it 0."""
        values = {p.symbol: p.value for p in self._parameters if p.value is not None}
        if not expr.free_symbols <= set(values):
            return False
        try:
            return abs(complex(expr.xreplace(values))) < 1e-300
        except (TypeError, ValueError):
            return False

    def _error(self, message: str, field: str | None) -> ModelError:
        return ModelError(message, field=field, source=self.source)

    def _declare(self, name: str, field: str) -> None:
        if not isinstance(name, str) or not IDENTIFIER.match(name) or keyword.iskeyword(name):
            raise self._error(f"{name!r} is not a valid name (letters, digits, '_')", field)
        if name in RESERVED:
            raise self._error(f"'{name}' is reserved (a function, constant or time)", field)
        if name in self._names:
            raise self._error(f"'{name}' is declared twice", field)
        if name.startswith("lambda_"):
            raise self._error(f"'{name}': names starting 'lambda_' are reserved for multipliers",
                              field)

    def _component(self, name: str, field: str) -> None:
        if not isinstance(name, str) or not name:
            raise self._error("every component needs a non-empty name", f"{field}.name")
        if name in self._component_names:
            raise self._error(f"the name '{name}' is used twice", f"{field}.name")
        self._component_names.add(name)

    def _coordinate(self, name: str, field: str) -> Coordinate:
        for c in self._coordinates:
            if c.name == name:
                return c
        raise self._error(f"'{name}' is not a declared coordinate", field)

    def _all_state_symbols(self) -> Iterable[sp.Symbol]:
        for c in self._coordinates:
            yield c.symbol
            yield c.velocity

    def _extent(self, value, between, what: str, field: str):
        """(length expression, end attachments or None) of a spring or damper."""
        if (value is None) == (between is None):
            raise self._error(f"give exactly one of '{what}' or 'between'", field)
        if value is not None:
            return self.expression(value, f"{field}.{what}", velocities=False), None
        if isinstance(between, str) or not isinstance(between, Sequence) or len(between) != 2:
            raise self._error("'between' takes exactly two points", f"{field}.between")
        ends = tuple(
            Attachment(self.point(reference, field=f"{field}.between[{k}]"),
                       self._attached_body(reference))
            for k, reference in enumerate(between)
        )
        a, b = ends[0].point, ends[1].point
        return sp.sqrt(sum((ai - bi) ** 2 for ai, bi in zip(a, b, strict=True))), ends

    def _attached_body(self, reference: object) -> str | None:
        """The particle or body a point reference is fixed to (None for a plain vector)."""
        if isinstance(reference, str):
            return reference
        if isinstance(reference, dict):
            return reference.get("body")
        return None

    def _time_derivative(self, expr: sp.Expr) -> sp.Expr:
        return sum(
            (expr.diff(c.symbol) * c.velocity for c in self._coordinates), expr.diff(TIME)
        )

    def _require_coordinate_dependence(self, values, name, field, what) -> None:
        coordinates = {c.symbol for c in self._coordinates}
        if not any(v.free_symbols & coordinates for v in values):
            raise self._error(
                f"the {what} of load '{name}' does not depend on any coordinate, so the load "
                "does no virtual work; attach it to a moving point", field,
            )


def _optional_float(value: object, field: str, source: str | None) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float | sp.Number):
        raise ModelError(f"expected a number, got {value!r}", field=field, source=source)
    try:
        number = float(value)
    except OverflowError:  # an integer beyond 1.8e308
        raise ModelError("the number is too large for a floating-point number", field=field,
                         source=source) from None
    if not math.isfinite(number):
        raise ModelError(f"the number {value!r} is not finite", field=field, source=source)
    return number


def _range(value, field: str, source: str | None) -> tuple[float, float] | None:
    if value is None:
        return None
    if not isinstance(value, Sequence) or len(value) != 2:
        raise ModelError("expected [lower, upper]", field=field, source=source)
    lower, upper = (_optional_float(v, field, source) for v in value)
    if not lower < upper:
        raise ModelError("lower must be below upper", field=field, source=source)
    return (lower, upper)


def _closed_range(value, field: str, source: str | None) -> tuple[float, float] | None:
    """[lower, upper] with lower <= upper (either may be -inf or inf), or None."""
    if value is None:
        return None
    if not isinstance(value, Sequence) or isinstance(value, str) or len(value) != 2:
        raise ModelError("expected [lower, upper]", field=field, source=source)
    bounds = []
    for v in value:
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise ModelError(f"a bound is a number, not {v!r}", field=field, source=source)
        if math.isnan(v):
            raise ModelError("a bound is a number, not nan", field=field, source=source)
        bounds.append(float(v))
    if not bounds[0] <= bounds[1]:
        raise ModelError("lower must not be above upper", field=field, source=source)
    return (bounds[0], bounds[1])


__all__ = ["ModelBuilder", "multiplier_name"]
