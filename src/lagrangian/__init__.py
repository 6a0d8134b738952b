"""lagrangian: equations of motion by Lagrange's method, from energies or components.

>>> import lagrangian
>>> system = lagrangian.load("pendulum")
>>> system.equations_of_motion().equations
Matrix([[L**2*m*theta_ddot + L*g*m*sin(theta)]])
"""

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the names below, for type checkers and readers; loaded on first use
    from sympy import cos, exp, sin, sqrt, tan

    from .api import (
        Answer,
        Backend,
        BackendUnavailable,
        CacheRefused,
        CheckReport,
        CompilerMissing,
        ConstraintKind,
        CoordinateAgreement,
        CrosscheckReport,
        CrosscheckSteps,
        DerivationError,
        DerivationSteps,
        Dynamics,
        EquationsOfMotion,
        Equilibria,
        Equilibrium,
        Finding,
        ForceReport,
        InvariantKind,
        JointKind,
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
        RunStatus,
        SaveAt,
        Simulation,
        SimulationResult,
        SpeedForm,
        SpeedSweep,
        StandaloneSource,
        State,
        StaticsReport,
        StepControl,
        StopCondition,
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
    "Backend",
    "BackendUnavailable",
    "CacheRefused",
    "CheckReport",
    "CompilerMissing",
    "ConstraintKind",
    "CoordinateAgreement",
    "CrosscheckReport",
    "CrosscheckSteps",
    "DerivationError",
    "DerivationSteps",
    "Dynamics",
    "EquationsOfMotion",
    "Equilibria",
    "Equilibrium",
    "Finding",
    "ForceReport",
    "InvariantKind",
    "JointKind",
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
    "RunStatus",
    "SaveAt",
    "Simulation",
    "SimulationResult",
    "SpeedForm",
    "SpeedSweep",
    "StandaloneSource",
    "State",
    "StaticsReport",
    "StepControl",
    "StopCondition",
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

_SYMPY_NAMES = frozenset({"cos", "exp", "sin", "sqrt", "tan"})


def __getattr__(name: str):
    """Each public name loaded on first use: `import lagrangian` (and the command line's start,
    `lagrangian --help`) pays for sympy, scipy and the API only when a name is asked for."""
    if name not in __all__:
        raise AttributeError(f"module 'lagrangian' has no attribute {name!r}")
    if name in _SYMPY_NAMES:
        import sympy

        value = getattr(sympy, name)
    else:
        from . import api

        value = getattr(api, name)
    globals()[name] = value  # once loaded, an ordinary module attribute
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
