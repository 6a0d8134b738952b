"""The mechanism as a user sketches it, found from the model's structure: rods from pivots and
between points, pivots, blocks on their tracks, bodies rolling on a surface (see ``sketch``).
Its points are those each component kind puts in a drawing (output/drawing.py).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import NamedTuple

import numpy as np
import sympy as sp

from ..compile.lambdified import StateFunction
from ..kinds import ConstraintKind
from ..model.expressions import as_expression
from ..model.model import Model
from .drawing import Drawing, drawing


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


def sketch(model: Model, values: Mapping[sp.Symbol, sp.Expr], parts: Drawing | None = None
           ) -> Sketch:
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
    parts = drawing(model, values) if parts is None else parts
    points, owners, bar_ends = parts.points, parts.owners, parts.bar_ends
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
