"""The public face of lagrangian: load a model or build one, then ask the System.

Everything a user needs is importable from here (and from ``lagrangian`` itself): the entry
points, the values a System takes, the results it returns and the errors it raises.
"""

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the names below, for type checkers and readers; loaded on first use
    from ..analysis.equilibria import Equilibria, Equilibrium
    from ..analysis.forces import ForceReport
    from ..analysis.linearization import LinearModel, SymbolicLinearModel
    from ..analysis.modes import Mode
    from ..analysis.speed_form import SpeedForm, SpeedSweep
    from ..analysis.statics import StaticsReport
    from ..check.classroom import AnswerResult, ClassReport
    from ..check.course import Lesson, course_lessons
    from ..check.crosscheck_report import CoordinateAgreement, CrosscheckReport, Reaction
    from ..check.diagnose import CheckReport, Finding
    from ..check.free_body_steps import CrosscheckSteps
    from ..check.units import UnitIssue, UnitsReport
    from ..compile.compiled import BackendUnavailable, CacheRefused, CompilerMissing
    from ..compile.functions import NumericSystem
    from ..derivation.equations import EquationsOfMotion
    from ..derivation.steps import DerivationSteps
    from ..derivation.virtual_work import LoadContribution
    from ..dynamics.algorithms.frames import TreeKinematics
    from ..dynamics.joint_space import Dynamics
    from ..dynamics.model_frames import ModelKinematics
    from ..dynamics.standalone.standalone import StandaloneSource
    from ..errors import DerivationError, InputError, LagrangianError, MissingExtraError, ModelError
    from ..kinds import Backend, ConstraintKind, InvariantKind, JointKind, RunStatus
    from ..model.answer import Answer
    from ..model.examples import example_names as examples
    from ..model.model import Model
    from ..model.reader import parse_model, read_model
    from ..model.values import ParameterValues, State
    from ..simulation.events import StopCondition
    from ..simulation.options import SaveAt, StepControl
    from .layout import StateLayout, state_layout
    from .loading import load
    from .modes import ModalAnalysis
    from .simulation import Simulation
    from .system import System, SystemBuilder

    SimulationResult = Simulation

