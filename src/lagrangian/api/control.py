"""System's methods for control: linearization along a run (the rest of the control API is
lagrangian.control's controllers, taken by System.simulate)."""

from __future__ import annotations


class ControlMethods:
    """Mixed into System (api/system.py)."""
