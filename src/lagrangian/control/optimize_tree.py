"""Collocation on a tree whose q and v differ in length (a ball joint, an MJCF free joint's
ball, a URDF floating joint between links, a floating base): the start named as simulate's
(tree_state.TreeState: a ball's <ball>_qw .. _qz and <ball>_wx .. _wz), and each unit
quaternion kept on |q| = 1 at the nodes by a multiplier mu along q in its defect,

    q_{k+1} - q_k - h/2 (q_dot_k + q_dot_{k+1}) - mu_k q_{k+1} = 0,  |q_{k+1}|^2 = 1,

the projection of the scheme's step back onto the sphere (mu is of the scheme's order h^3;
|mu| <= 1/2 keeps out the other root, mu near 2, where q_{k+1} is the step's opposite).
"""

from __future__ import annotations

from collections.abc import Mapping
from types import SimpleNamespace

import numpy as np

from ..compile.casadi_functions import CasadiFunctions
from ..errors import InputError, ModelError
from ..model.model import Model
from ..model.quaternions import QUATERNION_TOLERANCE


def on_manifold(model: Model) -> bool:
    """Whether the model's tree has a quaternion (its base's or a joint's)."""
    tree = model.kinematic_tree
    return tree is not None and (tree.floating_base or bool(tree.quaternion_joints))


def _state(model: Model, functions: CasadiFunctions):
    from ..dynamics.tree.free_flyer import BASE_VELOCITY
    from ..simulation.tree_state import TreeState

    tree = model.kinematic_tree
    base = BASE_VELOCITY if tree.floating_base else ()
    # the tree's names as the dynamics give them (a hinge's rate by its coordinate's name)
    names = SimpleNamespace(coordinates=functions.configuration,
                            velocity_names=(*base, *tree.velocity_coordinates))
    return TreeState(names, model)


def quaternions(model: Model, functions: CasadiFunctions) -> list[tuple[str, list[int]]]:
    """Each unit quaternion of x = [q; v]: (what it turns, as 'base quaternion (base_qx, ..)'
    or "joint 'shoulder' quaternion (shoulder_qw, ..)", and its four rows)."""
    state = _state(model, functions)
    starts = [("base", 3)] if state.floating else []
    starts += [(f"joint '{name}'", iq) for name, iq, _ in state.balls]
    starts += [(f"joint '{name}'", iq + 3) for name, iq, _ in state.free]
    names = functions.configuration
    return [(f"{what} quaternion ({', '.join(names[i:i + 4])})", list(range(i, i + 4)))
            for what, i in starts]


def tree_start(model: Model, functions: CasadiFunctions,
               start: Mapping[str, float] | None) -> dict[int, float]:
    """Every entry of x(0) (index -> SI value) from ``start`` named as simulate's initial (the
    base at the origin, each ball unturned, at rest; the other joints at the model's initial
    values); a quaternion off unit norm refused in one line naming it."""
    state = _state(model, functions)
    given = {str(k): v for k, v in dict(start or {}).items()}
    try:
        _, q0, v0 = state.start(model, given)
    except ModelError as exc:  # simulate's words, this argument's name
        raise InputError(exc.message, field="start") from None
    velocities = functions.velocities
    rates = [v0[state.v_names.index(n.removesuffix("_dot"))] if n not in state.v_names
             else v0[state.v_names.index(n)] for n in velocities]
    return dict(enumerate([*map(float, q0), *map(float, rates)]))


def refuse_hinges(model: Model, functions: CasadiFunctions, values, field: str) -> None:
    """One line for a ball's Euler hinge (or a floating joint's roll, pitch, yaw) named where
    the state's numbers are wanted, naming the numbers to give instead."""
    state = _state(model, functions)
    for key in dict(values or {}):
        if str(key) not in functions.states:
            state.refuse_hinge(str(key), field)


def check_goal(target: dict[int, float], rows: list[tuple[str, list[int]]]) -> None:
    """A goal quaternion named in full is of unit norm."""
    for names, indices in rows:
        if all(i in target for i in indices):
            norm = float(np.sqrt(sum(target[i] ** 2 for i in indices)))
            if abs(norm - 1.0) > QUATERNION_TOLERANCE:
                raise InputError(f"the {names} has norm {norm:.9g}: a unit quaternion is "
                                 "needed", field="goal")


def unit_guess(guess: np.ndarray, rows: list[tuple[str, list[int]]]) -> np.ndarray:
    """The straight-line guess with each quaternion scaled back to norm 1 (nlerp)."""
    for _, indices in rows:
        norm = np.linalg.norm(guess[indices], axis=0)
        guess[indices] /= np.where(norm > 1e-12, norm, 1.0)
    return guess


def project(ca, opti, X, defect, rows, target, nodes: int):
    """The defect (n2, nodes - 1) with mu q_{k+1} taken off each quaternion's rows, and
    |q_{k+1}|^2 = 1 where the goal does not fix all four numbers (there it holds already)."""
    if not rows:
        return defect
    mu = opti.variable(len(rows), nodes - 1)
    opti.set_initial(mu, 0.0)
    # (1 - mu) q_{k+1} = the step: mu near 0 is the step scaled back onto the sphere; near 2
    # it is the step turned to -q_{k+1}, the same rotation with the rate's sign flipped, a
    # branch that is no solution of the dynamics (the optimizer would use it): kept out
    opti.subject_to(opti.bounded(-0.5, ca.vec(mu), 0.5))
    shift = [ca.DM.zeros(1, nodes - 1)] * X.shape[0]
    for j, (_, indices) in enumerate(rows):
        for i in indices:
            shift[i] = mu[j, :] * X[i, 1:]
        norm = ca.sum1(X[indices, 1:] ** 2)
        fixed = all(i in target for i in indices)
        opti.subject_to(ca.vec(norm[:, :-1] if fixed else norm) == 1)
    return defect - ca.vertcat(*shift)


__all__ = ["check_goal", "on_manifold", "project", "quaternions", "refuse_hinges", "tree_start",
           "unit_guess"]
