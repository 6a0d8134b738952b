"""The impact map, derived: integrating Lagrange's equations over the instant of an impact gives
M(q) (q_dot+ - q_dot-) = J^T Lambda, with the striking point's velocity after it set by the law:

    [M  -J^T] [q_dot+]   [M q_dot-    ]
    [J    0 ] [Lambda] = [-E J q_dot- ]

J = dr/dq of the striking point: its normal row n^T dr/dq for "slip" (E = e), all its rows for
"stick" (E = e n n^T: the normal velocity reversed and scaled by e, the tangential one stopped).
Lambda is the impulse on the model at the point (N s; along n for slip). A model pinned at the
world origin whose pivot releases (a walker's stance foot) is extended by the pivot's free
offset p (every point moves with p_dot): the map is solved in (p, q) with p_dot- = 0 and the q
part kept; ``relabel`` then gives the coordinates after the impact, q' = R(q), q_dot' = dR/dq q_dot.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..errors import ModelError
from ..model.impacts import Impact
from .equations import EquationsOfMotion


@dataclass(frozen=True)
class ImpactMap:
    """One impact's map in symbols: the guard g(q, t) and its gradient, the mass matrix M (of
    (p, q) where the pivot releases: ``extension`` extra leading rows), the rows J of the
    striking point's velocity the law sets, the matrix E with J q_dot+ = -E J q_dot-, and the
    coordinates after it R(q) with their Jacobian dR/dq. Units SI."""

    impact: Impact
    extension: int  # dimensions of the released pivot's offset p (0 without release)
    mass_matrix: sp.ImmutableMatrix  # (extension + n) square, in q
    jacobian: sp.ImmutableMatrix  # rows of the point's velocity set by the law, (k, extension + n)
    restitution_matrix: sp.ImmutableMatrix  # E, (k, k)
    point_velocity: sp.ImmutableMatrix  # dr/dq_e, (d, extension + n): the point's velocity rows
    normal: sp.ImmutableMatrix  # n, (d, 1)
    guard: sp.Expr
    guard_gradient: sp.ImmutableMatrix  # dg/dq, (n, 1)
    relabelled: sp.ImmutableMatrix  # R(q), (n, 1)
    relabel_jacobian: sp.ImmutableMatrix  # dR/dq, (n, n)

    @property
    def name(self) -> str:
        return self.impact.name


def derive_impact_maps(eom: EquationsOfMotion) -> tuple[ImpactMap, ...]:
    """Every impact of ``eom``'s model, its map derived (an empty tuple without impacts)."""
    return tuple(derive_impact_map(eom, impact) for impact in eom.model.impacts)


def derive_impact_map(eom: EquationsOfMotion, impact: Impact) -> ImpactMap:
    """The map of ``impact`` (model/impacts.py) from the equations' mass matrix and the
    striking point's Jacobian."""
    model = eom.model
    field = f"impact '{impact.name}'"
    if model.constraints:
        raise ModelError("impacts are derived for models without constraints (write the "
                         "pinned points by their coordinates; the pivot may release)",
                         field=field, source=model.source)
    q = sp.Matrix(model.q)
    dimension = 3 if any(c != 0 for c in (*impact.point[2:], *impact.normal[2:])) or \
        _spatial(model) else 2
    point = sp.Matrix(impact.point[:dimension])
    normal = sp.Matrix(impact.normal[:dimension])
    mass = sp.Matrix(eom.mass_matrix)
    rows = point.jacobian(q)
    extension = 0
    if "pivot" in impact.release:
        mass, extension = _extended_mass(eom, dimension, field), dimension
        rows = sp.Matrix.hstack(sp.eye(dimension), rows)
    e = impact.restitution
    if impact.tangential == "stick":
        jacobian = rows
        restitution = e * normal * normal.T
    else:
        jacobian = normal.T * rows
        restitution = sp.Matrix([[e]])
    relabel = dict(impact.relabel)
    new = sp.Matrix([relabel.get(c.name, c.symbol) for c in model.coordinates])
    g = impact.guard
    return ImpactMap(
        impact=impact, extension=extension, mass_matrix=sp.ImmutableMatrix(mass),
        jacobian=sp.ImmutableMatrix(jacobian), restitution_matrix=sp.ImmutableMatrix(restitution),
        point_velocity=sp.ImmutableMatrix(rows), normal=sp.ImmutableMatrix(normal), guard=g,
        guard_gradient=sp.ImmutableMatrix([g.diff(s) for s in q]),
        relabelled=sp.ImmutableMatrix(new), relabel_jacobian=sp.ImmutableMatrix(new.jacobian(q)))


def _spatial(model) -> bool:
    points = [p.position for p in model.particles] + [b.position for b in model.bodies] + \
        [b.position for b in model.rigid_bodies]
    return bool(model.rigid_bodies) or any(r[2] != 0 for r in points)


def _extended_mass(eom: EquationsOfMotion, dimension: int, field: str) -> sp.Matrix:
    """M of (p, q) for the model moved rigidly by the pivot offset p: every centre of mass r_i
    moves by p, so T gains 1/2 m_total |p_dot|^2 + p_dot . sum m_i dr_i/dq q_dot."""
    model = eom.model
    if model.kinetic_energy != 0:
        raise ModelError("a released pivot needs the kinetic energy from particles and bodies "
                         "(an [energy] T cannot be moved with the pivot)", field=field,
                         source=model.source)
    q = sp.Matrix(model.q)
    masses = [(c.mass, sp.Matrix(c.position[:dimension]))
              for c in (*model.particles, *model.bodies, *model.rigid_bodies)]
    if not masses:
        raise ModelError("a released pivot needs particles or bodies", field=field,
                         source=model.source)
    total = sp.Add(*(m for m, _ in masses))
    coupling = sp.zeros(dimension, len(q))
    for m, r in masses:
        coupling += m * r.jacobian(q)
    top = sp.Matrix.hstack(total * sp.eye(dimension), coupling)
    bottom = sp.Matrix.hstack(coupling.T, sp.Matrix(eom.mass_matrix))
    return sp.Matrix.vstack(top, bottom)


__all__ = ["ImpactMap", "derive_impact_map", "derive_impact_maps"]
