"""Joint models of a kinematic tree, keyed by JointKind (Pinocchio's JointModel family): how a
joint places its body and the motion subspace S = (s_w, s_v) that one unit of joint rate gives it.

The recursions (tree_algorithms for generated code, recursive_numpy for numpy) never ask which
kind a joint is: they use S and the placement. A new one-degree-of-freedom joint (a helical
joint: S = (u, pitch u)) is one entry of JOINT_MODELS, not a branch in every algorithm."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ...errors import ModelError
from ...kinds import JointKind
from .free_flyer import FreeFlyerModel


class _Terms(Protocol):  # the emitter's arithmetic (tree_emitter._Emitter)
    def matmul(self, A, B): ...
    def vadd(self, a, b): ...
    def scale(self, s, a): ...
    def apply(self, R, x): ...
    def sincos(self, angle): ...


@dataclass(frozen=True)
class JointModel:
    """One kind of one-degree-of-freedom joint: its motion subspace per unit rate, in joint axes.

    ``turns``: the body turns about the axis u by the joint variable (rad);
    ``slides``: the body slides along u by the joint variable (m)."""

    kind: JointKind
    turns: bool
    slides: bool
    nq: int = 1  # configuration numbers (a free flyer's: 7, free_flyer.py)
    nv: int = 1  # velocity numbers

    def subspace(self, axis) -> tuple[list | None, list | None]:
        """S = (s_w, s_v): angular and linear velocity of the body per unit rate (None: zero)."""
        u = list(axis)
        return (u if self.turns else None), (u if self.slides else None)

    def placement_terms(self, E: _Terms, joint, theta, rotation):
        """The body's rotation R (body -> parent) and origin p (m) in its parent, as terms;
        ``rotation(E, joint, cos, sin)`` is Rot(u, theta)."""
        R0 = [list(row) for row in joint.rotation]
        R, p = R0, list(joint.translation)
        if self.turns:
            sin, cos = E.sincos(theta)
            R = E.matmul(R0, rotation(E, joint, cos, sin))
        if self.slides:
            p = E.vadd(p, E.scale(theta, E.apply(R0, joint.axis)))
        return R, p

    def placement_arrays(self, R0, t0, u, theta):
        """R (N, 3, 3) or (3, 3) and p (N, 3) or (3,) for joint values theta (N,), in numpy."""
        R, p = R0, t0
        if self.turns:
            c, s = np.cos(theta)[:, None, None], np.sin(theta)[:, None, None]
            uu = np.outer(u, u)
            skew = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
            R = R0 @ (uu + c * (np.eye(3) - uu) + s * skew)  # Rot(u, theta)
        if self.slides:
            p = t0 + theta[:, None] * (R0 @ u)
        return R, p


# the joints of one coordinate each (the compiled kernel of reach_c.py takes only these)
ONE_DOF = (JointKind.REVOLUTE, JointKind.PRISMATIC)


JOINT_MODELS: dict[JointKind, JointModel | FreeFlyerModel] = {
    JointKind.REVOLUTE: JointModel(JointKind.REVOLUTE, turns=True, slides=False),
    JointKind.PRISMATIC: JointModel(JointKind.PRISMATIC, turns=False, slides=True),
    # a floating base: only at a tree's root, and only in numpy and frames.py (recursive.py)
    JointKind.FREE_FLYER: FreeFlyerModel(),
}


def joint_model(kind: JointKind) -> JointModel | FreeFlyerModel:
    """The model of a joint kind that a kinematic tree can move."""
    try:
        return JOINT_MODELS[JointKind(kind)]
    except KeyError:
        raise ModelError(f"a kinematic tree moves a body by a one-degree-of-freedom joint "
                         f"({', '.join(JOINT_MODELS)}), not a {kind} joint "
                         "(fixed joints are merged into their parent)", field="joint") from None
