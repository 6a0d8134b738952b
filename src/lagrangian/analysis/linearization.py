"""Linearization about an equilibrium: M dq_ddot + C dq_dot + K dq = B du, and x_dot = A x + B u.

From M(q) q_ddot + Phi_q^T lambda = f(q, q_dot, t) at rest (q_dot = 0, q_ddot = 0, lambda0):
M = M(q0) (the dM/dq q_ddot terms vanish because q_ddot = 0), C = -df/dq_dot (dissipation plus
gyroscopic), K = -df/dq + sum_c lambda0_c d(Phi_q,c)/dq (the constraint Hessian), all evaluated
numerically from symbolic Jacobians compiled once: no symbolic inversion, no simplify.
With holonomic constraints the matrices are projected on the null space of Phi_q at q0, spanned
by the independent coordinates (dq = N z); velocity constraints restrict only the velocities.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from ..compile.at_rest import AtRestFunctions, linear_velocity_row
from ..derivation.equations import EquationsOfMotion
from ..derivation.kinematics import jacobian_row
from ..errors import DerivationError, ModelError
from ..kinds import ConstraintKind
from ..model.expressions import as_expression
from ..model.inputs import input_parameter
from ..model.values import ParameterValues, resolve_parameters, resolve_state

# Relative singular-value threshold for the rank of the constraint Jacobian.
RANK_TOLERANCE = 1e-9


# -- the equilibrium equations ------------------------------------------------------------------


def static_residual(values: dict[str, np.ndarray], multipliers: np.ndarray) -> np.ndarray:
    """[f(q, 0) - Phi_q^T lambda; Phi(q)] (forces, then constraint residuals), shape (..., n + s)."""
    force = values["forcing"] - np.einsum("...cn,...c->...n", values["jacobian"], multipliers)
    return np.concatenate([force, values["static"]], axis=-1)


def total_stiffness(values: dict[str, np.ndarray], multipliers: np.ndarray) -> np.ndarray:
    """K = -df/dq + sum_c lambda_c d(Phi_q,c)/dq, in user coordinates (n x n)."""
    return values["stiffness"] + np.einsum("...c,...cij->...ij", multipliers, values["hessians"])


# -- the linear model ---------------------------------------------------------------------------


def state_matrix(from_position: np.ndarray, from_velocity: np.ndarray) -> np.ndarray:
    """A of x_dot = A x, x = [z; z_dot] (1/s units per row): [[0, 1], [from_position,
    from_velocity]], the accelerations per unit displacement and per unit rate (-M^-1 K and
    -M^-1 C where nothing constrains z). The one place this block form is written."""
    p = from_position.shape[0]
    return np.block([[np.zeros((p, p)), np.eye(p)], [from_position, from_velocity]])



class SecondOrderForm:
    """M z_ddot + C z_dot + K z: the names both linear models give their matrices (numbers in
    LinearModel, sympy matrices in SymbolicLinearModel; SI units). Each holds mass_matrix,
    damping_matrix and stiffness_matrix."""

    @property
    def M(self):
        return self.mass_matrix

    @property
    def C(self):
        return self.damping_matrix

    @property
    def K(self):
        return self.stiffness_matrix

    @property
    def gyroscopic_matrix(self):
        """G = (C - C^T)/2: the skew, energy-neutral part of C."""
        return (self.damping_matrix - self.damping_matrix.T) / 2

    @property
    def dissipation_matrix(self):
        """(C + C^T)/2: the symmetric, energy-removing part of C."""
        return (self.damping_matrix + self.damping_matrix.T) / 2


@dataclass(frozen=True)
class LinearModel(SecondOrderForm):
    """M z_ddot + C z_dot + K z = B_q u about an equilibrium, and x_dot = A x + B u, x = [z; z_dot].

    ``coordinates`` name z: all coordinates of an unconstrained model, else the independent ones
    kept by the projection (dq = basis @ z in the user's ``user_coordinates``). Units SI.
    """

    equilibrium: dict[str, float]
    multipliers: dict[str, float]
    coordinates: tuple[str, ...]
    user_coordinates: tuple[str, ...]
    basis: np.ndarray
    mass_matrix: np.ndarray
    damping_matrix: np.ndarray
    stiffness_matrix: np.ndarray
    A: np.ndarray
    B: np.ndarray
    inputs: tuple[str, ...] = ()
    input_matrix: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    velocity_constraints: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    full_mass_matrix: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    full_damping_matrix: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    full_stiffness_matrix: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    # About a steady motion (analysis/steady.py): velocity name -> its constant rate; empty
    # about an equilibrium.
    steady: dict[str, float] = field(default_factory=dict)
    # About a steady motion with velocity constraints A(q) q_dot + b(q) = 0: their linearization
    # H dq + G dq_dot = 0 as rows over the state (dq, dq_dot). A keeps H dq + G dq_dot constant,
    # so the motions of the system are the invariant subspace where it is zero.
    state_constraints: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    # With inputs: the value of each that holds the equilibrium (its trim, analysis/trim.py:
    # the parameter's value, or the generalized force on a coordinate; SI), and the model's own
    # (a parameter's value in the model, 0 for a coordinate). u in B u is measured from the
    # model's own: trim - nominal holds the state.
    trim: dict[str, float] = field(default_factory=dict)
    nominal_inputs: dict[str, float] = field(default_factory=dict)
    # a robot with ball joints: the Euler charts that read a run's quaternion state into z
    # (control/lqr_charts.TreeCharts, set by System.linearize), for LQR's controller
    charts: object | None = field(default=None, repr=False, compare=False)

    @property
    def constrained(self) -> bool:
        return self.coordinates != self.user_coordinates or self.velocity_constraints.size > 0

    @property
    def state_names(self) -> tuple[str, ...]:
        return (*self.coordinates, *(f"{c}_dot" for c in self.coordinates))

    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of A (1/s), sorted by real part, largest first (the least stable first)."""
        values = np.linalg.eigvals(self.A)
        return values[np.lexsort((values.imag, -values.real))]

    def state_space(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(A, B, C, D) with the whole state as output: ``scipy.signal.StateSpace(*lm.state_space())``
        or ``control.ss(*lm.state_space())``."""
        size = self.A.shape[0]
        return self.A, self.B, np.eye(size), np.zeros((size, self.B.shape[1]))

    def __repr__(self) -> str:
        about = ", ".join(f"{k}={v:.6g}" for k, v in self.equilibrium.items())
        trim = "".join(f", {k}={v:.6g}" for k, v in self.trim.items())
        return (f"LinearModel(about {about}; coordinates={list(self.coordinates)}, "
                f"inputs={list(self.inputs)}{'; trim' if trim else ''}{trim[1:]})\n"
                f"M =\n{self.mass_matrix}\nC =\n"
                f"{self.damping_matrix}\nK =\n{self.stiffness_matrix}")


def independent_basis(jacobian: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Null-space basis N of the constraint Jacobian (n x p) with an identity on the independent
    coordinates; returns (N, indices of the independent coordinates).

    The rank comes from the singular values; the dependent coordinates are the pivots of a
    column-pivoted QR (the best-conditioned choice), so dq = N z never divides by a small pivot.
    """
    import scipy.linalg

    m, n = jacobian.shape
    if m == 0:
        return np.eye(n), np.arange(n)
    singular = np.linalg.svd(jacobian, compute_uv=False)
    rank = int(np.sum(singular > RANK_TOLERANCE * max(singular[0], 1e-300)))
    _, _, pivots = scipy.linalg.qr(jacobian, pivoting=True, mode="economic")
    dependent = np.sort(pivots[:rank])
    independent = np.array([i for i in range(n) if i not in set(dependent)], dtype=int)
    basis = np.zeros((n, n - rank))
    basis[independent, np.arange(n - rank)] = 1.0
    if rank:
        # J_d dq_d + J_i dq_i = 0 in the least-squares sense (redundant rows allowed).
        solution = np.linalg.lstsq(jacobian[:, dependent], -jacobian[:, independent], rcond=None)[0]
        basis[dependent, :] = solution
    return basis, independent


def null_space(matrix: np.ndarray) -> np.ndarray:
    """Orthonormal null-space basis (SVD) of a k x p matrix."""
    p = matrix.shape[1]
    if matrix.shape[0] == 0:
        return np.eye(p)
    _, singular, vt = np.linalg.svd(matrix)
    rank = int(np.sum(singular > RANK_TOLERANCE * max(singular[0] if singular.size else 0, 1e-300)))
    return vt[rank:].T


def linear_model_at(
    functions: AtRestFunctions,
    q0: np.ndarray,
    multipliers: np.ndarray,
    t: float = 0.0,
    *,
    inputs: Sequence[str] = (),
    input_columns: np.ndarray | None = None,
) -> LinearModel:
    """The linear model at a known equilibrium (q0, lambda0), from the compiled functions."""
    model = functions.model
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is refused just below
        values = functions.evaluate(np.asarray(q0, dtype=float), t)
        stiffness = total_stiffness(values, multipliers)
    n = functions.n
    mass, damping = values["mass"], values["damping"]
    for matrix, what in ((mass, "mass matrix M"), (damping, "damping matrix C"),
                         (stiffness, "stiffness matrix K")):
        if not np.all(np.isfinite(matrix)):
            raise DerivationError(f"the {what} is not finite at this equilibrium (a number "
                                  "beyond floating point: m L^2 of L = 1e300 overflows)")
    _require_balance(functions, values, multipliers)
    kinds = [c.kind for c in model.constraints]
    holonomic = [i for i, k in enumerate(kinds) if k == ConstraintKind.HOLONOMIC]
    velocity = [i for i, k in enumerate(kinds) if k != ConstraintKind.HOLONOMIC]
    basis, independent = independent_basis(values["jacobian"][holonomic])
    names = tuple(c.name for c in model.coordinates)
    reduced = tuple(names[i] for i in independent)
    Mr = basis.T @ mass @ basis
    Cr = basis.T @ damping @ basis
    Kr = basis.T @ stiffness @ basis
    p = basis.shape[1]
    G = values["jacobian"][velocity] @ basis
    Nv = null_space(G)
    reduced_mass = Nv.T @ Mr @ Nv
    try:
        projector = Nv @ np.linalg.solve(reduced_mass, Nv.T)
    except np.linalg.LinAlgError:
        raise DerivationError("the mass matrix is singular at this equilibrium; "
                              "the linear model has no state-space form") from None
    columns = np.zeros((n, 0)) if input_columns is None else np.asarray(input_columns, float)
    Br = basis.T @ columns
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is refused just below
        A = state_matrix(-projector @ Kr, -projector @ Cr)
        B = np.vstack([np.zeros((p, columns.shape[1])), projector @ Br])
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(B))):
        # M, C and K are finite, but M^-1 K may not be (g = 1e308 on a pendulum of m L^2 < 1)
        raise DerivationError("the state matrix A = [0 I; -M^-1 K  -M^-1 C] (or B) is not "
                              "finite at this equilibrium: M^-1 K or M^-1 C overflows")
    return LinearModel(
        equilibrium={name: float(v) for name, v in zip(names, q0, strict=True)},
        multipliers={c.name: float(v) for c, v in zip(model.constraints, multipliers,
                                                      strict=True)},
        coordinates=reduced,
        user_coordinates=names,
        basis=basis,
        mass_matrix=Mr,
        damping_matrix=Cr,
        stiffness_matrix=Kr,
        A=A,
        B=B,
        inputs=tuple(inputs),
        input_matrix=Br,
        velocity_constraints=G,
        full_mass_matrix=mass,
        full_damping_matrix=damping,
        full_stiffness_matrix=stiffness,
    )


