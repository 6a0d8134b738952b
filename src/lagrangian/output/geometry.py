"""The mechanism's geometry as numbers: particle positions, body bars, spring and damper ends.

Positions come from the model (particle and body positions, body angles), in the plane, in m,
gathered kind by kind through output/drawing.py's table.
A spring or damper given ``between`` two points has its kept ends, exactly. A spring given by its
length only gets end points guessed from that length (see ``spring_end_points``), or none when
none fit; a damper given by its rate only has none. output/animation.py draws what this gives.
Bodies in space (model/rotations.py) give their frames in 3D (``Mechanism.space_frame``), drawn
after ``view_projection`` from a chosen viewpoint, and their rolling wheels' rims and contact
points (``Mechanism.wheel_frame``). ``sketch`` (output/sketch.py) finds what a user would draw
besides the masses (rods, pivots, blocks on tracks, wheels on surfaces) from the model's structure.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..compile.lambdified import StateFunction
from ..model.model import Model
from ..model.values import ParameterValues, resolve_parameters
from .drawing import Drawing, drawing, spring_end_points
from .sketch import Sketch, sketch

__all__ = ["Frame", "Mechanism", "Sketch", "SpaceFrame", "box_half_extents", "mechanism",
           "sketch", "spring_end_points", "view_projection"]


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

    parts = drawing(model, values)  # each component kind's share (output/drawing.py)

    def ends(table: Mapping) -> list:
        return [e for name in table for point in table[name] for e in point[:2]]

    space = _space_geometry(parts, compile_) if model.rigid_bodies else {}
    drawn = sketch(model, values, parts)
    rod_exprs = [e for pair in drawn.rods for point in pair for e in point] + \
        [e for point in drawn.pivots for e in point]
    return Mechanism(
        particle_names=tuple(parts.particle_names),
        body_names=tuple(parts.body_names),
        spring_names=tuple(parts.spring_ends),
        damper_names=tuple(parts.damper_ends),
        _particles=compile_(parts.particles), _bodies=compile_(parts.bodies),
        _springs=compile_(ends(parts.spring_ends)), _dampers=compile_(ends(parts.damper_ends)),
        **space,
        rod_count=len(drawn.rods), pivot_count=len(drawn.pivots),
        _rods=compile_(rod_exprs) if rod_exprs else None, blocks=drawn.blocks,
        rolling=drawn.rolling, gravity=drawn.gravity, aimed=drawn.aimed,
    )


def _space_geometry(parts: Drawing, compile_) -> dict:
    """The 3D expressions of a model with bodies in space, as Mechanism's keyword arguments."""
    links = parts.links
    exprs = [*parts.space_particles, *parts.rigid, *(e for link in links for e in link)]
    for table in (parts.spring_ends, parts.damper_ends):
        exprs += [e for name in table for point in table[name] for e in (*point, 0, 0, 0)[:3]]
    return {"rigid_body_names": tuple(parts.rigid_body_names), "link_count": len(links),
            "wheels": parts.wheels, "_space": compile_(exprs), "_inertia": compile_(parts.inertia)}
