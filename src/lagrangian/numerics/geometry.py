"""The mechanism's geometry as numbers: particle positions, body bars, spring and damper ends.

Positions come from the model (particle and body positions, body angles), in the plane, in m.
A spring or damper given ``between`` two points has its kept ends, exactly. A spring given by its
length only gets end points guessed from that length (see ``spring_end_points``), or none when
none fit; a damper given by its rate only has none. output/animation.py draws what this gives.
Bodies in space (model/rotations.py) give their frames in 3D (``Mechanism.space_frame``), drawn
after ``view_projection`` from a chosen viewpoint.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import sympy as sp

from ..model.model import Model
from ..model.values import ParameterValues, resolve_parameters
from .lambdified import StateFunction


class Frame(NamedTuple):
    """Batched positions (m) at k instants: particles (k, P, 2), bar ends (k, B, 2, 2), spring
    ends (k, S, 2, 2), damper ends (k, D, 2, 2)."""

    particles: np.ndarray
    bars: np.ndarray
    springs: np.ndarray
    dampers: np.ndarray


class SpaceFrame(NamedTuple):
    """Batched 3D positions (m, world axes) at k instants: particles (k, P, 3); for each body in
    space its origin (k, B, 3), rotation (k, B, 3, 3; columns are the body axes in the world),
    centre of mass (k, B, 3), and the uniform box of the same mass and inertia (half extents
    (k, B, 3) along principal axes (k, B, 3, 3), columns in the world); links (k, L, 2, 3):
    each body's origin to its centre of mass, and a parent's origin to its child's origin (the
    joint); planar bars (k, Bp, 2, 3) in z = 0; spring and damper ends (k, S|D, 2, 3)."""

    particles: np.ndarray
    origins: np.ndarray
    rotations: np.ndarray
    centres: np.ndarray
    half_extents: np.ndarray
    principal_axes: np.ndarray
    links: np.ndarray
    bars: np.ndarray
    springs: np.ndarray
    dampers: np.ndarray


ISOMETRIC_VIEW = (45.0, float(np.degrees(np.arctan(1 / np.sqrt(2)))))  # azimuth, elevation (deg)


def view_projection(azimuth: float, elevation: float) -> np.ndarray:
    """The (2, 3) map from world points to the screen (right, up) seen from the direction at
    ``azimuth`` (deg, from +x towards +y) and ``elevation`` (deg, above the x-y plane), z up."""
    a, e = np.radians(azimuth), np.radians(elevation)
    right = np.array([-np.sin(a), np.cos(a), 0.0])
    up = np.array([-np.sin(e) * np.cos(a), -np.sin(e) * np.sin(a), np.cos(e)])
    return np.stack([right, up])


def box_half_extents(mass: np.ndarray, principal_moments: np.ndarray) -> np.ndarray:
    """Half extents (m) of the uniform box with this mass (kg) and principal moments (kg m^2):
    I1 = m (b^2 + c^2) / 3, ... so a^2 = 3 (I2 + I3 - I1) / (2 m)."""
    total = principal_moments.sum(axis=-1, keepdims=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        squared = 3 * (total - 2 * principal_moments) / (2 * mass[..., None])
    return np.sqrt(np.clip(np.nan_to_num(squared, nan=0.0, posinf=0.0, neginf=0.0), 0, None))


@dataclass(frozen=True)
class Mechanism:
    """Compiled geometry: functions of (q, q_dot, t) arrays giving points in the plane (m)."""

    particle_names: tuple[str, ...]
    body_names: tuple[str, ...]
    spring_names: tuple[str, ...]
    damper_names: tuple[str, ...]
    _particles: StateFunction
    _bodies: StateFunction
    _springs: StateFunction
    _dampers: StateFunction
    rigid_body_names: tuple[str, ...] = ()
    link_count: int = 0
    _space: StateFunction | None = None  # particles, bodies in space, links, springs, dampers
    _inertia: StateFunction | None = None  # each body in space's inertia tensor, row by row

    def space_frame(self, q: np.ndarray, v: np.ndarray, t: np.ndarray) -> SpaceFrame:
        """Batched 3D geometry for states q, v (k, n) at times t (k,), bodies in space included."""
        k = len(t)
        flat = self._frame_space(q, v, t)
        sizes = [len(self.particle_names) * 3, len(self.rigid_body_names) * 16,
                 self.link_count * 6, len(self.spring_names) * 6, len(self.damper_names) * 6]
        parts = np.split(flat, np.cumsum(sizes)[:-1], axis=-1)
        particles = parts[0].reshape(k, -1, 3)
        rigid = parts[1].reshape(k, -1, 16)  # origin, centre, R (row by row), mass
        origins, centres = rigid[..., 0:3], rigid[..., 3:6]
        rotations = rigid[..., 6:15].reshape(k, -1, 3, 3)
        mass = rigid[..., 15]
        # The inertia tensor (body axes) diagonalized: its eigenvectors are the box's edges.
        tensor = self._inertia(q, v, t).reshape(k, -1, 3, 3)
        moments, axes = np.linalg.eigh(tensor)
        half = box_half_extents(mass, moments)
        principal = rotations @ axes
        links = parts[2].reshape(k, -1, 2, 3)
        bars2 = self.frame(q, v, t).bars
        bars = np.concatenate([bars2, np.zeros(bars2.shape[:-1] + (1,))], axis=-1)
        springs = parts[3].reshape(k, -1, 2, 3)
        dampers = parts[4].reshape(k, -1, 2, 3)
        return SpaceFrame(particles, origins, rotations, centres, half, principal, links, bars,
                          springs, dampers)

    def _frame_space(self, q, v, t) -> np.ndarray:
        if self._space is None:
            raise ValueError("this mechanism was compiled without its 3D geometry")
        return self._space(q, v, t)

    def frame(self, q: np.ndarray, v: np.ndarray, t: np.ndarray) -> Frame:
        """Batched positions of everything drawn, for states q, v (k, n) at times t (k,)."""
        k = len(t)

        def stack(f: StateFunction, count: int, shape: tuple[int, ...]) -> np.ndarray:
            return f(q, v, t).reshape((k, count) + shape)

        particles = stack(self._particles, len(self.particle_names), (2,))
        raw = stack(self._bodies, len(self.body_names), (4,))  # x, y, angle, half length
        c, s = np.cos(raw[..., 2]), np.sin(raw[..., 2])
        half = raw[..., 3]
        centre = raw[..., :2]
        offset = np.stack([c * half, s * half], axis=-1)
        bars = np.stack([centre - offset, centre + offset], axis=-2)
        springs = stack(self._springs, len(self.spring_names), (2, 2))
        dampers = stack(self._dampers, len(self.damper_names), (2, 2))
        return Frame(particles, bars, springs, dampers)


def mechanism(model: Model, parameters: Mapping[str, float | None] | ParameterValues | None = None
              ) -> Mechanism:
    """Compile the drawable geometry of ``model`` once (parameters by name, SI; the model's
    values where not given)."""
    if isinstance(parameters, Mapping):  # a symbolic-only parameter (None) keeps its symbol
        parameters = {k: v for k, v in parameters.items() if v is not None}
    values = resolve_parameters(model, parameters, require=False).symbol_values(model)

    def compile_(exprs) -> StateFunction:
        return StateFunction(model, exprs, values)

    particles = [e for p in model.particles for e in p.position[:2]]
    bodies = []
    for body in model.bodies:
        mass, inertia = body.mass.xreplace(values), body.inertia.xreplace(values)
        # Drawn as the uniform bar of the same mass and inertia: length sqrt(12 I / m).
        half = sp.sqrt(3 * inertia / mass) if mass != 0 else sp.S.Zero
        bodies.extend([body.position[0], body.position[1], body.angle, half])
    ends = spring_end_points(model, values)
    springs = [e for name in ends for point in ends[name] for e in point[:2]]
    damper_ends = {d.name: (d.ends[0].point, d.ends[1].point) for d in model.dampers
                   if d.ends is not None}
    dampers = [e for name in damper_ends for point in damper_ends[name] for e in point[:2]]
    space = {}
    if model.rigid_bodies:
        space = _space_geometry(model, ends, damper_ends, compile_)
    return Mechanism(
        particle_names=tuple(p.name for p in model.particles),
        body_names=tuple(b.name for b in model.bodies),
        spring_names=tuple(ends),
        damper_names=tuple(damper_ends),
        _particles=compile_(particles), _bodies=compile_(bodies), _springs=compile_(springs),
        _dampers=compile_(dampers), **space,
    )


def _space_geometry(model: Model, ends: Mapping, damper_ends: Mapping, compile_) -> dict:
    """The 3D expressions of a model with bodies in space, as Mechanism's keyword arguments."""
    by_name = {b.name: b for b in model.rigid_bodies}
    exprs = [e for p in model.particles for e in (*p.position, 0, 0, 0)[:3]]
    inertia = []
    for body in model.rigid_bodies:
        exprs += [*body.origin, *body.position, *(e for row in body.rotation for e in row),
                  body.mass]
        inertia += [e for row in body.inertia for e in row]
    links = 0
    for body in model.rigid_bodies:  # the body's origin (its joint or pivot) to its centre
        exprs += [*body.origin, *body.position]
        links += 1
    for body in model.rigid_bodies:  # the parent's origin to the joint on it
        if body.parent in by_name:
            exprs += [*by_name[body.parent].origin, *body.origin]
            links += 1
    for table in (ends, damper_ends):
        exprs += [e for name in table for point in table[name] for e in (*point, 0, 0, 0)[:3]]
    return {"rigid_body_names": tuple(by_name), "link_count": links,
            "_space": compile_(exprs), "_inertia": compile_(inertia)}


def spring_end_points(model: Model, values: Mapping[sp.Symbol, sp.Expr]) -> dict[str, tuple]:
    """Spring name -> (point A, point B), in the model's order.

    A spring given ``between`` two points has its kept ends. For one given by its length only,
    A and B are guessed where the length equals |A - B| at sampled states: candidates are the
    origin and the particle and body centres; failing a pair, one moving candidate and a fixed
    anchor found by least squares. Springs matching neither are skipped.
    """
    guessed = _guessed_end_points(model, [s for s in model.springs if s.ends is None], values)
    found = {}
    for spring in model.springs:
        if spring.ends is not None:
            found[spring.name] = (spring.ends[0].point, spring.ends[1].point)
        elif spring.name in guessed:
            found[spring.name] = guessed[spring.name]
    return found


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
