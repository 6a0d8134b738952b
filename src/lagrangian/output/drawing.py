"""What each component kind puts in a drawing, one table entry per kind (``draw``;
tests/model/test_component_tables.py walks every kind): positions in the plane and in space (m),
as expressions, and the points a user's sketch is made of (output/sketch.py).

A particle is a point; a planar body the uniform bar of its mass and inertia (length
sqrt(12 I / m)); a body in space its frame, centre and inertia; a spring or damper its two ends
(a spring given by its length only: ends guessed from it, ``spring_end_points``); a rolling
contact its wheel. Loads and constraints are drawn by nothing (``NOT_DRAWN``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import singledispatch

import numpy as np
import sympy as sp

from ..compile.lambdified import StateFunction
from ..model.contacts import RollingContact
from ..model.expressions import as_expression
from ..model.model import Body, Constraint, Damper, Model, Particle, PointForce, Spring, Torque
from ..model.rotations import Moment, RigidBody

NOT_DRAWN = (PointForce, Torque, Moment, Constraint)  # no position of their own to draw


def _padded(point) -> tuple:
    """A point as a 3-vector (z = 0 in the plane)."""
    return tuple((*point, 0, 0, 0)[:3])


@dataclass
class Drawing:
    """The drawable parts of a model, gathered kind by kind (``draw``), in the model's order.

    In the plane: particles (x, y), bodies (x, y, angle, half length), spring and damper ends
    ((x, y) twice); in space: particles (x, y, z), bodies in space (origin, centre, rotation row
    by row, mass) with their inertia tensors, links (origin to centre; the parent's origin to the
    joint) and wheels; for the sketch: points (3-vectors) with their owners, ("particle", i) or
    ("body", j), and each bar's two end points (indices into ``points``).
    """

    model: Model
    values: Mapping[sp.Symbol, sp.Expr]
    particle_names: list[str] = field(default_factory=list)
    particles: list = field(default_factory=list)
    body_names: list[str] = field(default_factory=list)
    bodies: list = field(default_factory=list)
    spring_ends: dict[str, tuple] = field(default_factory=dict)
    damper_ends: dict[str, tuple] = field(default_factory=dict)
    space_particles: list = field(default_factory=list)
    rigid_body_names: list[str] = field(default_factory=list)
    rigid: list = field(default_factory=list)
    inertia: list = field(default_factory=list)
    origins: dict[str, tuple] = field(default_factory=dict)
    centre_links: list = field(default_factory=list)
    joints: list[tuple[str | None, tuple]] = field(default_factory=list)  # (parent, origin)
    contact_wheels: list = field(default_factory=list)  # (body, radius, axle, normal)
    points: list[tuple] = field(default_factory=list)
    owners: list[tuple[str, int]] = field(default_factory=list)
    bar_ends: dict[int, tuple[int, int]] = field(default_factory=dict)
    _guessed: dict[str, tuple] | None = None

    def half_length(self, body: Body) -> sp.Expr:
        """Half the length (m) of the uniform bar of the body's mass and inertia."""
        mass, inertia = body.mass.xreplace(self.values), body.inertia.xreplace(self.values)
        return sp.sqrt(3 * inertia / mass) if mass != 0 else sp.S.Zero

    def guessed_ends(self, spring: Spring) -> tuple | None:
        """The ends guessed for a spring given by its length only (all such found at once)."""
        if self._guessed is None:
            self._guessed = _guessed_end_points(
                self.model, [s for s in self.model.springs if s.ends is None], self.values)
        return self._guessed.get(spring.name)

    @property
    def links(self) -> list:
        """Each body in space's origin to its centre, then each parent's origin to its joint."""
        return self.centre_links + [(*self.origins[parent], *origin)
                                    for parent, origin in self.joints if parent in self.origins]

    @property
    def wheels(self) -> tuple:
        """Rolling wheels on bodies in space: (body index, radius, axle, normal)."""
        return tuple((self.rigid_body_names.index(body), radius, axle, normal)
                     for body, radius, axle, normal in self.contact_wheels
                     if body in self.rigid_body_names)


def drawing(model: Model, values: Mapping[sp.Symbol, sp.Expr]) -> Drawing:
    """Every component of ``model`` through ``draw`` (parameters as ``values``)."""
    parts = Drawing(model, values)
    for component in (*model.particles, *model.bodies, *model.rigid_bodies, *model.springs,
                      *model.dampers, *model.loads, *model.constraints, *model.contacts):
        draw(component, parts)
    return parts


@singledispatch
def draw(component, parts: Drawing) -> None:
    """Add what ``component`` shows to ``parts``."""
    raise TypeError(f"no drawing for a component of kind {type(component).__name__}")


@draw.register
def _(particle: Particle, parts: Drawing) -> None:
    parts.owners.append(("particle", len(parts.particle_names)))
    parts.points.append(_padded(particle.position))
    parts.particle_names.append(particle.name)
    parts.particles.extend(particle.position[:2])
    parts.space_particles.extend(_padded(particle.position))


