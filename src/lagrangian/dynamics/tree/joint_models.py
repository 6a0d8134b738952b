"""Joint models of a kinematic tree, keyed by JointKind (Pinocchio's JointModel family): how a
joint places its body and the motion subspace S = (s_w, s_v) that one unit of joint rate gives it.

The recursions (tree_algorithms for generated code, recursive_numpy for numpy) never ask which
kind a joint is: they use S and the placement. A one-degree-of-freedom joint is one entry of
JOINT_MODELS (and its branch in each C kernel: tree_kernel.c's tk_place and tk_subspace,
reach_kernel.c's body and subspace, derivatives_kernel.c's kinematics), not a branch in every
algorithm. The helical joint (a screw, Pinocchio's JointModelHelicalUnaligned) turns and
slides: S = (u, pitch u), pitch (m/rad) the joint's own number (TreeJoint.pitch). The free
flyer (free_flyer.py) and the ball joint (spherical.py, MuJoCo's: a quaternion w x y z, three
angular rates in its body's axes) are entries of several numbers, walked by their own branches."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ...errors import ModelError
from ...kinds import JointKind
from .free_flyer import FreeFlyerModel
from .spherical import SphericalModel


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
    ``slides``: the body slides along u by the joint variable (m), or by pitch times it where
    ``pitched`` (a helical joint: it turns and slides by one variable)."""

    kind: JointKind
    turns: bool
    slides: bool
    nq: int = 1  # configuration numbers (a free flyer's: 7, free_flyer.py)
    nv: int = 1  # velocity numbers
    pitched: bool = False  # the slide is pitch * theta (m/rad): the joint's pitch is needed

    def lead(self, pitch: float | None = None) -> float:
        """The slide per unit of the joint variable: 1 for a prismatic joint (m/m), the pitch
        for a helical one (m/rad), 0 for one that does not slide. A pitched kind without its
        pitch is refused by name (a caller that knows only the unpitched kinds)."""
        if not self.slides:
            return 0.0
        if not self.pitched:
            return 1.0
        if pitch is None:
            raise ModelError(f"a {self.kind} joint slides by its pitch times its angle: this "
                             "algorithm was not given the joint's pitch", field="joint")
        return float(pitch)

    def subspace(self, axis, pitch: float | None = None) -> tuple[list | None, list | None]:
        """S = (s_w, s_v): angular and linear velocity of the body per unit rate (None: zero);
        ``pitch`` the joint's (TreeJoint.pitch), needed by a helical joint."""
        u = list(axis)
        if not self.slides:
            return (u if self.turns else None), None
        lead = self.lead(pitch)
        return (u if self.turns else None), (u if lead == 1.0 else [lead * x for x in u])

    def placement_terms(self, E: _Terms, joint, theta, rotation):
        """The body's rotation R (body -> parent) and origin p (m) in its parent, as terms;
        ``rotation(E, joint, cos, sin)`` is Rot(u, theta)."""
        R0 = [list(row) for row in joint.rotation]
        R, p = R0, list(joint.translation)
        if self.turns:
            sin, cos = E.sincos(theta)
            R = E.matmul(R0, rotation(E, joint, cos, sin))
        if self.slides:
            lead = self.lead(getattr(joint, "pitch", None))
            axis = joint.axis if lead == 1.0 else [lead * x for x in joint.axis]
            p = E.vadd(p, E.scale(theta, E.apply(R0, axis)))
        return R, p

    def placement_arrays(self, R0, t0, u, theta, pitch: float | None = None):
        """R (N, 3, 3) or (3, 3) and p (N, 3) or (3,) for joint values theta (N,), in numpy;
        ``pitch`` the joint's, needed by a helical joint."""
        R, p = R0, t0
        if self.turns:
            c, s = np.cos(theta)[:, None, None], np.sin(theta)[:, None, None]
            uu = np.outer(u, u)
            skew = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
            R = R0 @ (uu + c * (np.eye(3) - uu) + s * skew)  # Rot(u, theta)
        if self.slides:
            p = t0 + (self.lead(pitch) * theta)[:, None] * (R0 @ u)
        return R, p


# the joints of one coordinate each (the compiled kernel of reach_c.py takes only these)
ONE_DOF = (JointKind.REVOLUTE, JointKind.PRISMATIC, JointKind.HELICAL)


JOINT_MODELS: dict[JointKind, JointModel | FreeFlyerModel | SphericalModel] = {
    JointKind.REVOLUTE: JointModel(JointKind.REVOLUTE, turns=True, slides=False),
    JointKind.PRISMATIC: JointModel(JointKind.PRISMATIC, turns=False, slides=True),
    # a screw: Rot(u, theta) and pitch * theta along u (S = (u, pitch u), pitch in m/rad)
    JointKind.HELICAL: JointModel(JointKind.HELICAL, turns=True, slides=True, pitched=True),
    # a floating base at a tree's root (numpy and the engine), or a URDF floating joint below it
    # (numpy, the engine and the generated code: emit/tree_floating.py's several_*)
    JointKind.FREE_FLYER: FreeFlyerModel(),
    # a ball joint (MuJoCo's): a quaternion w x y z, the angular velocity in the body's axes
    # (spherical.py); numpy, the engine and the generated code (emit/tree_floating.py)
    JointKind.SPHERICAL: SphericalModel(),
}


def joint_model(kind: JointKind) -> JointModel | FreeFlyerModel | SphericalModel:
    """The model of a joint kind that a kinematic tree can move."""
    try:
        return JOINT_MODELS[JointKind(kind)]
    except KeyError:
        raise ModelError(f"a kinematic tree moves a body by a one-degree-of-freedom joint "
                         f"({', '.join(JOINT_MODELS)}), not a {kind} joint "
                         "(fixed joints are merged into their parent)", field="joint") from None
