"""The public face of lagrangian: load a model or build one, then ask the System.

Everything a user needs is importable from here (and from ``lagrangian`` itself): the entry
points, the values a System takes, the results it returns and the errors it raises.
"""

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
from .modes import ModalAnalysis
from .simulation import Simulation
from .system import System, SystemBuilder, load

# One Simulation (issue 26): the old public name of a run's result names the same type.
SimulationResult = Simulation

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
