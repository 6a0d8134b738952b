"""The mechanism's geometry as numbers: particle positions, body bars, spring and damper ends.

Positions come from the model (particle and body positions, body angles), in the plane, in m.
A spring or damper given ``between`` two points has its kept ends, exactly. A spring given by its
length only gets end points guessed from that length (see ``spring_end_points``), or none when
none fit; a damper given by its rate only has none. output/animation.py draws what this gives.
Bodies in space (model/rotations.py) give their frames in 3D (``Mechanism.space_frame``), drawn
after ``view_projection`` from a chosen viewpoint, and their rolling wheels' rims and contact
points (``Mechanism.wheel_frame``). ``sketch`` finds what a user would draw besides the masses
(rods, pivots, blocks on tracks, wheels on surfaces) from the model's structure.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import sympy as sp

from ..compile.lambdified import StateFunction
from ..kinds import ConstraintKind
from ..model.expressions import as_expression
from ..model.model import Model
from ..model.values import ParameterValues, resolve_parameters


class Frame(NamedTuple):
    """Batched positions (m) at k instants: particles (k, P, 2), bar ends (k, B, 2, 2), spring
    ends (k, S, 2, 2), damper ends (k, D, 2, 2), rod ends (k, R, 2, 2: anchor, point) and
    pivots (k, V, 2: fixed or driven supports)."""

    particles: np.ndarray
    bars: np.ndarray
    springs: np.ndarray
    dampers: np.ndarray
    rods: np.ndarray | None = None
    pivots: np.ndarray | None = None


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
    rods: np.ndarray | None = None
    pivots: np.ndarray | None = None


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
    # The mechanism as a user sketches it (see ``sketch``): rods, pivots, blocks, rolling bodies.
    rod_count: int = 0
    pivot_count: int = 0
    _rods: StateFunction | None = None  # rod ends then pivots, 3 components each
    blocks: tuple[tuple[int, tuple[float, float]], ...] = ()  # particle index, unit track
    rolling: tuple[tuple[int, float, tuple[float, float]], ...] = ()  # body, radius, normal
    gravity: tuple[float, float] | None = None  # unit direction of gravity in the plane
    aimed: tuple[tuple[int, int], ...] = ()  # (body, pivot): bar drawn from the pivot
    # Rolling contacts of bodies in space: (body index, radius (m), axle (body axes), ground
    # normal (world)), the ground being the plane r . n = 0 (model/contacts.py).
    wheels: tuple[tuple[int, float, tuple[float, ...], tuple[float, ...]], ...] = ()

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
        rods, pivots = self._rods_and_pivots(q, v, t)
        return SpaceFrame(particles, origins, rotations, centres, half, principal, links, bars,
                          springs, dampers, rods, pivots)

    def wheel_frame(self, space: SpaceFrame, points: int = 41) -> tuple[np.ndarray, np.ndarray]:
        """Each rolling wheel's rim (k, W, points, 3) and contact point (k, W, 3) in the world:
        with a = R axle and d = -(n - (n.a) a)/|n - (n.a) a| (down in the wheel's plane), the
        contact is r_C = r_G + r d and the rim r_G + r (cos s d + sin s a x d)."""
        k = len(space.origins)
        if not self.wheels:
            return np.zeros((k, 0, points, 3)), np.zeros((k, 0, 3))
        index = [w[0] for w in self.wheels]
        radius = np.array([w[1] for w in self.wheels])[None, :, None]
        axle = np.einsum("kbij,bj->kbi", space.rotations[:, index],
                         np.array([w[2] for w in self.wheels]))
        normal = np.array([w[3] for w in self.wheels])[None]
        down = -(normal - np.sum(normal * axle, axis=-1, keepdims=True) * axle)
        down /= np.maximum(np.linalg.norm(down, axis=-1, keepdims=True), 1e-300)
        side = np.cross(axle, down)
        centre = space.origins[:, index]
        contact = centre + radius * down
        s = np.linspace(0, 2 * np.pi, points)[None, None, :, None]
        rim = centre[:, :, None] + radius[..., None] * (np.cos(s) * down[:, :, None] +
                                                        np.sin(s) * side[:, :, None])
        return rim, contact

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
        rods, pivots = self._rods_and_pivots(q, v, t)
        for j, p in self.aimed:  # pinned at one end: from the pivot through the centre
            bars[:, j] = np.stack([pivots[:, p, :2], 2 * centre[:, j] - pivots[:, p, :2]], axis=1)
        return Frame(particles, bars, springs, dampers, rods[..., :2], pivots[..., :2])

    def _rods_and_pivots(self, q, v, t) -> tuple[np.ndarray, np.ndarray]:
        """Rod ends (k, R, 2, 3) and pivots (k, V, 3), in 3D."""
        k = len(t)
        if self._rods is None:
            return np.zeros((k, 0, 2, 3)), np.zeros((k, 0, 3))
        flat = self._rods(q, v, t)
        rods = flat[:, :self.rod_count * 6].reshape(k, -1, 2, 3)
        return rods, flat[:, self.rod_count * 6:].reshape(k, -1, 3)


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
        space = _space_geometry(model, ends, damper_ends, compile_, values)
    drawn = sketch(model, values)
    rod_exprs = [e for pair in drawn.rods for point in pair for e in point] + \
        [e for point in drawn.pivots for e in point]
    return Mechanism(
        particle_names=tuple(p.name for p in model.particles),
        body_names=tuple(b.name for b in model.bodies),
        spring_names=tuple(ends),
        damper_names=tuple(damper_ends),
        _particles=compile_(particles), _bodies=compile_(bodies), _springs=compile_(springs),
        _dampers=compile_(dampers), **space,
        rod_count=len(drawn.rods), pivot_count=len(drawn.pivots),
        _rods=compile_(rod_exprs) if rod_exprs else None, blocks=drawn.blocks,
        rolling=drawn.rolling, gravity=drawn.gravity, aimed=drawn.aimed,
    )


def _space_geometry(model: Model, ends: Mapping, damper_ends: Mapping, compile_,
                    values: Mapping) -> dict:
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
    names = list(by_name)
    wheels = []
    for contact in model.contacts:
        try:
            radius = float(as_expression(contact.radius).xreplace(values))
            axle = tuple(float(as_expression(c).xreplace(values)) for c in contact.axle)
            normal = tuple(float(as_expression(c).xreplace(values)) for c in contact.normal)
        except (TypeError, ValueError):
            continue  # a symbolic radius or direction: the wheel is not drawn
        if contact.body in by_name:
            wheels.append((names.index(contact.body), radius, axle, normal))
    return {"rigid_body_names": tuple(by_name), "link_count": links, "wheels": tuple(wheels),
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


class Sketch(NamedTuple):
    """The mechanism as a user sketches it (see ``sketch``): rods as (anchor, point) and pivots
    as 3-vectors of expressions; blocks as (particle index, unit track direction); rolling
    bodies as (body index, radius rho (m), unit normal n from the surface to the centre); the
    unit direction of gravity in the plane, if any."""

    rods: tuple[tuple[tuple, tuple], ...] = ()
    pivots: tuple[tuple, ...] = ()
    blocks: tuple[tuple[int, tuple[float, float]], ...] = ()
    rolling: tuple[tuple[int, float, tuple[float, float]], ...] = ()
    gravity: tuple[float, float] | None = None
    aimed: tuple[tuple[int, int], ...] = ()  # (body index, pivot index): a link pinned at an end


_SKETCH_SAMPLES = 8


def sketch(model: Model, values: Mapping[sp.Symbol, sp.Expr]) -> Sketch:
    """What a user draws besides the masses, found from the model's structure:

    - a rod from a point's pivot: the part of its position (particle, body centre) without one
      of its coordinates, when that part holds no coordinate and the point stays at a fixed
      distance from it (pivot + l (sin q, -cos q); a driven support x_s(t) + ...); a body whose
      bar of the same inertia reaches that pivot is a link pinned at its end, its bar drawn from
      the pivot through its centre (``aimed``), whatever its angle is measured from;
    - a rod between two points of different owners (particles, body centres, bar ends) that
      stay at a fixed non-zero distance in every configuration (the double pendulum's second
      rod, a cart and its pendulum), unless both lie on one body's bar (one per pair of owners);
    - pivots: those anchors, and bar ends that do not move with the coordinates;
    - blocks: particles moving along a straight line (a cart, a slider), with the line;
    - rolling bodies: a body whose centre moves along a line while a constraint keeps the point
      at distance rho below it (along the normal) from slipping: v.d + rho omega = 0.

    Decided at random configurations (q, t in [-1, 1]): the structure holds at every
    configuration, so it holds at these; nothing is fitted to a run. Bodies in space are drawn
    from their joints already (``_space_geometry``) and take no part.
    """
    gravity = None
    if model.gravity is not None:
        try:
            g = np.array([float(as_expression(c).xreplace(values))
                          for c in model.gravity.direction[:2]])
            if np.hypot(*g) > 0:
                gravity = tuple(float(c) for c in g / np.hypot(*g))
        except (TypeError, ValueError):
            gravity = None
    points, owners = [], []  # 3-vectors; owner: ("particle", i) or ("body", j)
    for i, particle in enumerate(model.particles):
        points.append(tuple((*particle.position, 0, 0, 0)[:3]))
        owners.append(("particle", i))
    bar_ends = {}
    for j, body in enumerate(model.bodies):
        centre = tuple((*body.position, 0, 0, 0)[:3])
        points.append(centre)
        owners.append(("body", j))
        mass, inertia = body.mass.xreplace(values), body.inertia.xreplace(values)
        half = sp.sqrt(3 * inertia / mass) if mass != 0 else sp.S.Zero
        if half != 0:
            direction = (sp.cos(body.angle), sp.sin(body.angle), 0)
            ends = []
            for sign in (-1, 1):
                ends.append(len(points))
                points.append(tuple(c + sign * half * u for c, u in zip(centre, direction,
                                                                         strict=True)))
                owners.append(("body", j))
            bar_ends[j] = tuple(ends)
    coordinates = set(model.q)
    # Pivot candidates: a point's position without the terms holding one of its coordinates.
    candidates = []  # (point index, anchor)
    for index, (point, owner) in enumerate(zip(points, owners, strict=True)):
        if owner[0] == "body" and index != _centre_index(owners, index):
            continue  # bar ends follow their centre
        held = set().union(*(as_expression(c).free_symbols for c in point)) & coordinates
        for q in (c for c in model.q if c in held):
            anchor = tuple(sp.Add(*(term for term in sp.Add.make_args(sp.expand(c))
                                    if q not in term.free_symbols)) for c in point)
            if not set().union(*(as_expression(c).free_symbols for c in anchor)) & coordinates:
                candidates.append((index, anchor))
    n = len(model.q)
    rng = np.random.default_rng(11)
    samples = rng.uniform(-1.0, 1.0, size=(_SKETCH_SAMPLES, 2 * n + 1))
    q_s, v_s, t_s = samples[:, :n], samples[:, n:2 * n], samples[:, -1]
    exprs = [c for point in points for c in point] + \
        [c for _, anchor in candidates for c in anchor]
    try:
        with np.errstate(all="ignore"):
            flat = StateFunction(model, exprs, values)(q_s, v_s, t_s)
    except (TypeError, ValueError, ZeroDivisionError, NameError, KeyError):
        return Sketch(gravity=gravity)
    at = flat.reshape(_SKETCH_SAMPLES, -1, 3)  # (samples, points then anchors, 3)
    where, anchors_at = at[:, :len(points)], at[:, len(points):]
    scale = 1.0 + float(np.nanmax(np.abs(at))) if np.isfinite(at).any() else 1.0
    tolerance = 1e-9 * scale

    def fixed_distance(a: np.ndarray, b: np.ndarray) -> bool:
        d = np.linalg.norm(a - b, axis=-1)
        return bool(np.all(np.isfinite(d)) and np.ptp(d) <= tolerance and d.min() > tolerance)

    def still(a: np.ndarray) -> bool:
        return bool(np.all(np.isfinite(a)) and np.ptp(a, axis=0).max() <= tolerance)

    def on_bar(a: np.ndarray, j: int) -> bool:
        """a lies on body j's bar at every sample."""
        e0, e1 = where[:, bar_ends[j][0]], where[:, bar_ends[j][1]]
        u = e1 - e0
        s = np.clip(np.sum((a - e0) * u, axis=-1) / np.maximum(np.sum(u * u, axis=-1), 1e-300),
                    0, 1)
        return bool(np.all(np.linalg.norm(e0 + s[:, None] * u - a, axis=-1) <= tolerance))

    def same_bar(a: np.ndarray, b: np.ndarray) -> bool:
        return any(on_bar(a, j) and on_bar(b, j) for j in bar_ends)

    rods, pivots, pivots_at = [], [], []

    def add_pivot(expr: tuple, value: np.ndarray) -> int:
        for i, seen in enumerate(pivots_at):
            if np.all(np.abs(value - seen) <= tolerance):
                return i
        pivots.append(expr)
        pivots_at.append(value)
        return len(pivots) - 1

    rooted = set()
    aimed = []  # (body, pivot): a link pinned at one end, its bar drawn from the pivot
    for (index, anchor), value in zip(candidates, np.moveaxis(anchors_at, 1, 0), strict=True):
        if index in rooted or not fixed_distance(where[:, index], value):
            continue
        rooted.add(index)
        pivot = add_pivot(anchor, value)
        owner = owners[index]
        if owner[0] == "body" and owner[1] in bar_ends and np.allclose(
                np.linalg.norm(where[:, bar_ends[owner[1]][1]] - where[:, index], axis=-1),
                np.linalg.norm(value - where[:, index], axis=-1), rtol=0, atol=tolerance):
            # The uniform bar of this inertia reaches the pivot: a link pinned at its end,
            # drawn along pivot -> centre whatever the body's angle is measured from.
            aimed.append((owner[1], pivot))
        elif not same_bar(value, where[:, index]):
            rods.append((anchor, points[index]))
    for ends in bar_ends.values():
        for e in ends:
            if still(where[:, e]):
                add_pivot(points[e], where[:, e])
    best = {}  # (owner, owner) -> (distance, i, j): the shortest fixed distance between them
    for i in range(len(points)):
        for j in range(i + 1, len(points)):
            if owners[i] == owners[j] or (still(where[:, i]) and still(where[:, j])):
                continue
            if fixed_distance(where[:, i], where[:, j]) and \
                    not same_bar(where[:, i], where[:, j]):
                key = (owners[i], owners[j])
                distance = float(np.linalg.norm(where[0, i] - where[0, j]))
                if key not in best or distance < best[key][0]:
                    best[key] = (distance, i, j)
    rods += [(points[i], points[j]) for _, i, j in best.values()]
    # A rod held by a constraint rather than by the coordinates: Phi = c (|P - A|^2 - L^2)
    # (the Cartesian pendulum's x^2 + y^2 - L^2), A the origin or another point.
    holonomic = [c.expression for c in model.constraints if c.kind == ConstraintKind.HOLONOMIC]
    if holonomic:
        try:
            with np.errstate(all="ignore"):
                phi = StateFunction(model, holonomic, values)(q_s, v_s, t_s)
        except (TypeError, ValueError, ZeroDivisionError, NameError, KeyError):
            phi = np.full((_SKETCH_SAMPLES, 0), np.nan)
        origin = (sp.S.Zero,) * 3
        anchors = [(origin, np.zeros((_SKETCH_SAMPLES, 3)), None)] + \
            [(points[j], where[:, j], owners[j]) for j in range(len(points))]
        for column in phi.T:
            if not np.all(np.isfinite(column)):
                continue
            for i, point in enumerate(points):
                found = False
                for anchor, value, owner in anchors:
                    if owner == owners[i]:
                        continue
                    squared = np.sum((where[:, i] - value) ** 2, axis=-1)
                    basis = np.column_stack([squared, -np.ones_like(squared)])
                    (c, c_length2), *_ = np.linalg.lstsq(basis, column, rcond=None)
                    if abs(c) > 1e-12 and c_length2 / c > tolerance and np.allclose(
                            basis @ [c, c_length2], column,
                            atol=1e-9 * (1 + np.max(np.abs(column)))) and np.ptp(squared) > 0:
                        rods.append((anchor, point))
                        if owner is None:
                            add_pivot(anchor, value)
                        found = True
                        break
                if found:
                    break
    blocks = []
    if not model.rigid_bodies:
        for i in range(len(model.particles)):
            direction = _line_direction(where[:, i], tolerance)
            if direction is not None:
                blocks.append((i, direction))
    rolling = [] if model.rigid_bodies else _rolling_bodies(model, values, points, owners,
                                                             where, samples, tolerance)
    return Sketch(tuple(rods), tuple(pivots), tuple(blocks), tuple(rolling), gravity,
                  tuple(aimed))


def _centre_index(owners: list, index: int) -> int:
    """The index of the first point of this point's owner (a body's centre)."""
    return owners.index(owners[index])


def _line_direction(path: np.ndarray, tolerance: float) -> tuple[float, float] | None:
    """The unit direction (in the plane) of a point that moves along a straight line, or None."""
    if not np.all(np.isfinite(path)) or np.any(np.abs(path[:, 2]) > tolerance):
        return None
    centred = path[:, :2] - path[:, :2].mean(axis=0)
    _, spread, axes = np.linalg.svd(centred, full_matrices=False)
    if spread[0] <= tolerance or spread[1] > 1e-9 * spread[0]:
        return None
    d = axes[0] if axes[0][np.argmax(np.abs(axes[0]))] > 0 else -axes[0]
    return (float(d[0]), float(d[1]))


def _rolling_bodies(model, values, points, owners, where, samples, tolerance) -> list:
    """Bodies rolling without slipping on a straight surface: (body index, rho, normal)."""
    if not model.bodies or not model.constraints:
        return []
    n = len(model.q)
    q, v, t = samples[:, :n], samples[:, n:2 * n], samples[:, -1]
    found = []
    for j, body in enumerate(model.bodies):
        direction = _line_direction(where[:, owners.index(("body", j))], tolerance)
        if direction is None:
            continue
        d = np.array(direction)
        rows = [sp.diff(c, x) for c in body.position[:2] for x in model.q] + \
            [sp.diff(body.angle, x) for x in model.q]
        for constraint in model.constraints:
            speeds = model.q_dot if constraint.kind == ConstraintKind.VELOCITY else model.q
            rows_c = [sp.diff(constraint.expression, x) for x in speeds]
            try:
                with np.errstate(all="ignore"):
                    at = StateFunction(model, rows + rows_c, values)(q, v, t)
            except (TypeError, ValueError, ZeroDivisionError, NameError, KeyError):
                continue
            jp = at[:, :2 * n].reshape(-1, 2, n)
            slide = np.einsum("i,sin->sn", d, jp)  # d . dP/dq
            turn = at[:, 2 * n:3 * n]  # d angle / dq
            a = at[:, 3 * n:]
            radii = []
            for s in range(len(a)):
                basis = np.column_stack([slide[s], turn[s]])
                if not np.all(np.isfinite(basis)) or not np.all(np.isfinite(a[s])):
                    break
                (alpha, gamma), *_ = np.linalg.lstsq(basis, a[s], rcond=None)
                if abs(alpha) <= 1e-12 or np.linalg.norm(basis @ [alpha, gamma] - a[s]) > \
                        1e-9 * (1 + np.linalg.norm(a[s])) or not np.any(turn[s]):
                    break
                radii.append(gamma / alpha)  # rho: v . d + rho omega = 0
            if len(radii) == len(a) and np.ptp(radii) <= 1e-9 * (1 + abs(radii[0])) and \
                    abs(radii[0]) > tolerance:
                normal = (-d[1], d[0])  # the contact is at centre - rho n
                found.append((j, float(radii[0]), (float(normal[0]), float(normal[1]))))
                break
    return found
