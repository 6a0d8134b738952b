"""Chains of point masses (an n-link pendulum): each particle's 1/2 m v.v through the segments of
the chain, so the work grows with the pairs of segments, not with particles times coordinates.

Where a particle's position r_i holds every term of another's r_p (its parent in the chain),
r_i = r_p + delta_i, and down the chain r_i = sum of the segments delta_s on its path from the
ground. Then J_i = sum_s J(delta_s) and a_rest,i = sum_s a_rest(delta_s), so

    sum_i m_i J_i^T J_i  = sum over segment pairs (s, s') on one path of
                           J(delta_s)^T J(delta_s') times the masses beyond the deeper of them,

and the same for m J^T a_rest and the weight's virtual work. The entries are those the
particle-by-particle path of inertia.py writes, term for term, when no coordinate appears in two
segments of one path (checked here: a particle whose path repeats a coordinate, or whose mass
varies or whose position depends on t or the rates, goes the particle-by-particle way instead).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import sympy as sp

from ..model.model import Particle
from .kinematics import Differentiator


@dataclass
class _Segment:
    """One particle of the chain: the terms its position adds to its parent's (m), the
    coordinates they hold (indices into q), and the masses (kg) at and beyond it."""

    particle: Particle
    parent: _Segment | None
    terms: tuple[frozenset, ...]
    full: tuple[frozenset, ...]  # every term of its position, by component
    coordinates: tuple[int, ...] = ()
    path_coordinates: frozenset = frozenset()
    masses: list[sp.Expr] = field(default_factory=list)

    def ancestors(self):
        node = self.parent
        while node is not None:
            yield node
            node = node.parent


def _terms(position: Sequence[sp.Expr]) -> tuple[frozenset, ...]:
    return tuple(frozenset(a for a in sp.Add.make_args(c) if a != 0) for c in position)


def particle_chains(particles: Sequence[Particle], q, q_dot, t,
                    d: Differentiator) -> list[_Segment]:
    """The chain segments, parents before children; empty when no particle extends another
    (nothing to gain), so those particles go the particle-by-particle way."""
    fixed = {t, *q, *q_dot}
    moving = {t, *q_dot}
    eligible = [p for p in particles
                if not d.free_symbols(p.mass) & fixed
                and not any(d.free_symbols(c) & moving for c in p.position)]
    index = {x: k for k, x in enumerate(q)}
    order = sorted(eligible, key=lambda p: sum(len(s) for s in _terms(p.position)))
    segments: list[_Segment] = []
    for particle in order:
        terms = _terms(particle.position)
        size = sum(len(s) for s in terms)
        parent = None
        for candidate in reversed(segments):  # the deepest first
            whole = candidate.full
            if sum(len(s) for s in whole) < size and all(
                    a <= b for a, b in zip(whole, terms, strict=True)):
                parent = candidate
                break
        own = terms if parent is None else tuple(
            b - a for a, b in zip(parent.full, terms, strict=True))
        present = frozenset().union(*(d.free_symbols(x) for s in own for x in s))
        coordinates = tuple(sorted(index[x] for x in present if x in index))
        above = parent.path_coordinates if parent is not None else frozenset()
        if above & set(coordinates):
            continue  # a coordinate twice on one path: the particle-by-particle way
        segments.append(_Segment(particle, parent, own, terms, coordinates,
                                 above | set(coordinates)))
    if all(s.parent is None for s in segments):
        return []
    for segment in segments:
        for node in (segment, *segment.ancestors()):
            node.masses.append(segment.particle.mass)
    return segments


def add_chain_inertia(segments: Sequence[_Segment], acc, d: Differentiator, q, q_dot, t,
                      gravity) -> None:
    """Add the chain's m J^T J to M, -m J^T a_rest and the weight's m g d . J to f."""
    columns, rests = {}, {}
    for s in segments:
        delta = [sp.Add(*c) for c in s.terms]
        jacobian = [d.row(c, q) for c in delta]
        columns[id(s)] = {a: tuple(row[a] for row in jacobian) for a in s.coordinates
                          if any(row[a] != 0 for row in jacobian)}
        velocity = [sp.Add(*(j * v for j, v in zip(row, q_dot, strict=True) if j != 0))
                    for row in jacobian]
        rests[id(s)] = [d.rate(v, q, q_dot, t) for v in velocity]
    negated = {m: -m for s in segments for m in s.masses}
    for s in segments:
        own = columns[id(s)]
        if gravity is not None:
            for a, column in own.items():
                lever = sp.Add(*(dc * x for dc, x in zip(gravity.direction, column, strict=True)
                                 if dc != 0 and x != 0))
                if lever != 0:
                    acc.forcing[a][gravity.magnitude * lever].extend(s.masses)
        negative = [negated[m] for m in s.masses]
        for w in (s, *s.ancestors()):  # the pair (w, s), s the deeper: the masses beyond s
            for a, column_a in columns[id(w)].items():
                for b, column_b in own.items():
                    if w is s and b < a:
                        continue
                    i, j = (a, b) if a <= b else (b, a)
                    first, second = (column_a, column_b) if a <= b else (column_b, column_a)
                    dot = acc._dot(first, second)
                    if dot != 0:
                        acc.mass[i][j][dot].extend(s.masses)
                        acc._collected.pop((i, j), None)
            # f_a -= m J_a . a_rest over the pairs: a on w with the rest of s, and a on s
            # with the rest of w (once when w is s).
            for a, column in columns[id(w)].items():
                for term in acc._projection(column, rests[id(s)]):
                    acc.forcing[a][term].extend(negative)
            if w is not s:
                for a, column in own.items():
                    for term in acc._projection(column, rests[id(w)]):
                        acc.forcing[a][term].extend(negative)


__all__ = ["add_chain_inertia", "particle_chains"]
