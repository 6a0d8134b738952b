"""What the user describes: an immutable mechanical model in generalized coordinates.

Every expression is a sympy expression in the coordinate symbols ``q``, velocity
symbols ``q_dot``, parameters and time ``t`` (definitions already substituted).
Vectors are 3-tuples; planar models have a zero third component.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import sympy as sp

from ..errors import ModelError
from ..kinds import ConstraintKind
from .checked import si_number, unknown_name
from .vector import Vector

if TYPE_CHECKING:
    from .contacts import RollingContact
    from .impacts import Impact
    from .rotations import RigidBody
    from .tree import KinematicTree

TIME = sp.Symbol("t")


def velocity_name(coordinate: str) -> str:
    return f"{coordinate}_dot"


def acceleration_name(coordinate: str) -> str:
    return f"{coordinate}_ddot"


def multiplier_name(constraint: str) -> str:
    return f"lambda_{constraint}"


@dataclass(frozen=True)
class Coordinate:
    """A generalized coordinate q with its velocity symbol q_dot; unit as declared (SI)."""

    name: str
    symbol: sp.Symbol
    velocity: sp.Symbol
    acceleration: sp.Symbol
    unit: str = "m"
    initial: float | None = None
    rate: float | None = None
    range: tuple[float, float] | None = None

    @property
    def is_angle(self) -> bool:
        return self.unit in ("rad", "radian", "deg", "degree", "rev", "")


@dataclass(frozen=True)
class Parameter:
    """A named constant; ``value`` in SI units, or None for a purely symbolic one; ``range``
    (lower, upper), inclusive, and ``integer`` the values it may take (a count: a wheel's
    spokes), checked wherever a value is given."""

    name: str
    symbol: sp.Symbol
    value: float | None = None
    unit: str | None = None
    range: tuple[float, float] | None = None
    integer: bool = False

    def checked(self, value: float, field: str) -> float:
        """``value`` if the parameter may take it, else a ModelError naming it and its range."""
        if self.integer and value != int(value):
            raise ModelError(f"'{self.name}' is a whole number (a count), not {value:g}",
                             field=field)
        if self.range is not None and not self.range[0] <= value <= self.range[1]:
            lower, upper = self.range
            raise ModelError(f"'{self.name}' = {value:g} is outside its range [{lower:g}, "
                             f"{upper:g}]", field=field)
        return value


@dataclass(frozen=True)
class Particle:
    """A point mass m (kg) at position r(q, t) (m)."""

    name: str
    mass: sp.Expr
    position: Vector


@dataclass(frozen=True)
class Body:
    """A planar rigid body: mass (kg), inertia about its centre of mass (kg m^2), position, angle."""

    name: str
    mass: sp.Expr
    inertia: sp.Expr
    position: Vector
    angle: sp.Expr


@dataclass(frozen=True)
class Attachment:
    """Where a two-point element (spring, damper) ends: the point, and the particle or body it
    is fixed to (None for a point given as a vector: the ground or a prescribed point)."""

    point: Vector
    body: str | None = None


@dataclass(frozen=True)
class Spring:
    """A linear spring: V = 1/2 k (length - rest_length)^2, in J.

    ``ends`` holds its two attachments when it was given ``between`` two points (its length is
    then their distance), None when only its length was given.
    """

    name: str
    stiffness: sp.Expr
    rest_length: sp.Expr
    length: sp.Expr
    ends: tuple[Attachment, Attachment] | None = None


@dataclass(frozen=True)
class Damper:
    """A linear viscous damper: Rayleigh dissipation D = 1/2 c rate^2, in W.

    ``ends`` as for a spring: set when it was given ``between`` two points.
    """

    name: str
    coefficient: sp.Expr
    rate: sp.Expr
    ends: tuple[Attachment, Attachment] | None = None


@dataclass(frozen=True)
class PointForce:
    """A force F (N) applied at point r(q, t): virtual work F . dr."""

    name: str
    point: Vector
    force: Vector


@dataclass(frozen=True)
class Torque:
    """A torque tau (N m) turning through angle theta(q, t): virtual work tau d(theta)."""

    name: str
    torque: sp.Expr
    angle: sp.Expr


Load = PointForce | Torque


@dataclass(frozen=True)
class Gravity:
    """Uniform gravity of magnitude g (m/s^2) along the unit vector ``direction``."""

    magnitude: sp.Expr
    direction: Vector


@dataclass(frozen=True)
class Constraint:
    """Phi(q, t) = 0 (``kind='holonomic'``) or A(q, t) q_dot + b(q, t) = 0 (``kind='velocity'``)."""

    name: str
    kind: ConstraintKind
    expression: sp.Expr

    def __post_init__(self):
        object.__setattr__(self, "kind", ConstraintKind(self.kind))


@dataclass(frozen=True)
class SteadyMotion:
    """The steady motion a model is usually studied about (a bicycle rolling straight ahead):
    the parameter that is its speed (m/s), each steady rate as text in the parameters
    (NAME_dot -> "v", "-v/rR"), the coordinates whose equations are kept, and where it is."""

    speed: str
    rates: tuple[tuple[str, str], ...]
    keep: tuple[str, ...]
    about: tuple[tuple[str, float], ...] = ()


@dataclass(frozen=True)
class Model:
    """A complete mechanical model: coordinates, parameters, energies and components."""

    name: str
    coordinates: tuple[Coordinate, ...]
    parameters: tuple[Parameter, ...] = ()
    definitions: tuple[tuple[str, sp.Expr], ...] = ()
    kinetic_energy: sp.Expr = sp.S.Zero
    potential_energy: sp.Expr = sp.S.Zero
    dissipation: sp.Expr = sp.S.Zero
    gravity: Gravity | None = None
    particles: tuple[Particle, ...] = ()
    bodies: tuple[Body, ...] = ()
    springs: tuple[Spring, ...] = ()
    dampers: tuple[Damper, ...] = ()
    loads: tuple[Load, ...] = ()
    generalized_forces: tuple[tuple[str, sp.Expr], ...] = ()
    constraints: tuple[Constraint, ...] = ()
    description: str = ""
    source: str | None = None
    time: sp.Symbol = field(default=TIME)
    # Bodies in space (model/rotations.py); their moments (rotations.Moment) are in ``loads``.
    rigid_bodies: tuple[RigidBody, ...] = ()
    # Rolling contacts (model/contacts.py); their constraints are in ``constraints``.
    contacts: tuple[RollingContact, ...] = ()
    # The steady motion `speeds` linearizes about when none is given ([steady] in the file).
    steady_motion: SteadyMotion | None = None
    # Control laws ([control] in the file): (input name, u(q, q_dot, t)), an input being a
    # coordinate (its generalized force), a parameter or a load; used only when a run asks
    # for them (simulate's controller="model"), never by derive.
    control: tuple[tuple[str, sp.Expr], ...] = ()
    # Impacts ([[impacts]] in the file, model/impacts.py): a guard, a striking point, its law.
    impacts: tuple[Impact, ...] = ()
    # A robot read from URDF keeps its tree in numbers (model/tree.py) for recursive dynamics;
    # not part of the model's identity (equal models with and without it are equal).
    kinematic_tree: KinematicTree | None = field(default=None, compare=False, repr=False)
    # A robot read from URDF: (coordinate name, the file's joint name) for each coordinate,
    # since joint names are made identifiers ("joint_8.0" -> "joint_8_0"); () otherwise.
    source_names: tuple[tuple[str, str], ...] = field(default=(), compare=False, repr=False)
    # ... and its joints' velocity (rad/s or m/s) and effort (N m or N) limits, None where the
    # file gives none (or 0): (coordinate name, velocity, effort).
    source_ratings: tuple[tuple[str, float | None, float | None], ...] = field(
        default=(), compare=False, repr=False)
    # ... and its joints' <dynamics>: (coordinate name, damping in N m s/rad or N s/m, Coulomb
    # friction in N m or N), 0 where the file gives none; used only by dynamics(actuators=True).
    source_dynamics: tuple[tuple[str, float, float], ...] = field(
        default=(), compare=False, repr=False)
    # ... and its joints' armature, the rotor inertia on M's diagonal (kg m^2 or kg; an MJCF
    # joint's, model/mjcf.py): (coordinate name, armature), the coordinates with one; used only
    # by dynamics(actuators=True), as <dynamics>.
    source_armature: tuple[tuple[str, float], ...] = field(
        default=(), compare=False, repr=False)

    @property
    def q(self) -> tuple[sp.Symbol, ...]:
        return tuple(c.symbol for c in self.coordinates)

    @property
    def q_dot(self) -> tuple[sp.Symbol, ...]:
        return tuple(c.velocity for c in self.coordinates)

    @property
    def q_ddot(self) -> tuple[sp.Symbol, ...]:
        return tuple(c.acceleration for c in self.coordinates)

    def coordinate(self, name: str) -> Coordinate:
        for c in self.coordinates:
            if c.name == name:
                return c
        raise KeyError(name)

    def parameter(self, name: str) -> Parameter:
        for p in self.parameters:
            if p.name == name:
                return p
        raise KeyError(name)

    def with_parameter_values(self, values: dict[str, float]) -> Model:
        """A copy with some parameter values replaced (SI units); unknown names are refused."""
        names = [p.name for p in self.parameters]
        for name in values:
            if name not in names:
                raise unknown_name(name, names, "parameter", "parameters")
        parameters = tuple(replace(p, value=p.checked(si_number(p.name, values[p.name],
                                                                "parameters"), "parameters"))
                           if p.name in values else p for p in self.parameters)
        return replace(self, parameters=parameters)
