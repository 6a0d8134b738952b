"""An impact's relabelling checked against the geometry: the coordinates after it, R(q), must
place every particle and body where the impact left them (as a set: a walker's legs swap), and
with a released pivot about the striking point as the new pivot at the origin:

    {r_i(R(q))} = {r_i(q) - r_strike(q)}   (bodies' angles the same),

so a relabelling that does not describe the same configuration is refused, never run.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import sympy as sp

from ..compile.lambdified import StateFunction
from ..errors import InputError

TOLERANCE = 1e-8  # m (and for an angle's cosine and sine), times max(1, the model's size)


class RelabelCheck:
    """Where each particle and body is (and each planar body's cos, sin of its angle), and
    the striking point, as numbers; ``__call__(q, t)`` refuses a relabelling that moves them."""

    def __init__(self, model, impact_map, substitution: Mapping):
        impact = impact_map.impact
        self.name = impact.name
        self.released = bool(impact_map.extension)
        d = impact_map.normal.shape[0]
        rows, self.masses, self.labels, self.turns = [], [], [], []
        for kind, items in (("particle", model.particles), ("body", model.bodies),
                            ("body", model.rigid_bodies)):
            for item in items:
                rows += list(item.position[:d])
                turned = kind == "body" and hasattr(item, "angle")
                rows += [sp.cos(item.angle), sp.sin(item.angle)] if turned else [0, 0]
                # a particle's or body's mass: the reader's parsed expression, never text
                self.masses.append(float(sp.sympify(item.mass).xreplace(substitution)))  # safe
                self.labels.append(f"{kind} '{item.name}'")
        self.d = d
        rows += list(impact.point[:d])
        self._where = StateFunction(model, rows, substitution)
        self._relabelled = StateFunction(model, list(impact_map.relabelled), substitution)

    def __call__(self, q, t) -> None:
        n, d = len(q), self.d
        zeros = np.zeros(n)
        before = self._where.at(q, zeros, t)
        after = self._where.at(self._relabelled.at(q, zeros, t), zeros, t)
        width = d + 2
        count = len(self.masses)
        strike = before[count * width:]
        old = before[:count * width].reshape(count, width)
        new = after[:count * width].reshape(count, width)
        if self.released:
            old[:, :d] -= strike
        scale = max(1.0, float(np.max(np.abs(old), initial=0.0)))
        free = list(range(count))
        for i in range(count):
            match = [j for j in free if abs(self.masses[j] - self.masses[i]) <=
                     1e-12 * max(1.0, abs(self.masses[i]))
                     and float(np.max(np.abs(new[i] - old[j]))) <= TOLERANCE * scale]
            if not match:
                where = ", about the striking point as the new pivot" if self.released else ""
                raise InputError(
                    f"impact '{self.name}': after its relabelling the {self.labels[i]} is not "
                    f"where the impact left any part of the model{where}: the relabelling "
                    "must describe the same configuration", field="impacts")
            free.remove(match[0])


__all__ = ["RelabelCheck"]
