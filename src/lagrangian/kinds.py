"""The kinds and states the package names, as string enums: each compares equal to its
string (JSON, files and messages keep the same words), and a typo is an AttributeError, not a
comparison that is silently never true."""

from __future__ import annotations

from enum import StrEnum


class JointKind(StrEnum):
    """How a joint moves its body, in model files and URDF alike: about its axis (revolute),
    along it (prismatic), by a rotation sequence (spherical: in a kinematic tree a ball joint,
    MuJoCo's, by a unit quaternion w x y z and the angular velocity in the child's axes), not
    at all (fixed) or freely in space (free_flyer: a URDF robot's floating base), or about and
    along its axis at once (helical: a screw, turning theta and sliding pitch * theta; the
    Python tree builder's, model/robot_builder.py), or MuJoCo's free joint (free: three
    prismatic joints along the world's axes and a ball, MuJoCo's qpos/qvel exactly; an MJCF
    robot's, model/mjcf_free.py). A kinematic tree moves its bodies by the
    one-degree-of-freedom kinds, ball joints and free flyers (at its root, a floating base; or
    below it, a URDF floating joint between two links) (dynamics/tree/joint_models.py)."""

    REVOLUTE = "revolute"
    PRISMATIC = "prismatic"
    SPHERICAL = "spherical"
    FIXED = "fixed"
    # a URDF robot's floating base (dynamics/tree/free_flyer.py): six degrees of freedom, in a tree
    # only (a model file's body moves by its coordinates)
    FREE_FLYER = "free_flyer"
    # a screw (Pinocchio's JointModelHelicalUnaligned): in a tree only, made by
    # lagrangian.RobotBuilder (URDF and model files have none)
    HELICAL = "helical"
    # MuJoCo's free joint (MJCF <freejoint>) in MuJoCo's layout: q = [x y z (world), qw qx qy qz],
    # v = [origin velocity in world axes, angular velocity in body axes]. Never a tree joint's
    # kind: expanded when the tree is built into three prismatic joints along the world's axes
    # and a spherical joint at their end, which every backend moves (model/mjcf_free.py)
    FREE = "free"


class ConstraintKind(StrEnum):
    """Phi(q, t) = 0 (holonomic) or A(q, t) q_dot + b(q, t) = 0 (velocity)."""

    HOLONOMIC = "holonomic"
    VELOCITY = "velocity"


class LoadStepKind(StrEnum):
    """What a step of derive --steps finds the virtual work of: a point force, a torque, a moment
    on a body in space, a damper, the dissipation function D, or generalized forces given."""

    FORCE = "force"
    TORQUE = "torque"
    MOMENT = "moment"
    DAMPER = "damper"
    DISSIPATION = "dissipation"
    GIVEN = "given"


class FindingStatus(StrEnum):
    """The verdict on one item of a checked answer: as ours, equal to ours in another form,
    wrong, or a note that judges nothing."""

    CORRECT = "correct"
    EQUIVALENT = "equivalent"
    WRONG = "wrong"
    NOTE = "note"


class DistributionKind(StrEnum):
    """How an ensemble draws a parameter: normal(mean, standard deviation) or uniform(low, high)."""

    NORMAL = "normal"
    UNIFORM = "uniform"


class FreeBodyKind(StrEnum):
    """What a free body of the Newton-Euler check is: a particle (m a = F), a planar body (and
    I alpha = M), or a body in space (Euler's equations)."""

    PARTICLE = "particle"
    BODY = "body"
    BODY_IN_SPACE = "body in space"


class ModeKind(StrEnum):
    """How a mode moves: oscillating, overdamped (real eigenvalues, zeta >= 1), rigid-body (zero
    frequency, neutral) or divergent (grows without oscillating)."""

    OSCILLATING = "oscillating"
    OVERDAMPED = "overdamped"
    RIGID_BODY = "rigid-body"
    DIVERGENT = "divergent"


class CrossingKind(StrEnum):
    """Which eigenvalues cross Re = 0 as the speed changes: a complex pair (a bicycle's weave) or
    a real one (its capsize)."""

    OSCILLATORY = "oscillatory"
    REAL = "real"


class InvariantKind(StrEnum):
    """What a run monitors: T + V, the Jacobi integral h, or the work balance h - h0 - int P dt."""

    ENERGY = "energy"
    JACOBI_INTEGRAL = "jacobi_integral"
    WORK_BALANCE = "work_balance"


class RunStatus(StrEnum):
    """How a simulation ended."""

    FINISHED = "finished"
    STOPPED = "stopped"
    LIMIT = "limit"  # a joint reached its URDF position limit (simulate's limits)
    INTERRUPTED = "interrupted"
    FAILED = "failed"


class Backend(StrEnum):
    """Where the numeric functions run: generated C, numpy, or C when a compiler works."""

    AUTO = "auto"
    C = "c"
    NUMPY = "numpy"


__all__ = ["Backend", "ConstraintKind", "CrossingKind", "DistributionKind", "FindingStatus",
           "FreeBodyKind", "InvariantKind", "JointKind", "LoadStepKind", "ModeKind", "RunStatus"]
