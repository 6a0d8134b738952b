"""The user-facing System: a thin stateful shell over an immutable Model and pure functions.

Like MuJoCo's model/data split, the Model is fixed; what is derived from it is cached here.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
from functools import cached_property, lru_cache
from typing import TYPE_CHECKING

import sympy as sp

from ..derivation.lagrange import derive
from ..errors import InputError, LagrangianError
from ..model.builder import ModelBuilder
from ..model.model import Model
from .checking import CheckMethods
from .conservation import ConservationMethods
from .control import ControlMethods
from .export import ExportMethods
from .impacts import ImpactMethods
from .studies import StudyMethods

# The rest of the library is imported inside the methods that use it: a command pays only for
# the stages it runs (`derive` loads no checker, compiler, engine or integrator; issue 38).
if TYPE_CHECKING:
    from ..analysis.equilibria import Equilibria
    from ..analysis.forces import ForceReport
    from ..analysis.linearization import LinearModel, SymbolicLinearModel
    from ..analysis.statics import StaticsReport
    from ..compile.at_rest import AtRestFunctions
    from ..compile.functions import NumericSystem
    from ..derivation.equations import EquationsOfMotion
    from ..derivation.steps import DerivationSteps
    from ..dynamics.tree_at_rest import TreeAtRest
    from ..model.values import State
    from ..simulation.events import StopCondition
    from ..simulation.options import SaveAt, StepControl
    from .modes import ModalAnalysis
    from .simulation import Simulation


@lru_cache(maxsize=16)
def _derived(model: Model) -> EquationsOfMotion:
    """Lagrange's equations of a model, cached by its content (a Model is frozen and compares
    by value): a model file loaded twice, or two Systems of one model, share one derivation."""
    return derive(model)

class System(CheckMethods, ControlMethods, StudyMethods, ConservationMethods, ImpactMethods,
             ExportMethods):
    """A mechanical system described in generalized coordinates.

    >>> import lagrangian
    >>> pendulum = lagrangian.load("pendulum")          # a built-in example, or a path
    >>> pendulum.equations_of_motion().mass_matrix
    Matrix([[L**2*m]])
    """

    def __init__(self, model: Model):
        if not isinstance(model, Model):
            raise TypeError("System(model) takes a lagrangian Model; use load() or SystemBuilder")
        self._model = model

    @property
    def model(self) -> Model:
        return self._model

    @property
    def name(self) -> str:
        return self._model.name

    @property
    def coordinates(self) -> tuple[sp.Symbol, ...]:
        return self._model.q

    @property
    def velocities(self) -> tuple[sp.Symbol, ...]:
        return self._model.q_dot

    @property
    def parameters(self) -> dict[str, float | None]:
        """Parameter name -> SI value (None for symbolic-only parameters)."""
        return {p.name: p.value for p in self._model.parameters}

    @property
    def joint_names(self) -> dict[str, str]:
        """A robot read from URDF: coordinate name -> the file's joint name (the coordinate is
        the joint's name made an identifier, "joint_8.0" -> "joint_8_0"); {} for other models."""
        return dict(self._model.source_names)

    @property
    def coordinate_names(self) -> dict[str, str]:
        """The reverse of ``joint_names``: the URDF's joint name -> coordinate name (joints that
        move; locked, fixed and mimic joints have no coordinate)."""
        return {joint: coordinate for coordinate, joint in self._model.source_names}

    @property
    def joint_limits(self) -> dict[str, tuple[float, float]]:
        """A robot read from URDF: coordinate name -> its joint's position limit (lower, upper)
        in rad or m, where the file gives one; {} for other models."""
        from ..check.warnings import joint_limits

        return joint_limits(self._model)

    def symbol(self, name: str) -> sp.Symbol:
        """The sympy symbol of a coordinate, velocity or parameter, by name."""
        for c in self._model.coordinates:
            if name in (c.name, c.velocity.name, c.acceleration.name):
                return {c.name: c.symbol, c.velocity.name: c.velocity,
                        c.acceleration.name: c.acceleration}[name]
        for p in self._model.parameters:
            if p.name == name:
                return p.symbol
        raise KeyError(name)

    def with_parameters(self, **values: float) -> System:
        """A copy of the system with some parameter values replaced (SI units)."""
        return System(self._model.with_parameter_values(values))

    def with_gravity(self, gravity: Sequence[float]) -> System:
        """A copy under uniform gravity ``(g_x, g_y, g_z)`` in world axes (m/s^2): the gravity
        parameter (a URDF's ``g``) becomes |g| and the direction g/|g|, as Pinocchio's
        ``model.gravity``; a robot's compiled dynamics are rebuilt for (and cached by) the
        direction."""
        from ..model.gravity import with_gravity

        return System(with_gravity(self._model, gravity))

    @property
    def runs_on_tree(self) -> bool:
        """Whether simulate, equilibria, modes and dynamics run on the kinematic tree's
        recursions (a URDF robot, a model file's large tree of bodies on joints): nothing is
        derived for them."""
        return self._recursive is not None

    def equations_of_motion(self) -> EquationsOfMotion:
        """M q_ddot + Phi_q^T lambda = f by Lagrange's method (derived once, then cached)."""
        return self._equations

    def steps(self) -> DerivationSteps:
        """The working of Lagrange's method (derive --steps): per coordinate dL/dq_dot, its
        d/dt, dL/dq, Q and the equation; per load its virtual displacement and work."""
        return self.equations_of_motion().steps()

    @cached_property
    def _equations(self) -> EquationsOfMotion:
        return _derived(self._model)

    def generalized_forces_at(
        self, configuration: Mapping[str, float], parameters: Mapping[str, float] | None = None
    ) -> ForceReport:
        """Each generalized force, and each load's part of it, at a configuration (SI)."""
        from ..analysis.forces import evaluate_generalized_forces

        return evaluate_generalized_forces(self.equations_of_motion(), configuration, parameters)

    def statics(
        self, configuration: Mapping[str, float], solve_for: str | Sequence[str],
        parameters: Mapping[str, float] | None = None,
    ) -> StaticsReport:
        """The load magnitudes (parameters ``solve_for``, entering Q linearly) that hold the
        mechanism at rest at ``configuration`` (SI; coordinates not given follow the
        constraints), by virtual work delta W = 0, with each load's share and the reactions."""
        from ..analysis.statics import solve_statics

        unknowns = [solve_for] if isinstance(solve_for, str) else list(solve_for)
        return solve_statics(self.equations_of_motion(), configuration, unknowns, parameters)

    # -- simulation -------------------------------------------------------------------------------

    def simulate(
        self,
        t_end: float,
        *,
        initial: Mapping[str, float] | State | None = None,
        step_control: StepControl | None = None,
        save_at: SaveAt | None = None,
        stop_when: str | StopCondition | None = None,
        progress=None,
        method: str = "DOP853",
        rtol: float = 1e-9,
        atol: float = 1e-9,
        samples: int = 1001,
        limits: bool | str = True,
        controller=None,
        inputs: Sequence[str] | None = None,
        max_impacts: int | None = None,
        settle: bool = False,
        canonical: bool = False,
    ) -> Simulation:
        """Integrate the equations of motion to ``t_end`` (s); returns a Simulation.

        ``initial`` overrides the model's initial/rate values (SI: rad, m, rad/s, m/s; 't' sets
        the start time); ``step_control`` (StepControl: method, rtol, atol, max_step) and
        ``save_at`` (SaveAt: samples) say how to integrate and what to keep (``method``,
        ``rtol``, ``atol`` and ``samples`` are the same as plain keywords); ``stop_when`` is a
        condition such as "theta < 0" (or a StopCondition) that ends the run. Constrained models
        are kept on Phi = 0 by projection (see docs/simulation.md). A robot read from URDF
        stops with status 'limit' when a joint reaches its position limit, naming it
        (``limits=False`` ignores them; a start beyond one is refused, or with
        ``limits="clamp"`` started at the limit, with ``limits=False`` where it is, a warning
        in the result's message either way); velocity and effort limits exceeded are reported
        either way (``summary()["limits_exceeded"]``). ``controller`` (t, q, q_dot) -> u adds
        generalized forces, or B u for named ``inputs`` (its own ``inputs`` where it has them,
        as lagrangian.control's controllers do), to the model's own; "model" runs the file's
        [control] laws, compiled with its equations: docs/control.md. On a floating base u
        is the n joint torques or all n + 6 entries, the base's wrench first, and
        ``stop_when`` may name the base's numbers (base_z, base_vz, ...); a ball joint's
        quaternion and angular velocity are named <joint>_qw .. _qz and <joint>_wx .. _wz
        (docs/bridges.md), a URDF floating joint between links' <joint>_x .. _qw (m, then
        x y z w) and <joint>_vx .. _wz (m/s, rad/s, child axes) (docs/floating-base.md). A
        model with
        [[impacts]] runs through them (``.impacts`` lists each; status 'accumulated' where they
        accumulate, 'settled' with ``settle=True``, 'impact_limit' at ``max_impacts``, default
        1000): docs/simulation.md. ``canonical=True`` integrates Hamilton's equations in
        (q, p) instead (``hamiltonian()``; the momenta in ``.momenta`` and the p_<q> columns)."""
        from ..compile.functions import refuse_large_chain
        from ..derivation.regularity import require_inertia
        from ..model.values import resolve_state
        from ..simulation.simulate import parse_stop_condition, simulate, urdf_limits
        from .options import run_options
        from .simulation import Simulation

        # a start beyond a position limit: refused, clamped to it, or run from where it is
        start_beyond = {True: "refuse", "clamp": "clamp", False: "ignore"}.get(limits) \
            if isinstance(limits, bool | str) else None
        if start_beyond is None:
            raise InputError(f"limits is True, False or 'clamp', not {limits!r}", field="limits")
        # q and v differ in length (a floating base, a ball joint, a free flyer below the
        # root): simulation/floating.py
        manifold = self._floating or bool(getattr(self._model.kinematic_tree,
                                                  "quaternion_joints", ()))
        if start_beyond == "clamp" and manifold:
            raise InputError(("a floating base's" if self._floating else "a robot with a ball "
                              "or floating joint:") + " start is not clamped (yet): start it "
                             "inside, or run with limits=False", field="limits")
        limits = limits is not False
        tree = self._recursive is not None  # the tree's recursions: nothing to derive
        if canonical is not True and canonical is not False:
            raise InputError(f"canonical is True or False, not {canonical!r}", field="canonical")
        if canonical and (tree or self._model.impacts):
            raise InputError("a run in (q, p) is for a model file without impacts: "
                             + ("a robot's tree has no derived L" if tree else
                                "its impacts map velocities, not momenta (yet)"),
                             field="canonical")
        if tree and manifold:  # q (+) v dt on SE(3) and S^3: simulation/floating.py
            from ..simulation.floating import simulate_floating

            step_control, save_at = run_options(step_control, save_at, method, rtol, atol,
                                                samples, 1001)
            return Simulation.of(simulate_floating(self, t_end, initial, step_control, save_at,
                                                   controller, stop_when, limits, progress))
        if not tree:
            refuse_large_chain(self.model)  # before deriving what could not be compiled
            require_inertia(self.equations_of_motion(), "simulate")
        start = resolve_state(self._model, initial, field="initial")
        step_control, save_at = run_options(step_control, save_at, method, rtol, atol, samples,
                                         1001)
        stop = parse_stop_condition(stop_when, self._model) if isinstance(stop_when, str) else stop_when
        if self._model.impacts and not tree:  # through them: each listed (.impacts)
            return Simulation.of(self._run_through_impacts(
                t_end, start, step_control, save_at, progress, stop, controller, max_impacts,
                settle))
        law = isinstance(controller, str) and not tree and inputs is None
        controller = self._model_law(controller) if law else controller  # once per System
        result = simulate(None if tree else self.equations_of_motion(), t_end, initial=start,
                          step_control=step_control, save_at=save_at, stop=stop,
                          progress=progress, functions=None if law else self._numeric,
                          limits=urdf_limits(self._model, positions=limits), controller=controller,
                          inputs=getattr(controller, "inputs", ()) if inputs is None else inputs,
                          model=self._model, start_beyond=start_beyond,
                          start_limits=urdf_limits(self._model),
                          canonical=self.hamiltonian() if canonical else None)
        return Simulation.of(result)

    @property
    def _floating(self) -> bool:
        tree = getattr(self._model, "kinematic_tree", None)
        return bool(tree is not None and tree.floating_base)

    # -- compiled numeric functions -------------------------------------------------------------

    def numeric(self, parameters: Mapping[str, float] | None = None, backend: str = "auto"
                ) -> NumericSystem:
        """M, f, Phi_q, gamma, energy and the ODE right-hand side as batched numeric functions.

        backend "c" (generated C, compiled once and cached), "numpy", or "auto" (C if a compiler
        works). Parameters (SI) override the model's values.
        """
        from ..compile.functions import numeric, refuse_large_chain
        from ..dynamics.selection import recursive_dynamics

        if parameters is None and backend == "auto":
            return self._numeric
        fast = recursive_dynamics(self.model, parameters, backend)  # a tree: no derivation
        if fast is not None:
            return fast.numeric_system()
        refuse_large_chain(self.model)  # before deriving what could not be compiled
        return numeric(self.equations_of_motion(), parameters, backend=backend)

    @cached_property
    def _numeric(self) -> NumericSystem:
        """The default numeric system, compiled once per System (its parameters are fixed)."""
        from ..compile.functions import numeric, refuse_large_chain

        fast = self._recursive
        if fast is not None:
            return fast.numeric_system()
        refuse_large_chain(self.model)  # before deriving what could not be compiled
        return numeric(self.equations_of_motion())

    @cached_property
    def _recursive(self):
        """Recursive dynamics of a URDF tree in generated C (numpy without a compiler), or
        None (dynamics/joint_space.py)."""
        if self._model.kinematic_tree is None and not self._model.rigid_bodies:
            return None  # particles and energies: no tree to recurse on, no engine to load
        from ..dynamics.selection import recursive_dynamics

        return recursive_dynamics(self.model)

    def dynamics(self, parameters: Mapping[str, float] | None = None, backend: str = "auto",
                 kernel: str = "auto", *, actuators: bool = False,
                 armature: Mapping[str, float] | None = None):
        """M(q), bias C q_dot + g, g(q), inverse and forward dynamics and the energies, batched
        over leading axes (q of shape (n,) or (N, n)); a generalized force tau acts on top of
        the model's own loads (dynamics/joint_space.py). A URDF robot runs recursive algorithms in
        generated C (dynamics/recursive.py; in numpy without a compiler or with backend
        "numpy"), the other models their derived equations. A URDF robot's ``parameters`` may
        set a link's inertial (``{"tool0.mass": 2.5}``, dynamics/tree/inertials.py) without a
        rebuild; ``kernel`` "auto" or "compact" (the engine: one compiled module for every
        tree and variant) or "unrolled" (the tree's own code, compiled per tree on first use,
        about 2x faster per call). ``actuators=True``
        adds the URDF's joint damping and friction (and an MJCF's armature), ``armature``
        {joint: kg m^2 or kg} to M (dynamics/actuators.py)."""
        from ..dynamics.actuators import actuated
        from ..dynamics.selection import model_dynamics

        if parameters is None and backend == "auto" and kernel == "auto" \
                and self._recursive is not None:
            rigid = self._recursive
        else:
            rigid = model_dynamics(self.model, lambda: self.numeric(parameters, backend),
                                   parameters, backend, equations=self.equations_of_motion,
                                   kernel=kernel)
        if actuators and self.model.source_armature and (armature is None
                                                         or isinstance(armature, Mapping)):
            armature = {**dict(self.model.source_armature), **dict(armature or {})}  # the file's
        return rigid if not actuators and armature is None else \
            actuated(rigid, self.model, armature, friction=actuators)

    # -- equilibria, linearization and modes -----------------------------------------------------

    @cached_property
    def _static_functions(self) -> AtRestFunctions | TreeAtRest:
        """Compiled functions at rest, built once per System (parameters are fixed per System):
        a tree's from its recursions (nothing derived), else from the derived equations."""
        from ..compile.at_rest import AtRestFunctions
        from ..compile.functions import refuse_large_chain

        if self._recursive is not None:
            from ..dynamics.tree_at_rest import TreeAtRest

            return TreeAtRest(self._recursive)
        refuse_large_chain(self.model)
        return AtRestFunctions(self.equations_of_motion())

    def equilibria(self) -> Equilibria:
        """Configurations of rest, f(q, 0) = Phi_q^T lambda with Phi(q) = 0, each with its stability."""
        from ..analysis.equilibria import find_equilibria
        from ..analysis.linearization import is_statically_stable, linear_model_at
        from ..analysis.modes import is_stable

        functions = self._static_functions
        # a tree's M is positive definite (checked when its recursions were taken)
        statics = self._recursive is None and not self.equations_of_motion().has_inertia

        def stable(q, multipliers) -> bool:
            if statics:  # no inertia: stable where the potential has a minimum
                return is_statically_stable(functions, q, multipliers)
            return is_stable(linear_model_at(functions, q, multipliers))

        return find_equilibria(functions, stability=stable)

    def linearize(self, about: Mapping[str, float] | None = None, inputs: Sequence[str] = (), *,
                  symbolic: bool = False, steady: Mapping[str, float] | None = None,
                  ) -> LinearModel | SymbolicLinearModel:
        """Linear model M, C, K and state-space A, B (x = [q; q_dot]) about an equilibrium.

        ``about`` maps coordinate names to SI values (the others are solved for); without it the
        equilibrium nearest the initial values is used. ``inputs`` name parameters, loads or
        coordinates (a generalized force); their values that make ``about`` an equilibrium are
        solved for (least squares, the residual checked: the result's ``trim``), so a load's
        value in the file does not matter; refused only when no input can hold it.
        ``symbolic=True`` gives exact M, C, K of a small unconstrained model with the
        parameters kept as symbols. ``steady`` linearizes about a steady motion instead: cyclic
        coordinates turning at constant rates, e.g.
        ``steady={"psi_dot": 10}`` (rad/s), the rest at ``about`` (the others solved for).
        A robot with a ball joint (or a floating joint between links) is linearized in the
        model's Euler angles (``shoulder__x``, ``__y``, ``__z``, R = Rx Ry Rz), and ``lqr`` of
        it reads a run's quaternion state into them: docs/control.md.
        """
        from ..analysis.linearization import linear_model_at, symbolic_linear_model
        from ..compile.at_rest import AtRestFunctions
        from ..control.lqr_charts import refuse_state_names

        refuse_state_names(self, about)  # a ball's quaternion: its Euler angles, by name

        if steady:
            from ..analysis.steady import steady_linear_model
            from ..errors import ModelError

            if symbolic or inputs:
                raise ModelError("about a steady motion the linear model is numeric and has "
                                 "no inputs yet", field="steady")
            return steady_linear_model(self.equations_of_motion(), about, steady)
        if symbolic:
            return symbolic_linear_model(self.equations_of_motion(), dict(about or {}))
        inputs = tuple(inputs)
        # inputs are columns of the derived equations' generalized forces
        functions = self._static_functions if not inputs or self._recursive is None \
            else AtRestFunctions(self.equations_of_motion())
        if inputs:  # the inputs' values that hold ``about`` solved for (its trim)
            from ..analysis.trim import trimmed_linear_model

            return self._charted(trimmed_linear_model(
                functions, about, inputs,
                lambda values: AtRestFunctions(self.equations_of_motion(), values)))
        import numpy as np

        from ..analysis.equilibria import resolve_equilibrium

        with np.errstate(over="ignore", invalid="ignore"):  # judged by linear_model_at's check
            q, multipliers = resolve_equilibrium(functions, about)
        return self._charted(linear_model_at(functions, q, multipliers))

    def _charted(self, linear: LinearModel) -> LinearModel:
        """The linear model with the Euler charts that read a run's ball joints into its
        coordinates (control/lqr_charts.py), where the tree has a ball joint."""
        from ..control.lqr_charts import tree_charts

        charts = tree_charts(self)
        return linear if charts is None else replace(linear, charts=charts)

    def modes(self, about: Mapping[str, float] | None = None, *,
              steady: Mapping[str, float] | None = None,
              inputs: Sequence[str] = ()) -> ModalAnalysis:
        """Natural frequencies (rad/s), damping ratios and mode shapes about an equilibrium, or
        about a steady motion (``steady``: velocity name -> constant rate). A model with a
        [steady] table (a bicycle: it has no upright equilibrium at rest) is taken about that
        steady motion when neither ``about`` nor ``steady`` is given. ``inputs`` (as in
        linearize) give its ``linear_model`` a B, so lqr(modes, Q, R) can use it."""
        from ..analysis.modes import modal_analysis
        from ..compile.functions import refuse_large_chain
        from ..derivation.regularity import require_inertia
        from .modes import ModalAnalysis

        if self._recursive is None:  # a tree's M is positive definite (checked)
            refuse_large_chain(self.model)
            require_inertia(self.equations_of_motion(), "modes")
        default = self._model.steady_motion
        if steady is None and about is None and default is not None:
            steady, about = dict(default.rates), dict(default.about) or None
        return ModalAnalysis.of(modal_analysis(self.linearize(about, inputs, steady=steady),
                                               self._model.name), self._model)

    def warnings(self, set_parameters: Mapping[str, object] | None = None) -> list[str]:
        """Where the user is probably wrong, one line each: a declared g with no gravity, a
        dimensionally inconsistent term (the units check), a parameter in ``set_parameters``
        that no equation contains. Not errors: the results are right for what was written."""
        from ..check.warnings import model_warnings, setting_warnings

        eom = None
        needs_equations = bool(set_parameters) or (
            "g" in self.parameters and self._model.gravity is None)
        if needs_equations and self._model.kinematic_tree is None:
            try:
                eom = self.equations_of_motion()
            except LagrangianError:  # the command itself says what is wrong
                return []
        lines = model_warnings(self._model, eom)
        if set_parameters and eom is not None:
            lines += setting_warnings(eom, set_parameters)
        return lines

    # -- the report page ---------------------------------------------------------------------

    def report(self, answer=None, *, t_end: float | None = None, progress=None, size=None,
               fps=None):
        """One self-contained HTML page (report/page.py): the model and its drawing, T, V, L,
        the generalized forces per load, the equations, equilibria, modes (each drawn moving), a
        simulation of ``t_end`` s (default 10), the units check and, given ``answer`` (as in
        ``check``), the check's findings; ``size`` ("WxH" pixels) and ``fps`` of its animations.
        Returns a Report: ``.html``, ``.save(path)``; it shows itself in Jupyter."""
        from ..report.page import build_report

        return build_report(self, answer=answer, t_end=t_end, progress=progress, size=size,
                            fps=fps)

    def to_latex(self, standalone: bool = False, expand: bool = False) -> str:
        """The derivation as LaTeX (amsmath), as ``derive --format latex``: M q_ddot
        (+ Phi_q^T lambda) = f per coordinate, long rows broken; with ``standalone`` a complete
        document for pdflatex titled with the model's name. Large equations (a deep chain of
        bodies) are written in named intermediate quantities, listed first, unless ``expand``."""
        from ..output.derivation import derivation_latex

        return derivation_latex(self.equations_of_motion(), standalone=standalone,
                                expand=expand)

    def to_text(self, expand: bool = False) -> str:
        """The derivation as ``derive`` prints it: T, V, L, the equations, Q, M and f in the
        model-file grammar. Large equations (a deep chain of bodies) are written in named
        intermediate quantities, listed first, unless ``expand``."""
        from ..output.derivation import derivation_text

        return derivation_text(self.equations_of_motion(), expand=expand)

    def __repr__(self) -> str:
        names = ", ".join(c.name for c in self._model.coordinates)
        return f"System({self._model.name!r}, coordinates=[{names}])"

    def _repr_latex_(self) -> str:
        from ..model.notation import latex_symbol_names

        eom = self.equations_of_motion()
        names = latex_symbol_names(self._model)
        return rf"$L = {sp.latex(eom.lagrangian, symbol_names=names)}$"


class SystemBuilder(ModelBuilder):
    """Describe a system from Python; ``build()`` returns a :class:`System`.

    >>> import lagrangian
    >>> b = lagrangian.SystemBuilder("Pendulum")
    >>> theta = b.coordinate("theta", unit="rad")
    >>> m, L, g = b.parameter("m", 1.0), b.parameter("L", 0.5), b.parameter("g", 9.81)
    >>> bob = (L * lagrangian.sin(theta), -L * lagrangian.cos(theta))
    >>> _ = b.set_gravity(g, (0, -1)).add_particle("bob", m, bob)
    >>> b.build().equations_of_motion().forcing
    Matrix([[-L*g*m*sin(theta)]])
    """

    def build(self) -> System:
        return System(self.build_model())
