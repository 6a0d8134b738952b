"""The public face of lagrangian: load a model or build one, then ask the System.

Everything a user needs is importable from here (and from ``lagrangian`` itself).
"""

from ..derivation.equations import EquationsOfMotion, LoadContribution
from ..errors import DerivationError, LagrangianError, ModelError
from ..model.examples import example_names as examples
from ..model.model import Model
from ..model.reader import parse_model, read_model
from ..simulation import Simulation
from .system import System, SystemBuilder, load

__all__ = [
    "DerivationError",
    "EquationsOfMotion",
    "LagrangianError",
    "LoadContribution",
    "Model",
    "ModelError",
    "Simulation",
    "System",
    "SystemBuilder",
    "examples",
    "load",
    "parse_model",
    "read_model",
]