# The forces at an equilibrium balance to this fraction of the largest force at play.
BALANCE_TOLERANCE = 1e-6


def _require_balance(functions, values, multipliers) -> None:
    """The equilibrium checked once more, in numbers that cannot overflow a scale: a force of
    1e308 N left unbalanced was judged against an infinite scale and passed."""
    force = values["forcing"]
    reaction = values["jacobian"].T @ np.asarray(multipliers, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        residual = force - reaction
    scale = max(float(np.abs(force).max(initial=0.0)),
                float(np.abs(reaction).max(initial=0.0)), 1.0)
    worst = int(np.argmax(np.abs(residual))) if residual.size else 0
    if residual.size and not (np.all(np.isfinite(residual)) and
                              abs(residual[worst]) <= BALANCE_TOLERANCE * scale):
        name = functions.model.coordinates[worst].name
        raise ModelError(f"not an equilibrium: the forces at rest do not balance (residual "
                         f"{residual[worst]:.3g} on {name})", field="about")


def is_statically_stable(functions: AtRestFunctions, q0: np.ndarray, multipliers: np.ndarray,
                         t: float = 0.0) -> bool:
    """For a mechanism without inertia: a strict minimum of the potential on the constraints
    (the stiffness K, reduced to the admissible displacements, positive definite)."""
    values = functions.evaluate(np.asarray(q0, dtype=float), t)
    stiffness = total_stiffness(values, multipliers)
    kinds = [c.kind for c in functions.model.constraints]
    holonomic = [i for i, k in enumerate(kinds) if k == ConstraintKind.HOLONOMIC]
    velocity = [i for i, k in enumerate(kinds) if k != ConstraintKind.HOLONOMIC]
    basis, _ = independent_basis(values["jacobian"][holonomic])
    admissible = basis @ null_space(values["jacobian"][velocity] @ basis)
    reduced = admissible.T @ stiffness @ admissible
    symmetric = (reduced + reduced.T) / 2
    if symmetric.size == 0:
        return False
    scale = max(float(np.abs(symmetric).max()), 1e-300)
    return bool(np.all(np.linalg.eigvalsh(symmetric) > 1e-10 * scale))


# -- inputs -------------------------------------------------------------------------------------


def input_columns(
    eom: EquationsOfMotion, q0: np.ndarray, inputs: Sequence[str],
    parameters: Mapping[str, float] | ParameterValues | None = None, t: float = 0.0,
) -> np.ndarray:
    """df/du at rest for each named input (n x r).

    An input is a parameter (df/dp), a load (df/dp for the one parameter its force or torque
    contains, e.g. cart_pendulum's ``push`` -> F), or a coordinate (a generalized force on it).
    """
    model = eom.model
    n = len(model.q)
    columns = np.zeros((n, len(inputs)))
    values = resolve_parameters(model, parameters).symbol_values(model)
    at_rest = {v: sp.S.Zero for v in model.q_dot}
    point = {s: sp.Float(float(v)) for s, v in zip(model.q, q0, strict=True)}
    point[model.time] = sp.Float(float(t))
    names = [c.name for c in model.coordinates]
    for k, name in enumerate(inputs):
        symbol = input_parameter(model, name)
        if symbol is None:
            columns[names.index(name), k] = 1.0
            continue
        for i, f in enumerate(eom.forcing):
            if symbol in f.free_symbols:
                d = f.diff(symbol).xreplace(at_rest).xreplace(values).xreplace(point)
                columns[i, k] = float(sp.N(d))
    return columns


# -- symbolic linear matrices for small models ------------------------------------------------

SYMBOLIC_MAX_COORDINATES = 6


@dataclass(frozen=True)
class SymbolicLinearModel(SecondOrderForm):
    """M, C, K as sympy matrices at an equilibrium, parameters kept as symbols."""

    coordinates: tuple[str, ...]
    equilibrium: dict[str, sp.Expr]
    mass_matrix: sp.ImmutableMatrix
    damping_matrix: sp.ImmutableMatrix
    stiffness_matrix: sp.ImmutableMatrix

    def _repr_latex_(self) -> str:
        parts = [rf"{name} = {sp.latex(m)}" for name, m in
                 (("M", self.mass_matrix), ("C", self.damping_matrix),
                  ("K", self.stiffness_matrix))]
        return "$" + r",\quad ".join(parts) + "$"


def symbolic_linear_model(eom: EquationsOfMotion, about: Mapping[str, object]) -> SymbolicLinearModel:
    """Exact M, C, K of a small unconstrained model at the configuration ``about``."""
    model = eom.model
    n = len(model.q)
    if model.constraints:
        raise ModelError("symbolic linear matrices are available for unconstrained models only; "
                         "use the numeric linearize() for constrained ones", field="about")
    if n > SYMBOLIC_MAX_COORDINATES:
        raise ModelError(f"symbolic linear matrices are limited to {SYMBOLIC_MAX_COORDINATES} "
                         f"coordinates (this model has {n}); use the numeric linearize()",
                         field="about")
    state = resolve_state(model, about, field="about", velocities=False, time=False)
    # Exact values (sympy.pi) are kept exact; numbers near a simple multiple of pi become one.
    point = {c.symbol: _exact(about[c.name] if isinstance(about.get(c.name), sp.Basic) else q)
             for c, q in zip(model.coordinates, state.q, strict=True)}
    at_rest = {v: sp.S.Zero for v in model.q_dot}
    forcing = [as_expression(e) for e in eom.forcing]
    K = [[-d.xreplace(point) for d in jacobian_row(e.xreplace(at_rest), model.q)]
         for e in forcing]
    C = [[-d.xreplace(at_rest).xreplace(point) for d in linear_velocity_row(e, model.q_dot)]
         for e in forcing]
    M = eom.mass_matrix.xreplace(point)
    return SymbolicLinearModel(
        coordinates=tuple(c.name for c in model.coordinates),
        equilibrium={c.name: point[c.symbol] for c in model.coordinates},
        mass_matrix=sp.ImmutableMatrix(M),
        damping_matrix=sp.ImmutableMatrix(C),
        stiffness_matrix=sp.ImmutableMatrix(K),
    )


def _exact(value: object) -> sp.Expr:
    """A float near a simple multiple of pi or a rational becomes exact (sin(pi) is then 0)."""
    if isinstance(value, sp.Basic):
        return value
    number = float(value)  # type: ignore[arg-type]
    return sp.nsimplify(number, [sp.pi], tolerance=1e-12, rational=False)
