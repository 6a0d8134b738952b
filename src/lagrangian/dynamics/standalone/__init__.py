"""Exports of a robot's dynamics to other code: standalone C99 (its dynamics, frames and control
laws) and CasADi Functions (casadi_tree.py: the numpy reference's recursions over casadi SX)."""
