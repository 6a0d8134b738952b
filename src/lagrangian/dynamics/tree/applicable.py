"""Whether a model is a bare kinematic tree: the tree that describes its whole dynamics (a URDF
robot not edited since, or a model file's rigid bodies on joints), which the recursive paths
(recursive.py, the standalone export) run without deriving anything."""

from __future__ import annotations

from collections.abc import Mapping

from ...model.model import Model
from ...model.tree import KinematicTree, body_tree

# A model file's tree of at least this many bodies runs the recursions (numbers, simulation,
# modes): below it the derived equations compile quickly and print as the user wrote them.
TREE_PATH_BODIES = 6


def applicable_tree(model: Model, parameters: Mapping[str, float] | None = None
                    ) -> KinematicTree | None:
    """The model's kinematic tree when it describes the model's whole dynamics (a robot read
    from URDF and not edited since: only its rigid bodies, gravity and the actuator forces; or
    a model file's rigid bodies on revolute and prismatic joints, in numbers at ``parameters``
    over the model's values), else None, so that nothing else a model holds is ever left out."""
    tree = model.kinematic_tree
    if tree is None:
        if not model.rigid_bodies or any(b.joint is None for b in model.rigid_bodies):
            return None
        from ...model.values import resolve_parameters

        values = resolve_parameters(model, parameters, require=False)
        if any(v is None for v in values.values):
            return None
        # built from the model itself: its bodies, gravity and forces are checked there
        return body_tree(model, dict(zip((p.symbol for p in model.parameters), values.values,
                                         strict=True)))
    if (model.particles or model.bodies or model.springs or model.dampers or model.loads
            or model.constraints or model.definitions
            or model.kinetic_energy != 0 or model.potential_energy != 0
            or model.dissipation != 0):
        return None
    if model.rigid_bodies != tree.rigid_bodies:
        return None
    # an MJCF ball joint: three hinge angles in the model's symbolic bodies, a quaternion here
    if tuple(c.name for c in model.coordinates) != (tree.model_coordinates or tree.coordinates):
        return None
    names = {p.name: p.symbol for p in model.parameters}
    if any(a is not None and a not in names
           for a in (tree.gravity_parameter, *tree.actuators)):
        return None
    gravity = model.gravity
    if (gravity is None) != (tree.gravity_parameter is None):
        return None
    if gravity is not None and (gravity.magnitude != names[tree.gravity_parameter] or
                                tuple(float(d) for d in gravity.direction)
                                != tree.gravity_direction):
        return None
    expected = {c: ((names[a]),) for c, a in zip(tree.velocity_coordinates, tree.actuators,
                                                 strict=True) if a is not None}
    given: dict[str, tuple] = {}
    for coordinate, force in model.generalized_forces:
        given[coordinate] = given.get(coordinate, ()) + (force,)
    if given != expected:
        return None
    return tree


__all__ = ["TREE_PATH_BODIES", "applicable_tree"]
