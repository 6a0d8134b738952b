"""lagrangian.RobotBuilder: a robot's links and joints described in Python
(model/robot_builder.py), built into a System as load(urdf) gives one."""

from __future__ import annotations

from ..model.robot_builder import KINDS, RobotTree
from .system import System


class RobotBuilder(RobotTree):
    """Describe a robot's kinematic tree from Python; ``build()`` returns a :class:`System`.

    >>> import lagrangian
    >>> b = lagrangian.RobotBuilder("screw")
    >>> _ = b.link("base").link("nut", mass=1.0, inertia=(0.01, 0.01, 0.02))
    >>> _ = b.joint("lead", "helical", "base", "nut", axis=(0, 0, 1), pitch=0.005)
    >>> b.build().dynamics().mass_matrix([0.0]).round(6)
    array([[0.020025]])
    """

    def build(self, floating_base: bool = False) -> System:
        """The robot as a System (its dynamics on the tree: ``system.dynamics()``); the root
        link fixed to the world unless ``floating_base``."""
        return System(self.build_model(floating_base))


__all__ = ["KINDS", "RobotBuilder"]
