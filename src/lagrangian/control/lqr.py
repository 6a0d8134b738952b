"""The linear-quadratic regulator about a linear model x_dot = A x + B u (analysis/linearization.py):
u = -K x minimizes int (x^T Q x + u^T R u) dt, K = R^-1 B^T S with S from the continuous
algebraic Riccati equation A^T S + S A - S B R^-1 B^T S + Q = 0 (scipy's solver).

x = [z - z0; z_dot] in the linear model's coordinates z about its equilibrium z0 (SI units). On a
robot with ball joints z are the model's Euler angles and the run's state is read into them
(lqr_charts.py).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from ..analysis.linearization import LinearModel
from ..errors import InputError
from .gains import square_matrix
from .lqr_charts import TreeCharts

# A mode counts as unstable (needs the inputs) when its real part is above -this x |A|.
_MARGINAL = 1e-9


@dataclass(frozen=True, repr=False)
class LQR:
    """The regulator u = -K x and what it promises: the closed-loop eigenvalues eig(A - B K)
    (1/s). Called as (t, q, q_dot) -> u (one value per input), it is a controller for
    System.simulate; ``inputs`` tells simulate what u drives."""

    K: np.ndarray
    S: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    A: np.ndarray
    B: np.ndarray
    inputs: tuple[str, ...]
    state_names: tuple[str, ...]
    equilibrium: dict[str, float]
    _positions: np.ndarray  # index of each z in the model's coordinates
    _origin: np.ndarray  # z0
    # the inputs' values that hold the equilibrium (the linear model's trim), and what u adds
    # to the model's own values to reach them (trim - nominal; 0 where the model's hold it)
    trim: dict[str, float] = field(default_factory=dict)
    _offset: np.ndarray | None = None
    # a robot with ball joints: its Euler charts (lqr_charts.py), the inputs' generalized
    # forces B_q (n x r) and the whole equilibrium in the model's coordinates
    _charts: TreeCharts | None = None
    _forces: np.ndarray | None = None
    _about: np.ndarray | None = None

    @property
    def gain(self) -> np.ndarray:
        return self.K

    @property
    def closed_loop(self) -> np.ndarray:
        """A - B K."""
        return self.A - self.B @ self.K

    @property
    def closed_loop_eigenvalues(self) -> np.ndarray:
        """eig(A - B K) (1/s), the least stable first."""
        values = np.linalg.eigvals(self.closed_loop)
        return values[np.lexsort((values.imag, -values.real))]

    def state(self, q, q_dot) -> np.ndarray:
        """x = [z - z0; z_dot] from the model's q and q_dot, shape (..., 2p); on a robot with
        ball joints also from the run's (a ball's quaternion and angular velocity: the Euler
        angles nearest the equilibrium and their rates)."""
        q, v = np.asarray(q, dtype=float), np.asarray(q_dot, dtype=float)
        if self._on_tree(q):
            q, v, _ = self._charts.model_state(q, v, self._about)
        return np.concatenate([q[..., self._positions] - self._origin,
                               v[..., self._positions]], axis=-1)

    def __call__(self, t, q, q_dot) -> np.ndarray:
        """u = u* - K x on top of the model's own input values, u* what holds the equilibrium
        (trim - nominal; the inputs' units: N, N m, or the parameter's). Given the run's state
        of a robot with ball joints, the tree's nv generalized forces E^-T B_q u instead (a
        ball's moment in its body's axes, N m), as simulate takes them."""
        if self._on_tree(np.asarray(q)):
            theta, rates, E = self._charts.model_state(q, q_dot, self._about)
            x = np.concatenate([theta[self._positions] - self._origin, rates[self._positions]])
            u = -(self.K @ x) if self._offset is None else self._offset - self.K @ x
            return self._charts.torques(E, self._forces @ u)
        u = -(self.K @ self.state(q, q_dot))
        return u if self._offset is None else self._offset + u

    def _on_tree(self, q: np.ndarray) -> bool:
        """Whether q is the tree's (quaternions) rather than the model's Euler angles."""
        return self._charts is not None and q.shape[-1] == self._charts.nq

    def summary(self) -> dict:
        """JSON-ready: inputs, states, K, closed-loop eigenvalues (re, im)."""
        return {"inputs": list(self.inputs), "states": list(self.state_names),
                "equilibrium": dict(self.equilibrium), "trim": dict(self.trim),
                "K": self.K.tolist(),
                "closed_loop_eigenvalues": [[float(v.real), float(v.imag)]
                                            for v in self.closed_loop_eigenvalues]}

    def __repr__(self) -> str:
        slowest = self.closed_loop_eigenvalues[0]
        trim = ", ".join(f"{k}={v:.6g}" for k, v in self.trim.items())
        return (f"LQR(inputs={list(self.inputs)}, states={list(self.state_names)}, "
                f"{'trim ' + trim + ', ' if trim else ''}"
                f"slowest closed-loop eigenvalue {slowest:.4g} 1/s)\nK =\n{self.K}")


def lqr(linear_model: LinearModel, Q, R) -> LQR:
    """The LQR about ``linear_model`` (System.linearize(about, inputs=[...]) or a modal
    analysis' ``linear_model``): weights Q on x = [z - z0; z_dot] (number, diagonal or
    matrix, positive semidefinite) and R on u (positive definite). Refused in one line when
    (A, B) is not stabilizable or Q leaves an unstable mode unweighted. On a robot with ball
    joints z are the model's Euler angles and the inputs generalized forces there (its
    coordinates, actuators), the controller taking the run's quaternion state."""
    import scipy.linalg

    model = getattr(linear_model, "linear_model", linear_model)  # a ModalAnalysis too
    if not isinstance(model, LinearModel):
        raise InputError("lqr takes a LinearModel (System.linearize(about, inputs=[...]))",
                         field="linear_model")
    if model.steady or model.state_constraints.size:
        raise InputError("lqr needs a linear model about an equilibrium, not a steady motion",
                         field="linear_model")
    charts = getattr(model, "charts", None)  # a robot with ball joints: lqr_charts.py
    if charts is not None:
        charts.check_inputs(model.inputs)
    A, B = np.asarray(model.A, dtype=float), np.asarray(model.B, dtype=float)
    size, width = A.shape[0], B.shape[1]
    if width == 0:
        raise InputError("the linear model has no inputs: System.linearize(about, inputs=[...]) "
                         "or System.modes(about, inputs=[...]) names the loads, parameters or "
                         "coordinates the controller drives", field="linear_model")
    Q = square_matrix(Q, size, "Q")
    R = square_matrix(R, width, "R", definite=True)
    _require_stabilizable(A, B, model.inputs)
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")  # a failing solve warns first: the refusal says it
            S = scipy.linalg.solve_continuous_are(A, B, Q, R)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise InputError(f"no stabilizing Riccati solution ({exc}); Q must weigh every "
                         "unstable mode", field="Q") from None
    try:  # a subnormal R (2e-309) overflows K: refused below as not stabilizing, quietly
        with np.errstate(all="ignore"):
            K = np.linalg.solve(R, B.T @ S)
            closed = np.linalg.eigvals(A - B @ K) if np.all(np.isfinite(K)) \
                else np.array([np.nan])
    except np.linalg.LinAlgError:  # a solution too ill-conditioned to trust: refused as one
        closed = np.array([np.nan])
    if not np.all(closed.real < 0):
        raise InputError("the Riccati solution does not stabilize (A, B): Q must weigh every "
                         "unstable mode", field="Q")
    names = list(model.user_coordinates)
    positions = np.array([names.index(c) for c in model.coordinates], dtype=int)
    origin = np.array([model.equilibrium[c] for c in model.coordinates], dtype=float)
    trim = dict(model.trim)
    offset = np.array([trim[name] - model.nominal_inputs.get(name, 0.0) for name in model.inputs],
                      dtype=float) if trim else None
    return LQR(K=K, S=S, Q=Q, R=R, A=A, B=B, inputs=tuple(model.inputs),
               state_names=tuple(model.state_names), equilibrium=dict(model.equilibrium),
               _positions=positions, _origin=origin, trim=trim,
               _offset=offset if offset is not None and np.any(offset) else None,
               _charts=charts, _forces=None if charts is None else model.input_matrix,
               _about=None if charts is None else np.array([model.equilibrium[c] for c in names]))


def _require_stabilizable(A: np.ndarray, B: np.ndarray, inputs) -> None:
    """The PBH test: every mode with Re(lambda) >= 0 is moved by B (rank [A - lambda I, B] = n)."""
    size = A.shape[0]
    scale = max(float(np.abs(A).max()), 1.0)
    for value in np.linalg.eigvals(A):
        if value.real < -_MARGINAL * scale:
            continue
        pencil = np.hstack([A - value * np.eye(size), B.astype(complex)])
        singular = np.linalg.svd(pencil, compute_uv=False)
        if singular[-1] <= 1e-9 * max(singular[0], 1e-300):
            raise InputError(f"(A, B) is not stabilizable: the mode with eigenvalue "
                             f"{value:.4g} 1/s is not moved by the inputs "
                             f"({', '.join(inputs)})", field="linear_model")
