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
        AnswerResult,
        Backend,
        BackendUnavailable,
        CacheRefused,
        CheckReport,
        ClassReport,
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
        InputError,
        InvariantKind,
        JointKind,
        LagrangianError,
        Lesson,
        LinearModel,
        LoadContribution,
        MissingExtraError,
        ModalAnalysis,
        Mode,
        Model,
        ModelError,
        ModelKinematics,
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
        StateLayout,
        StaticsReport,
        StepControl,
        StopCondition,
        SymbolicLinearModel,
        System,
        SystemBuilder,
        TreeKinematics,
        UnitIssue,
        UnitsReport,
        course_lessons,
        examples,
        load,
        parse_model,
        read_model,
        state_layout,
    )
    from .api.optimize import Trajectory, optimize
    from .api.robot_builder import RobotBuilder
    from .control import computed_torque, lqr
    from .errors import DynamicsWarning, ModelWarning

__version__ = "0.1.0"

# The public API (api.__all__) and the sympy functions a SystemBuilder user writes with.
__all__ = [
    "Answer",
    "AnswerResult",
    "Backend",
    "BackendUnavailable",
    "CacheRefused",
    "CheckReport",
    "ClassReport",
    "CompilerMissing",
    "ConstraintKind",
    "CoordinateAgreement",
    "CrosscheckReport",
    "CrosscheckSteps",
    "DerivationError",
    "DerivationSteps",
    "Dynamics",
    "DynamicsWarning",
    "EquationsOfMotion",
    "Equilibria",
    "Equilibrium",
    "Finding",
    "ForceReport",
    "InputError",
    "InvariantKind",
    "JointKind",
    "LagrangianError",
    "Lesson",
    "LinearModel",
    "LoadContribution",
    "MissingExtraError",
    "ModelWarning",
    "ModalAnalysis",
    "Mode",
    "Model",
    "ModelError",
    "NumericSystem",
    "ParameterValues",
    "Reaction",
    "RobotBuilder",
    "RunStatus",
    "SaveAt",
    "Simulation",
    "SimulationResult",
    "SpeedForm",
    "SpeedSweep",
    "StandaloneSource",
    "State",
    "StateLayout",
    "StaticsReport",
    "StepControl",
    "StopCondition",
    "SymbolicLinearModel",
    "System",
    "SystemBuilder",
    "ModelKinematics",
    "TreeKinematics",
    "UnitIssue",
    "UnitsReport",
    "course_lessons",
    "examples",
    "load",
    "parse_model",
    "read_model",
    "SIMULATION_METHODS",
    "answer_files",
    "bare_angle_warnings",
    "check_report_path",
    "example_names",
    "example_path",
    "example_robots",
    "parse_quantity",
    "parse_steady_rates",
    "state_layout",
    "lqr",
    "computed_torque",
    "optimize",
    "Trajectory",
    "cos",
    "exp",
    "sin",
    "sqrt",
    "tan",
]

_SYMPY_NAMES = frozenset({"cos", "exp", "sin", "sqrt", "tan"})

# Public functions and limits that live in one stage, loaded from their own module on first use
# (not through the API, so that `lagrangian examples` starts without sympy or numpy).
_HOMES = {
    "DynamicsWarning": ("errors", "DynamicsWarning"),
    "ModelWarning": ("errors", "ModelWarning"),
    "parse_quantity": ("model.units", "parse_quantity"),
    "example_names": ("model.examples", "example_names"),
    "example_path": ("model.examples", "example_path"),
    "example_robots": ("model.robots", "example_robots"),
    "SIMULATION_METHODS": ("simulation.options", "METHODS"),
    "parse_steady_rates": ("analysis.steady", "parse_steady_rates"),
    "bare_angle_warnings": ("check.warnings", "bare_angle_warnings"),
    "answer_files": ("check.classroom", "answer_files"),
    "course_lessons": ("check.course", "course_lessons"),
    "check_report_path": ("report.page", "check_report_path"),
    "lqr": ("control.lqr", "lqr"),
    "computed_torque": ("control.computed_torque", "computed_torque"),
    "optimize": ("api.optimize", "optimize"),
    "RobotBuilder": ("api.robot_builder", "RobotBuilder"),
    "Trajectory": ("control.optimize", "Trajectory"),
}

# The command line's own helpers (issue 38): not the public face (``__all__``, ``dir()``), yet
# found here, since the CLI is a client of this package only (pyproject.toml's import contract:
# it imports no stage directly). Each is public in its own module.
_CLI_HOMES = {
    "state_units": ("model.values", "state_units"),
    "resolve_state": ("model.values", "resolve_state"),
    "example_summary": ("model.examples", "example_summary"),
    "example_text": ("model.examples", "example_text"),
    "physical_warnings": ("derivation.regularity", "physical_warnings"),
    "parse_stop_condition": ("simulation.events", "parse_stop_condition"),
    "speed_sweep": ("analysis.speed_form", "speed_sweep"),
    "MAX_STUDY_POINTS": ("analysis.study", "MAX_STUDY_POINTS"),
    "limit_warnings": ("check.warnings", "limit_warnings"),
    "check_input_file": ("model.reader", "check_text_file"),
    "course_document": ("check.course", "course_document"),
    "course_folder": ("check.course", "course_folder"),
    "state_dynamics": ("api.state_dynamics", "state_dynamics"),
    "state_kinematics": ("api.state_dynamics", "state_kinematics"),
}


def __getattr__(name: str):
    """Each public name loaded on first use: `import lagrangian` (and the command line's start,
    `lagrangian --help`) pays for sympy, scipy and the API only when a name is asked for."""
    if name not in __all__ and name not in _CLI_HOMES:
        raise AttributeError(f"module 'lagrangian' has no attribute {name!r}")
    if name in _SYMPY_NAMES:
        import sympy

        value = getattr(sympy, name)
    elif name in _HOMES or name in _CLI_HOMES:
        from importlib import import_module

        home, attribute = _HOMES.get(name) or _CLI_HOMES[name]
        value = getattr(import_module(f"{__name__}.{home}"), attribute)
    else:
        from . import api

        value = getattr(api, name)
    globals()[name] = value  # once loaded, an ordinary module attribute
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__} - set(_CLI_HOMES))
