"""Which dynamics a model gets: a tree's recursive algorithms (recursive.TreeDynamics over the
engine, a tree's unrolled module, or numpy without a compiler: the backend chosen here, once, up
front), else the functions of its derived equations (constrained.py's DAE where it has
constraints). The choice, not the physics: joint_space.py, recursive.py and backends.py hold
that."""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np

from ..compile.functions import NumericSystem
from ..derivation.equations import EquationsOfMotion
from ..errors import DerivationError, InputError
from ..model.model import Model
from .joint_space import Dynamics


def recursive_dynamics(model: Model, parameters: Mapping[str, float] | None = None,
                       backend: str = "auto", kernel: str = "auto"):
    """The recursive dynamics of a URDF tree, or of a model file's tree of rigid bodies on
    joints (at least TREE_PATH_BODIES of them): recursive.TreeDynamics over the engine's one
    compiled module for every tree (``kernel`` "auto" or "compact"), the tree's own unrolled
    module, compiled per tree (``kernel="unrolled"``), or the numpy reference (backend "numpy",
    or backend "auto" where no compiler works: chosen here, up front, with one line saying so);
    None where they do not apply: not a bare tree, or a mass matrix that is not positive
    definite (the symbolic path names the joints).

    ``parameters`` may set a URDF link's inertial by ``<link>.<field>`` (model/tree.py
    INERTIAL_FIELDS: mass, com_x, ..., ixx, ...), as if the URDF had been edited."""
    from .recursive import TREE_PATH_BODIES, TreeDynamics, applicable_tree
    from .tree.inertials import split_inertials

    if kernel not in ("auto", "unrolled", "compact"):
        raise InputError(f"unknown kernel {kernel!r} (auto, unrolled or compact)", field="kernel")
    if backend not in ("auto", "c", "numpy"):
        return None
    parameters, inertials = split_inertials(model.kinematic_tree, parameters)
    tree = applicable_tree(model, parameters)
    # a model file's small tree keeps its derived equations (quick to compile, as written)
    if tree is None or (model.kinematic_tree is None and len(tree.joints) < TREE_PATH_BODIES):
        return None
    if inertials:
        tree = inertials
    # one engine for every tree and variant (a link's inertial, a payload, a floating base:
    # run-time numbers, no build); the per-tree unrolled module only when asked for, about 2x
    # faster per call after a compile of seconds per tree (docs/benchmarks.md)
    chosen = "unrolled" if kernel == "unrolled" else "compact"
    if backend == "numpy" or (backend == "auto" and not _compiled_ready(chosen)):
        chosen = "numpy"
    dynamics = TreeDynamics(model, tree, parameters, kernel=chosen)
    if tree.floating_base or dynamics.regular():
        # a floating base has no symbolic path to fall to: NaN rows where M is singular
        return dynamics
    if inertials:  # the derived equations know no link parameters: say what is wrong here
        raise InputError("with these link inertials the mass matrix is not positive definite "
                         "(a joint that moves no mass)", field="parameters")
    _refuse_massless_joints(model, dynamics)
    return None


def _compiled_ready(kernel: str) -> bool:
    """Whether the compiled backend can be had (the engine: in the cache or buildable; a tree's
    unrolled module: buildable); else one line saying numpy runs instead, and why."""
    from ..compile import compiled
    from ..compile.functions import tell_numpy_fallback
    from .engine.compact_kernel import kernel_key

    if compiled.ready(kernel_key(), native=True, exact=True) if kernel == "compact" \
            else compiled.available():
        return True
    # the same algorithms in numpy: the expanded equations of a 7-joint arm are too deep for
    # lambdify, the recursions are not
    reason = compiled.missing_compiler() or compiled.BackendUnavailable(
        "Python's C headers are missing")
    tell_numpy_fallback(reason, "the robot's recursive dynamics run in numpy, about 1000x slower "
                        "per call than compiled C")
    return False


def _refuse_massless_joints(model: Model, dynamics) -> None:
    """Joints whose column of M is zero (they carry only massless links, Romeo's hands): one
    line naming them and the fix, lock, before a long derivation would find the same."""
    from ..errors import lock_hint

    rng = np.random.default_rng(1)
    M = dynamics.mass_matrix(rng.uniform(-np.pi, np.pi, (3, dynamics.n)))
    diagonal = np.abs(np.diagonal(M, axis1=-2, axis2=-1)).max(axis=0)
    idle = [c for c, d in zip(dynamics.coordinates, diagonal, strict=True)
            if not d > 1e-14 * max(1.0, float(diagonal.max()))]
    if idle:
        joints = dict(model.source_names)
        raise DerivationError(lock_hint([joints.get(c, c) for c in idle]))


def model_dynamics(model: Model, symbolic: Callable[[], NumericSystem],
                   parameters: Mapping[str, float] | None = None, backend: str = "auto",
                   equations: Callable[[], EquationsOfMotion] | None = None,
                   kernel: str = "auto"):
    """Recursive dynamics where they apply, else Dynamics over ``symbolic()`` (the numeric
    functions of the derived equations; ``equations()`` gives them for coriolis_matrix), or for
    a model with constraints constrained.ConstrainedDynamics (forward dynamics only)."""
    fast = recursive_dynamics(model, parameters, backend, kernel)
    if fast is not None:
        return fast
    if model.constraints:  # the DAE's forward dynamics, through the multipliers
        from .constrained import ConstrainedDynamics

        return ConstrainedDynamics(symbolic(), equations, model)
    dynamics = Dynamics(symbolic(), equations)
    dynamics.model = model  # for its frames (model_frames.py)
    return dynamics


__all__ = ["model_dynamics", "recursive_dynamics"]
