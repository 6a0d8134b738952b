"""Trajectory optimisation by direct collocation on CasADi's Opti stack, solved by IPOPT.

minimise the effort J = integral of |u|^2 dt (u in the inputs' SI units) over x(t) = [q; q_dot],
u(t) on [0, t_final], subject to x_dot = rhs(x, u) at the collocation points (trapezoidal or
Hermite-Simpson), x(0) = start, x(t_final) = goal where given, and bounds on u and x.

A tree whose q and v differ (a floating base, a ball joint, a floating joint between links)
is collocated in our dynamics' x = [q; v] (dynamics/standalone/casadi_tree.py): a base's
position, quaternion (x y z w) and body twist first, a ball's quaternion (w x y z) and angular
velocity in its body's axes; each quaternion is held on |q| = 1 at the nodes (optimize_tree.py)
and the start is named as simulate's (the base at the origin, each ball unturned, at rest,
unless ``start`` names their numbers).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..compile.casadi_functions import CasadiFunctions
from ..errors import InputError, ModelError
from ..model.checked import unknown_name
from ..model.model import Model
from ..model.values import resolve_state
from ..simulation.replay import replay
from .optimize_tree import (
    check_goal,
    on_manifold,
    project,
    quaternions,
    refuse_hinges,
    tree_start,
    unit_guess,
)

METHODS = ("trapezoidal", "hermite-simpson")
OBJECTIVES = ("effort",)
MAX_NODES = 5000


@dataclass(frozen=True)
class Trajectory:
    """An optimal trajectory: ``t`` (s) at the nodes, ``states`` name -> values (rad, m,
    rad/s, m/s), ``inputs`` name -> values at the nodes (SI), ``cost`` (the objective, e.g.
    integral of u^2 dt), ``converged`` (IPOPT's verdict) and ``defects``: ``collocation`` (the
    largest residual of the discretised x_dot = rhs), ``final_state`` (the largest miss of the
    goal), ``constraints`` (the largest |Phi| at a node, 0 without constraints) and ``replay``
    (the largest state difference when u(t) is replayed through an accurate integrator: the
    discretisation error)."""

    method: str
    objective: str
    cost: float
    converged: bool
    status: str
    t: np.ndarray
    states: dict[str, np.ndarray]
    inputs: dict[str, np.ndarray]
    defects: dict[str, float]
    iterations: int
    midpoint_inputs: np.ndarray = field(repr=False, default_factory=lambda: np.zeros((0, 0)))
    # per input, the coordinate whose generalized force it is (index), None for a load
    input_coordinates: tuple[int | None, ...] = field(repr=False, default=())
    # how many generalized forces the controller gives when every input is a coordinate's:
    # the coordinates (a floating base's joints: simulate puts no force on the base)
    force_width: int = field(repr=False, default=0)

    def input_at(self, t: float) -> np.ndarray:
        """u(t) as the collocation scheme represents it: piecewise linear (trapezoidal) or
        piecewise quadratic through the nodes and midpoints (Hermite-Simpson); SI units."""
        grid = self.t
        u = np.column_stack([self.inputs[k] for k in self.inputs]) if self.inputs else \
            np.zeros((len(grid), 0))
        t = float(np.clip(t, grid[0], grid[-1]))
        k = min(int(np.searchsorted(grid, t, side="right")) - 1, len(grid) - 2)
        h = grid[k + 1] - grid[k]
        s = (t - grid[k]) / h
        if self.method == "trapezoidal":
            return (1 - s) * u[k] + s * u[k + 1]
        mid = self.midpoint_inputs[k]  # Lagrange quadratic through s = 0, 1/2, 1
        return (2 * (s - 0.5) * (s - 1)) * u[k] + (-4 * s * (s - 1)) * mid + \
            (2 * s * (s - 0.5)) * u[k + 1]

    def controller(self):
        """u(t) as an open-loop controller (t, q, q_dot) -> u with its ``inputs``, for
        ``System.simulate(t_final, initial=..., controller=trajectory.controller())``; inputs
        that are all coordinates give the n generalized forces (0 on the others)."""
        trajectory = self
        n = self.force_width or len(self.states) // 2
        rows = list(self.input_coordinates)
        if rows and all(row is not None for row in rows):  # generalized forces: B = I

            def forces(t, q, q_dot):
                tau = np.zeros(n)
                tau[rows] = trajectory.input_at(t)
                return tau

            return forces

        def open_loop(t, q, q_dot):
            return trajectory.input_at(t)

        open_loop.inputs = tuple(self.inputs)
        return open_loop

    def initial_state(self) -> dict[str, float]:
        """The state at t = 0, name -> SI value (as ``simulate(initial=...)`` takes it)."""
        return {name: float(values[0]) for name, values in self.states.items()}

    def to_dict(self) -> dict:
        """A JSON-ready document: cost, converged, t, states, inputs, defects (a number that
        is not finite, as a failed solve may leave, is null)."""
        return {"method": self.method, "objective": self.objective,
                "cost": _finite(self.cost), "converged": self.converged,
                "status": self.status, "iterations": self.iterations,
                "defects": {k: _finite(v) for k, v in self.defects.items()},
                "t": self.t.tolist(),
                "states": {k: [_finite(x) for x in v] for k, v in self.states.items()},
                "inputs": {k: [_finite(x) for x in v] for k, v in self.inputs.items()}}

    def _repr_html_(self) -> str:
        import html

        verdict = "converged" if self.converged else f"not converged ({self.status})"
        rows = "".join(f"<tr><td>{html.escape(k)}</td><td>{v:.3g}</td></tr>"
                       for k, v in self.defects.items())
        return (f"<p>Optimal trajectory, {html.escape(self.method)} collocation on "
                f"{len(self.t)} nodes: {html.escape(verdict)}; effort {self.cost:.6g}</p>"
                f"<table><tr><th>defect</th><th>largest</th></tr>{rows}</table>")

    def __repr__(self) -> str:
        verdict = "converged" if self.converged else f"not converged ({self.status})"
        return (f"Trajectory({self.method}, {len(self.t)} nodes, cost={self.cost:.6g}, "
                f"{verdict}, replay error {self.defects['replay']:.2g})")


def collocate(functions: CasadiFunctions, model: Model, t_final: float, nodes: int = 100, *,
              start: Mapping[str, float] | None = None, goal: Mapping[str, float] | None = None,
              bounds: Mapping[str, tuple[float, float]] | None = None,
              objective: str = "effort", method: str = "trapezoidal",
              tolerance: float = 1e-8, max_iterations: int = 3000) -> Trajectory:
    """Solve the optimal control problem by direct collocation on ``nodes`` points (t_final in
    s); ``start`` overrides the model's initial state, ``goal`` fixes the named states at
    t_final, ``bounds`` {name: (lower, upper)} limit inputs and states (SI)."""
    import casadi as ca

    method = _choice(method, METHODS, "method")
    _choice(objective, OBJECTIVES, "objective")
    t_final, nodes = _horizon(t_final, nodes)
    names = functions.states
    n2, r = len(names), len(functions.inputs)
    if r == 0:
        raise InputError("name at least one input to optimise (a load, parameter or "
                         "coordinate: inputs=[...])", field="inputs")
    manifold = on_manifold(model)
    rows = quaternions(model, functions) if manifold else []
    if manifold:  # named as simulate's start; a ball's Euler hinge refused naming its own
        refuse_hinges(model, functions, start, "start")
        refuse_hinges(model, functions, goal, "goal")
        _named(start, names, "start")
        first = tree_start(model, functions, start), {}
    else:
        first = _start(model, functions, start)
    target = _named(goal, names, "goal")
    check_goal(target, rows)
    lower, upper = _bounds(bounds, names, functions.inputs)

    opti = ca.Opti()
    X, U = opti.variable(n2, nodes), opti.variable(r, nodes)
    h = t_final / (nodes - 1)
    f = functions.rhs
    times = np.linspace(0.0, t_final, nodes)[None, :]  # the model's t at the nodes (s)
    timed = (ca.DM(times),) if functions.time_dependent else ()
    F = f.map(nodes)(X, U, *timed)  # x_dot at every node
    defects = []
    if method == "trapezoidal":
        defects.append(project(ca, opti, X, X[:, 1:] - X[:, :-1] - h / 2 * (F[:, :-1] + F[:, 1:]),
                               rows, target, nodes))
        cost = h / 2 * ca.sum2(ca.sum1(U[:, :-1] ** 2) + ca.sum1(U[:, 1:] ** 2))
        Um = None
    else:  # Hermite-Simpson, separated: midpoint states and inputs are variables
        Xm, Um = opti.variable(n2, nodes - 1), opti.variable(r, nodes - 1)
        Fm = f.map(nodes - 1)(Xm, Um, *((ca.DM(times[:, :-1] + h / 2),) if timed else ()))
        defects.append(Xm - (X[:, :-1] + X[:, 1:]) / 2 - h / 8 * (F[:, :-1] - F[:, 1:]))
        defects.append(project(ca, opti, X, X[:, 1:] - X[:, :-1]
                               - h / 6 * (F[:, :-1] + 4 * Fm + F[:, 1:]), rows, target, nodes))
        cost = h / 6 * ca.sum2(ca.sum1(U[:, :-1] ** 2) + 4 * ca.sum1(Um ** 2)
                               + ca.sum1(U[:, 1:] ** 2))
        opti.set_initial(Um, 0.0)
    for d in defects:
        opti.subject_to(ca.vec(d) == 0)
    fixed, free = first
    nq = len(functions.configuration) or n2 // 2  # q's entries of x, then v's
    for i, value in fixed.items():
        opti.subject_to(X[i, 0] == value)
    if functions.constraints is not None:
        m = len(functions.constraint_names)
        Phi = functions.constraints.map(nodes)(X[:nq, :], X[nq:, :], *timed)
        # the start on the constraints, at position and velocity level; the dynamics keep it
        q0, v0 = X[:nq, 0], X[nq:, 0]
        opti.subject_to(Phi[:, 0] == 0)
        opti.subject_to(_holonomic_rates(ca, functions, n2 // 2)(q0, v0, 0.0) == 0)
        constraint_rows = Phi
    else:
        m, constraint_rows = 0, None
    for i, value in target.items():
        opti.subject_to(X[i, -1] == value)
    middle = (Xm, Um) if method != "trapezoidal" else None
    for k, (lo, hi) in lower.items():  # at the nodes and, Hermite-Simpson, the midpoints
        for row in _rows(k, n2, (X, U), middle):
            opti.subject_to(opti.bounded(lo, row, hi) if hi is not None else row >= lo)
    for k, hi in upper.items():
        for row in _rows(k, n2, (X, U), middle):
            opti.subject_to(row <= hi)
    opti.minimize(cost)
    guess = unit_guess(_guess(fixed, free, target, n2, nodes), rows)
    opti.set_initial(X, guess)
    opti.set_initial(U, 0.0)
    if method != "trapezoidal":
        opti.set_initial(Xm, (guess[:, :-1] + guess[:, 1:]) / 2)
    opti.solver("ipopt", {"print_time": False},
                {"print_level": 0, "sb": "yes", "tol": tolerance, "max_iter": max_iterations})
    try:
        solution = opti.solve()
        get, converged = solution.value, True
    except RuntimeError:  # IPOPT stopped without an optimum: keep its last iterate, say so
        get, converged = opti.debug.value, False
    stats = opti.stats()
    status = str(stats.get("return_status", "unknown"))
    converged = converged and bool(stats.get("success", False))
    x, u = np.atleast_2d(get(X)), np.atleast_2d(get(U))
    x, u = x.reshape(n2, nodes), u.reshape(r, nodes)
    um = np.atleast_2d(get(Um)).reshape(r, nodes - 1).T if Um is not None else np.zeros((0, r))
    residual = max(float(np.max(np.abs(np.asarray(get(d))))) for d in defects)
    violation = float(np.max(np.abs(np.asarray(get(constraint_rows))))) if m else 0.0
    final = max((abs(float(x[i, -1]) - v) for i, v in target.items()), default=0.0)
    t = np.linspace(0.0, t_final, nodes)
    trajectory = Trajectory(
        method=method, objective=objective, cost=float(get(cost)), converged=converged,
        status=status, t=t, states={name: x[i].copy() for i, name in enumerate(names)},
        inputs={name: u[k].copy() for k, name in enumerate(functions.inputs)},
        defects={"collocation": residual, "final_state": final, "constraints": violation,
                 "replay": 0.0},
        iterations=int(stats.get("iter_count", 0)), midpoint_inputs=um,
        input_coordinates=functions.input_coordinates,
        force_width=len(functions.velocities) - 6 * functions.floating_base
        if functions.velocities else len(functions.coordinates))
    trajectory.defects["replay"] = _replay_error(functions, trajectory, x)
    return trajectory


def _holonomic_rates(ca, functions: CasadiFunctions, n: int):
    """d/dt Phi = Phi_q q_dot + Phi_t of the holonomic constraints (the rows without q_dot), a
    Function (q, q_dot, t); velocity constraints already hold at the velocity level."""
    q, v, t = ca.SX.sym("q", n), ca.SX.sym("v", n), ca.SX.sym("t")
    residual = functions.constraints(q, v, *((t,) if functions.time_dependent else ()))
    rows = [i for i in range(residual.shape[0]) if not ca.depends_on(residual[i], v)]
    rates = ca.jtimes(residual[rows], q, v) if rows else ca.SX(0, 1)
    if rows and functions.time_dependent:
        rates = rates + ca.jacobian(residual[rows], t)
    return ca.Function("rates", [q, v, t], [rates])


def _finite(x) -> float | None:
    x = float(x)
    return x if np.isfinite(x) else None


def _rows(k: int, n2: int, nodes, middle) -> list:
    """Row k of [X; U] at the nodes, and at the midpoints where they are variables."""
    pairs = [nodes] if middle is None else [nodes, middle]
    return [U[k - n2, :] if k >= n2 else X[k, :] for X, U in pairs]


def _replay_error(functions: CasadiFunctions, trajectory: Trajectory, x: np.ndarray) -> float:
    """The largest state difference at the nodes between the collocated trajectory and u(t)
    integrated accurately (DOP853, rtol 1e-10) from the same start: the discretisation error."""
    if functions.time_dependent:  # t rides along with u: rhs(x, u, t)
        states = replay(lambda y, ut: functions.rhs(y, ut[:-1], ut[-1]),
                        lambda t: np.r_[trajectory.input_at(t), t], trajectory.t, x[:, 0])
    else:
        states = replay(functions.rhs, trajectory.input_at, trajectory.t, x[:, 0])
    return float("inf") if states is None else float(np.max(np.abs(states - x)))


def _choice(value: str, allowed: Sequence[str], name: str) -> str:
    value = str(value).lower().replace("_", "-")
    if value not in allowed:
        raise InputError(f"{name} {value!r} is not one of {', '.join(allowed)}", field=name)
    return value


def _horizon(t_final, nodes) -> tuple[float, int]:
    try:
        t_final = float(t_final)
    except (TypeError, ValueError):
        raise InputError(f"t_final must be a number of seconds, not {t_final!r}",
                         field="t_final") from None
    if not np.isfinite(t_final) or t_final <= 0:
        raise InputError(f"t_final must be positive and finite, not {t_final}", field="t_final")
    if isinstance(nodes, bool) or not isinstance(nodes, (int, np.integer)) \
            or not 3 <= nodes <= MAX_NODES:
        raise InputError(f"nodes must be a whole number from 3 to {MAX_NODES}, not {nodes!r}",
                         field="nodes")
    return t_final, int(nodes)


def _named(values: Mapping[str, float] | None, names: Sequence[str], what: str) -> dict[int, float]:
    out = {}
    for key, value in dict(values or {}).items():
        name = str(key)  # a coordinate's sympy symbol names its state as its text does
        if name not in names:
            raise unknown_name(name, list(names), "state", what)
        out[list(names).index(name)] = _number(value, f"{what} {name}")
    return out


def _number(value, field: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InputError(f"expected a number, not {value!r}", field=field) from None
    if not np.isfinite(number):
        raise InputError(f"expected a finite number, not {number}", field=field)
    return number


def _start(model: Model, functions: CasadiFunctions, start) -> tuple[dict[int, float], dict]:
    """The fixed start (index -> value) and, for a constrained model given a partial start, the
    free entries (the states start does not name, placed on the constraints by the solver)
    with their guess (the model's initial values)."""
    names = functions.states
    given = _named(start, names, "start")
    state = resolve_state(model, {names[i]: v for i, v in given.items()}, field="start")
    values = [*map(float, state.q), *map(float, state.q_dot)]
    if functions.constraints is None or not given:  # the model's own start is consistent
        return {i: values[i] for i in range(len(names))}, {}
    return given, {i: values[i] for i in range(len(names)) if i not in given}


def _bounds(bounds, names: Sequence[str], inputs: Sequence[str]):
    lower, upper = {}, {}
    every = [*names, *inputs]
    for name, pair in dict(bounds or {}).items():
        if name not in every:
            raise unknown_name(name, every, "input or state", "bounds")
        try:
            lo, hi = pair
        except (TypeError, ValueError):
            raise InputError(f"expected (lower, upper), not {pair!r}",
                             field=f"bounds {name}") from None
        lo = None if lo is None else _number(lo, f"bounds {name}")
        hi = None if hi is None else _number(hi, f"bounds {name}")
        if lo is not None and hi is not None and lo > hi:
            raise InputError(f"the lower bound {lo} is above the upper bound {hi}",
                             field=f"bounds {name}")
        # a coordinate named as an input (a generalized force on it): the bound is the input's
        index = len(names) + list(inputs).index(name) if name in inputs else every.index(name)
        if lo is not None:
            lower[index] = (lo, hi)
        elif hi is not None:
            upper[index] = hi
    return lower, upper


def _guess(fixed, free, target, n2: int, nodes: int) -> np.ndarray:
    """Straight lines from the start to the goal (the start where no goal is given)."""
    begin = np.array([fixed.get(i, free.get(i, 0.0)) for i in range(n2)])
    end = np.array([target.get(i, begin[i]) for i in range(n2)])
    s = np.linspace(0.0, 1.0, nodes)
    return begin[:, None] + (end - begin)[:, None] * s[None, :]


def check_model(model: Model) -> None:
    """Refuse what collocation cannot take: anything but a model."""
    if not isinstance(model, Model):
        raise ModelError("optimize needs a model", field="optimize")


__all__ = ["METHODS", "OBJECTIVES", "Trajectory", "check_model", "collocate"]
