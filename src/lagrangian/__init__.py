"""lagrangian: equations of motion by Lagrange's method, from energies or components.

>>> import lagrangian
>>> system = lagrangian.load("pendulum")
>>> system.equations_of_motion().equations
Matrix([[L**2*m*theta_ddot + L*g*m*sin(theta)]])
"""

from sympy import cos, exp, sin, sqrt, tan

from .api import (
    Answer,
    CheckReport,
    CoordinateAgreement,
    CrosscheckReport,
    DerivationError,
    EquationsOfMotion,
    Equilibria,
    Equilibrium,
    Finding,
    ForceReport,
    LagrangianError,
    LinearModel,
    LoadContribution,
    ModalAnalysis,
    Mode,
    Model,
    ModelError,
    NumericSystem,
    ParameterValues,
    Reaction,
    Simulation,
    SimulationResult,
    State,
    StaticsReport,
    SymbolicLinearModel,
    System,
    SystemBuilder,
    UnitIssue,
    UnitsReport,
    examples,
    load,
    parse_model,
    read_model,
)

__version__ = "0.1.0"

# The public API (api.__all__) and the sympy functions a SystemBuilder user writes with.
__all__ = [
    "Answer",
    "CheckReport",
    "CoordinateAgreement",
    "CrosscheckReport",
    "DerivationError",
    "Equilibria",
    "Equilibrium",
    "EquationsOfMotion",
    "Finding",
    "ForceReport",
    "LagrangianError",
    "LinearModel",
    "LoadContribution",
    "ModalAnalysis",
    "Mode",
    "Model",
    "ModelError",
    "NumericSystem",
    "ParameterValues",
    "Reaction",
    "Simulation",
    "SimulationResult",
    "StaticsReport",
    "State",
    "SymbolicLinearModel",
    "System",
    "SystemBuilder",
    "UnitIssue",
    "UnitsReport",
    "examples",
    "load",
    "parse_model",
    "read_model",
    "cos",
    "exp",
    "sin",
    "sqrt",
    "tan",
]