@draw.register
def _(body: Body, parts: Drawing) -> None:
    j, half = len(parts.body_names), parts.half_length(body)
    parts.body_names.append(body.name)
    parts.bodies.extend([body.position[0], body.position[1], body.angle, half])
    centre = _padded(body.position)
    parts.points.append(centre)
    parts.owners.append(("body", j))
    if half != 0:
        direction = (sp.cos(body.angle), sp.sin(body.angle), 0)
        ends = []
        for sign in (-1, 1):
            ends.append(len(parts.points))
            parts.points.append(tuple(c + sign * half * u
                                      for c, u in zip(centre, direction, strict=True)))
            parts.owners.append(("body", j))
        parts.bar_ends[j] = tuple(ends)


@draw.register
def _(rigid: RigidBody, parts: Drawing) -> None:
    parts.rigid_body_names.append(rigid.name)
    parts.rigid += [*rigid.origin, *rigid.position, *(e for row in rigid.rotation for e in row),
                    rigid.mass]
    parts.inertia += [e for row in rigid.inertia for e in row]
    parts.origins[rigid.name] = tuple(rigid.origin)
    parts.centre_links.append((*rigid.origin, *rigid.position))
    parts.joints.append((rigid.parent, tuple(rigid.origin)))


@draw.register
def _(spring: Spring, parts: Drawing) -> None:
    if spring.ends is not None:
        parts.spring_ends[spring.name] = (spring.ends[0].point, spring.ends[1].point)
    elif (guessed := parts.guessed_ends(spring)) is not None:
        parts.spring_ends[spring.name] = guessed


@draw.register
def _(damper: Damper, parts: Drawing) -> None:
    if damper.ends is not None:  # a damper given by its rate only has no ends to draw
        parts.damper_ends[damper.name] = (damper.ends[0].point, damper.ends[1].point)


@draw.register
def _(contact: RollingContact, parts: Drawing) -> None:
    try:
        radius = float(as_expression(contact.radius).xreplace(parts.values))
        axle = tuple(float(as_expression(c).xreplace(parts.values)) for c in contact.axle)
        normal = tuple(float(as_expression(c).xreplace(parts.values)) for c in contact.normal)
    except (TypeError, ValueError):
        return  # a symbolic radius or direction: the wheel is not drawn
    parts.contact_wheels.append((contact.body, radius, axle, normal))


for _kind in NOT_DRAWN:
    draw.register(_kind, lambda component, parts: None)


def spring_end_points(model: Model, values: Mapping[sp.Symbol, sp.Expr]) -> dict[str, tuple]:
    """Spring name -> (point A, point B), in the model's order.

    A spring given ``between`` two points has its kept ends. For one given by its length only,
    A and B are guessed where the length equals |A - B| at sampled states: candidates are the
    origin and the particle and body centres; failing a pair, one moving candidate and a fixed
    anchor found by least squares. Springs matching neither are skipped.
    """
    parts = Drawing(model, values)
    for spring in model.springs:
        draw(spring, parts)
    return parts.spring_ends


def _guessed_end_points(model: Model, springs: list, values: Mapping) -> dict[str, tuple]:
    if not springs:
        return {}
    candidates = [(0, 0, 0)] + [p.position for p in model.particles] + \
        [b.position for b in model.bodies]
    n = len(model.q)
    rng = np.random.default_rng(7)
    samples = rng.uniform(-1.0, 1.0, size=(6, 2 * n + 1))  # rows of (q, q_dot, t)

    def sample(expr) -> np.ndarray:
        with np.errstate(all="ignore"):
            return StateFunction(model, [expr], values)(
                samples[:, :n], samples[:, n:2 * n], samples[:, -1])[:, 0]

    try:
        points = [np.stack([sample(c) for c in point], axis=-1) for point in candidates]
    except (TypeError, ValueError, ZeroDivisionError):
        return {}
    found = {}
    for spring in springs:
        try:
            length = sample(spring.length)
        except (TypeError, ValueError, ZeroDivisionError):
            continue
        if not np.all(np.isfinite(length)):
            continue
        scale = 1.0 + np.max(np.abs(length))
        match = None
        for i, a in enumerate(points):
            for j in range(i + 1, len(points)):
                distance = np.linalg.norm(a - points[j], axis=-1)
                if np.allclose(distance, np.abs(length), rtol=1e-9, atol=1e-12 * scale):
                    match = (candidates[i], candidates[j])
                    break
            if match:
                break
        if match is None:
            match = _fixed_anchor(points, candidates, length)
        if match is not None:
            found[spring.name] = match
    return found


def _fixed_anchor(points, candidates, length):
    for point, expr in zip(points[1:], candidates[1:], strict=True):
        # |P - A|^2 = L^2  <=>  2 P.A - c = |P|^2 - L^2 with c = |A|^2 (linear in A, c)
        matrix = np.column_stack([2 * point, -np.ones(len(point))])
        rhs = np.sum(point**2, axis=-1) - length**2
        solution, *_ = np.linalg.lstsq(matrix, rhs, rcond=None)
        anchor, c = solution[:3], solution[3]
        if np.allclose(matrix @ solution, rhs, atol=1e-9 * (1 + np.max(np.abs(rhs)))) and \
                abs(c - anchor @ anchor) < 1e-9 * (1 + abs(c)):
            return (tuple(sp.Float(x) for x in anchor), expr)
    return None