# Each public name's home, imported on first use: a command pays only for the stages it runs
# (`derive` needs no checker, compiler, engine or integrator). One Simulation (issue 26): the
# old public name of a run's result, SimulationResult, names the same type.
_HOMES = {
    "Equilibria": ("..analysis.equilibria", "Equilibria"),
    "Equilibrium": ("..analysis.equilibria", "Equilibrium"),
    "ForceReport": ("..analysis.forces", "ForceReport"),
    "LinearModel": ("..analysis.linearization", "LinearModel"),
    "SymbolicLinearModel": ("..analysis.linearization", "SymbolicLinearModel"),
    "Mode": ("..analysis.modes", "Mode"),
    "SpeedForm": ("..analysis.speed_form", "SpeedForm"),
    "SpeedSweep": ("..analysis.speed_form", "SpeedSweep"),
    "StaticsReport": ("..analysis.statics", "StaticsReport"),
    "AnswerResult": ("..check.classroom", "AnswerResult"),
    "ClassReport": ("..check.classroom", "ClassReport"),
    "Lesson": ("..check.course", "Lesson"),
    "course_lessons": ("..check.course", "course_lessons"),
    "CoordinateAgreement": ("..check.crosscheck_report", "CoordinateAgreement"),
    "CrosscheckReport": ("..check.crosscheck_report", "CrosscheckReport"),
    "Reaction": ("..check.crosscheck_report", "Reaction"),
    "CheckReport": ("..check.diagnose", "CheckReport"),
    "Finding": ("..check.diagnose", "Finding"),
    "CrosscheckSteps": ("..check.free_body_steps", "CrosscheckSteps"),
    "UnitIssue": ("..check.units", "UnitIssue"),
    "UnitsReport": ("..check.units", "UnitsReport"),
    "BackendUnavailable": ("..compile.compiled", "BackendUnavailable"),
    "CacheRefused": ("..compile.compiled", "CacheRefused"),
    "CompilerMissing": ("..compile.compiled", "CompilerMissing"),
    "NumericSystem": ("..compile.functions", "NumericSystem"),
    "EquationsOfMotion": ("..derivation.equations", "EquationsOfMotion"),
    "DerivationSteps": ("..derivation.steps", "DerivationSteps"),
    "LoadContribution": ("..derivation.virtual_work", "LoadContribution"),
    "TreeKinematics": ("..dynamics.algorithms.frames", "TreeKinematics"),
    "Dynamics": ("..dynamics.joint_space", "Dynamics"),
    "ModelKinematics": ("..dynamics.model_frames", "ModelKinematics"),
    "StandaloneSource": ("..dynamics.standalone.standalone", "StandaloneSource"),
    "DerivationError": ("..errors", "DerivationError"),
    "InputError": ("..errors", "InputError"),
    "LagrangianError": ("..errors", "LagrangianError"),
    "MissingExtraError": ("..errors", "MissingExtraError"),
    "ModelError": ("..errors", "ModelError"),
    "Backend": ("..kinds", "Backend"),
    "ConstraintKind": ("..kinds", "ConstraintKind"),
    "InvariantKind": ("..kinds", "InvariantKind"),
    "JointKind": ("..kinds", "JointKind"),
    "RunStatus": ("..kinds", "RunStatus"),
    "Answer": ("..model.answer", "Answer"),
    "examples": ("..model.examples", "example_names"),
    "Model": ("..model.model", "Model"),
    "parse_model": ("..model.reader", "parse_model"),
    "read_model": ("..model.reader", "read_model"),
    "ParameterValues": ("..model.values", "ParameterValues"),
    "State": ("..model.values", "State"),
    "StopCondition": ("..simulation.events", "StopCondition"),
    "SaveAt": ("..simulation.options", "SaveAt"),
    "StepControl": ("..simulation.options", "StepControl"),
    "StateLayout": (".layout", "StateLayout"),
    "state_layout": (".layout", "state_layout"),
    "ModalAnalysis": (".modes", "ModalAnalysis"),
    "Simulation": (".simulation", "Simulation"),
    "System": (".system", "System"),
    "SystemBuilder": (".system", "SystemBuilder"),
    "load": (".loading", "load"),
    "SimulationResult": (".simulation", "Simulation"),
}

__all__ = [
    # entry points
    "System",
    "TreeKinematics",
    "ModelKinematics",
    "SystemBuilder",
    "course_lessons",
    "examples",
    "load",
    "parse_model",
    "read_model",
    "state_layout",
    # what a System is made of and takes
    "Answer",
    "Model",
    "ParameterValues",
    "State",
    "StateLayout",
    "SaveAt",
    # the kinds and states it names (string enums)
    "Backend",
    "ConstraintKind",
    "InvariantKind",
    "JointKind",
    "RunStatus",
    "StepControl",
    "StopCondition",
    # what it returns
    "AnswerResult",
    "CheckReport",
    "ClassReport",
    "CoordinateAgreement",
    "CrosscheckReport",
    "CrosscheckSteps",
    "DerivationSteps",
    "Dynamics",
    "Equilibria",
    "Equilibrium",
    "EquationsOfMotion",
    "Finding",
    "ForceReport",
    "LinearModel",
    "Lesson",
    "LoadContribution",
    "ModalAnalysis",
    "Mode",
    "NumericSystem",
    "Reaction",
    "Simulation",
    "SimulationResult",
    "SpeedForm",
    "SpeedSweep",
    "StandaloneSource",
    "StaticsReport",
    "SymbolicLinearModel",
    "UnitIssue",
    "UnitsReport",
    # what it raises
    "BackendUnavailable",
    "CacheRefused",
    "CompilerMissing",
    "DerivationError",
    "LagrangianError",
    "InputError",
    "MissingExtraError",
    "ModelError",
]


def __getattr__(name: str):
    """A public name, imported from its home on first use."""
    if name not in _HOMES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from importlib import import_module

    home, attribute = _HOMES[name]
    value = getattr(import_module(home, __name__), attribute)
    globals()[name] = value  # once loaded, an ordinary module attribute
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
