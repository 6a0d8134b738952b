"""The layout of a system's state vectors: the names of q's entries and of v's, in order (on a
floating base q holds the base's position and unit quaternion, 7 numbers, and v its twist, 6),
and the numbers a floating base takes by default (at the world's origin, unturned, at rest)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class StateLayout:
    """Names of q's and v's entries in order; ``base_q``/``base_v`` a floating base's default
    numbers before the joints' (empty for a fixed base)."""

    q: tuple[str, ...]
    v: tuple[str, ...]
    base_q: tuple[float, ...] = ()
    base_v: tuple[float, ...] = ()

    @property
    def floating(self) -> bool:
        """Whether q and v hold a floating base's numbers first."""
        return bool(self.base_q)

    def names(self, vector: str) -> tuple[str, ...]:
        """The names of ``vector``'s entries: "q" (coordinates), else v's (velocities,
        accelerations and generalized forces share v's layout)."""
        return self.q if vector == "q" else self.v

    def expected(self, vector: str, given: int) -> str | None:
        """None when ``given`` entries fit ``vector``, else one line naming what is expected:
        "expected 8 comma-separated values (panda_joint1, ..., panda_finger_joint1), got 7"."""
        names = self.names(vector)
        if given == len(names):
            return None
        return (f"expected {len(names)} comma-separated values ({', '.join(names)}), "
                f"got {given}")


def state_layout(system) -> StateLayout:
    """The StateLayout of ``system`` (a floating base's names from its dynamics: the base's
    x, y, z, qx, qy, qz, qw then the joints in q; vx, vy, vz, wx, wy, wz then the joint rates
    in v; a ball joint's <ball>_qw, _qx, _qy, _qz in q and <ball>_wx, _wy, _wz in v; a free
    flyer below the root <joint>_x .. _qw in q and <joint>_vx .. _wz in v)."""
    joints = tuple(c.name for c in system.model.coordinates)
    tree = system.model.kinematic_tree
    floating = getattr(tree, "floating_base", False)
    if not floating and not getattr(tree, "quaternion_joints", ()):  # ball, free flyer
        return StateLayout(joints, joints)
    f = system.dynamics()  # a ball joint's quaternion and angular velocity (not Euler hinges)
    return StateLayout(tuple(f.coordinates), tuple(f.velocity_names),
                       *(((0.0,) * 6 + (1.0,), (0.0,) * 6) if floating else ()))
