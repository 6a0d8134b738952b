"""lagrangian: equations of motion by Lagrange's method, from energies or components.

>>> import lagrangian
>>> system = lagrangian.load("pendulum")
>>> system.equations_of_motion().equations
Matrix([[L**2*m*theta_ddot + L*g*m*sin(theta)]])
"""

from sympy import cos, exp, sin, sqrt, tan

from .api import (
    DerivationError,
    EquationsOfMotion,
    LagrangianError,
    LoadContribution,
    Model,
    ModelError,
    Simulation,
    System,
    SystemBuilder,
    examples,
    load,
    parse_model,
    read_model,
)

__version__ = "0.1.0"

__all__ = [
    "DerivationError",
    "EquationsOfMotion",
    "LagrangianError",
    "LoadContribution",
    "Model",
    "ModelError",
    "System",
    "Simulation",
    "SystemBuilder",
    "cos",
    "examples",
    "exp",
    "load",
    "parse_model",
    "read_model",
    "sin",
    "sqrt",
    "tan",
]
