"""simulate for a tree whose q and v differ in length, a floating base or ball joints (fixed or
floating base): y = [q, v (nv)] integrated on the manifold (simulation/tree_state.py).

q_dot from v by the free flyer's kinematics (position rate R v_lin, quaternion rate
1/2 q (x) (0, omega)), the base's quaternion renormalized after each accepted step and at each
sample; a free flyer below the root (a URDF floating joint between links) its position by
R(quat) v_lin in its parent's joint frame, its quaternion as a ball's; each ball joint as
q = c (x) exp(d) (q (+) d, MuJoCo's mj_integratePos), the solver
stepping the turn d (3 numbers, rad) by d_dot = J_r(d)^-1 omega (omega in the body's axes)
and moving the centre c to the ball when |d| passes tree_state.RECENTRE (restarting there with
the step size it had), so a ball's quaternion is of norm 1 by construction; v_dot by the
tree's forward dynamics (scipy's stepped loop; the compiled DOP853 loop takes q_dot = v only).
A stop condition (which may name the base's and the balls' numbers) and the joints' position
limits end the run as on a fixed base (simulation/simulate.py): the event located on the
step's dense output. A ball joint has no position limit (MJCF's cone range is
refused as the file is read).
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Mapping

import numpy as np

from ..errors import DynamicsWarning, InputError
from ..kinds import InvariantKind, RunStatus
from ..model.values import State
from .events import StopCondition, parse_stop_condition
from .guards import GuardedRhs, StepCollapse, check_start
from .integration_loops import LoopRun, crossing_time, touch_inside
from .invariants import cumulative_work
from .options import SaveAt, StepControl
from .result import STATUS_MESSAGES, SimulationResult
from .simulate import (
    at_limit,
    beyond_limits,
    check_start_rates,
    check_start_within,
    exceeded_limits,
    urdf_limits,
)
from .tree_state import BallCharts, TreeState


def configuration_rate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """q_dot (nq) of a floating-base state: base position rate R v_lin (m/s, world axes),
    quaternion rate 1/2 q (x) (0, omega) (x y z w; omega in base axes, rad/s), joint rates v."""
    rate = np.empty(len(q))
    base_rate(q, v, rate)
    rate[7:] = v[6:]
    return rate


def base_rate(q: np.ndarray, v: np.ndarray, rate: np.ndarray) -> None:
    """The base's seven entries of q_dot into ``rate`` (configuration_rate)."""
    x, y, z, w = (float(c) for c in q[3:7])
    vx, vy, vz, wx, wy, wz = (float(c) for c in v[:6])
    # R(q/|q|) v_lin written out (model/quaternions.py's matrix): a (1, 3, 3) stack of numpy
    # calls per right-hand side cost 30 times the tree's forward dynamics
    s = 2.0 / (x * x + y * y + z * z + w * w)
    rate[0] = (1 - s * (y * y + z * z)) * vx + s * (x * y - z * w) * vy + s * (x * z + y * w) * vz
    rate[1] = s * (x * y + z * w) * vx + (1 - s * (x * x + z * z)) * vy + s * (y * z - x * w) * vz
    rate[2] = s * (x * z - y * w) * vx + s * (y * z + x * w) * vy + (1 - s * (x * x + y * y)) * vz
    rate[3:7] = 0.5 * np.array([w * wx + y * wz - z * wy,
                                w * wy + z * wx - x * wz,
                                w * wz + x * wy - y * wx,
                                -x * wx - y * wy - z * wz])


class FloatingControl:
    """A controller's generalized forces on a floating base: (t, q, v) -> u with u the n joint
    torques (N m or N; the base unactuated, as a legged robot's), or all nv = n + 6 entries
    with the base's wrench first (force, then moment, base axes: a thruster, a drone). On a
    fixed base, all nv entries (a ball's three: the moment in its body's axes, N m)."""

    def __init__(self, controller, nv: int, floating: bool = True):
        if not callable(controller):
            raise InputError("the controller must be a callable (t, q, v) -> u",
                             field="controller")
        self.controller, self.nv, self.floating = controller, nv, floating

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        u = np.asarray(self.controller(t, q, v), dtype=float)
        joints = self.nv - 6
        if self.floating and u.shape == (joints,):
            u = np.concatenate([np.zeros(6), u])
        elif u.shape != (self.nv,):
            raise InputError(f"the controller returned shape {u.shape}; expected "
                             + (f"({joints},) joint torques or ({self.nv},) with the base's "
                                "wrench first" if self.floating else f"({self.nv},), one per "
                                "velocity number"), field="controller")
        if not np.all(np.isfinite(u)):
            raise InputError(f"the controller returned a value that is not finite at "
                             f"t = {t:.9g} s", field="controller")
        return u


def floating_stop_condition(text: str, dynamics, model) -> StopCondition:
    """``text`` ('base_z < 0.2', 'knee > 1', 'shoulder_qw < 0.9') parsed with the base's names
    (base_x .. base_qw, base_vx .. base_wz) and the balls' (<ball>_qw .. _qz, <ball>_wx ..
    _wz) beside the model's; one line for an unknown name or a ball's Euler hinge."""
    import sympy as sp

    state = TreeState(dynamics, model)
    # a free flyer's x y z are the model's coordinates too: parsed as the model's
    own = (*state.base_q, *state.base_v, *sorted(state.ball_q), *sorted(state.ball_v),
           *sorted(state.free_q - set(state.free_model)), *sorted(state.free_v))
    stop = parse_stop_condition(text, model, names={name: sp.Symbol(name) for name in own})
    for symbol in sorted(stop.function.free_symbols, key=str):
        state.refuse_hinge(str(symbol), "stop_when")
    return stop


def _stop_event(stop: StopCondition, state: TreeState, model, parameters):
    """g(q, v, t) of a stop condition (> 0 where it holds), q and v in the tree's layout."""
    import sympy as sp

    from ..compile.lambdified import numpy_function

    values = {p.symbol: parameters[p.name] for p in model.parameters
              if parameters.get(p.name) is not None}
    by_name = {c.name: c for c in model.coordinates}
    q_args = [by_name[n].symbol if n in by_name else sp.Symbol(n) for n in state.q_names]
    v_args = [by_name[n].velocity if n in by_name else sp.Symbol(n) for n in state.v_names]
    g = numpy_function([*q_args, *v_args, model.time], stop.function.xreplace(values))

    def event(q, v, t) -> float:
        return float(np.real(g(*q, *v, t)))

    return event


def _limit_event(limits, state: TreeState, q0):
    """The joints' position-limit event (simulate.beyond_limits) on the tree's layout; a joint
    that starts on its limit (the Panda's finger at 0) hides no other joint's crossing."""
    beyond = beyond_limits(limits, state.joints_q(q0))
    return None if beyond is None else (
        lambda q, v, t: beyond(state.joints_q(q), state.joints_v(v), t)), beyond


def simulate_floating(system, t_end: float, initial, step_control: StepControl,
                      save_at: SaveAt, controller=None, stop: str | StopCondition | None = None,
                      limits: bool = True, progress=None) -> SimulationResult:
    """Integrate a floating-base robot, or one with ball joints, to ``t_end`` (s) with the
    model's own loads (its tau_<joint> parameters), gravity and a ``controller``'s forces
    (FloatingControl); every quaternion kept of norm 1 after every step. ``stop`` ends the
    run where it turns true (status 'stopped'), a joint reaching its URDF position limit ends
    it with status 'limit' (``limits`` False: the joints run through them), as simulate does
    on a fixed base."""
    from scipy.integrate import BDF, DOP853, LSODA, RK23, RK45, Radau

    dynamics = system.dynamics()
    model = system.model
    state = TreeState(dynamics, model)
    if isinstance(stop, str):
        stop = floating_stop_condition(stop, dynamics, model)
    joint_limits = urdf_limits(model, positions=limits)
    t0, q0, v0 = state.start(model, initial)
    # the limits are the model's; run with them ignored, a start beyond one is said in the result
    every = joint_limits if limits else urdf_limits(model)
    rule = "refuse" if limits else "ignore"
    _, beyond_at_start = check_start_within(every, state.joints_q(q0), rule)
    _, too_fast = check_start_rates(every, state.joints_v(v0), rule)
    beyond_at_start = "; ".join(note for note in (beyond_at_start, too_fast) if note)
    if not (np.isfinite(t_end) and t_end > t0):
        raise InputError(f"the end time ({t_end} s) must be after the start time ({t0} s)",
                         field="t_end")
    nq, nv = dynamics.nq, dynamics.nv
    zero = np.zeros(nv)
    control = None if controller is None else FloatingControl(controller, nv, state.floating)
    evaluations = [0]
    q_of, v_of = state.q_index, state.v_index

    chart = BallCharts(state, q0)  # each ball's quaternion stepped as a turn from a centre
    nz = chart.nz

    def rhs(t, y, controlled=True):
        evaluations[0] += controlled  # the run's calls: the start's check is not one
        # the base's quaternion leaves the unit sphere by a step's error (the dynamics read
        # q/|q|); a ball's is on it by construction (c exp(d))
        q, v = chart.q(y[:nz]), y[nz:]
        tau = zero if control is None or not controlled else control(t, q, v)
        rate = np.empty(nq)
        if state.floating:
            base_rate(q, v, rate)
        for _, iq, iv in state.free:  # x y z rate R v_lin (its quaternion's: the chart's)
            base_rate(q[iq:iq + 7], v[iv:iv + 6], rate[iq:iq + 7])
        rate[q_of] = v[v_of]
        return np.concatenate([chart.rate(y[:nz], v, rate),
                               dynamics.forward_dynamics(q, v, tau)])

    def full(y):  # [q, v] of the solver's [z, v]: every quaternion of norm 1
        return np.concatenate([chart.q(y[:nz]), y[nz:]])

    solvers = {"DOP853": DOP853, "RK45": RK45, "RK23": RK23, "Radau": Radau, "BDF": BDF,
               "LSODA": LSODA}
    if step_control.method not in solvers:  # StepControl knows more than scipy steps here
        raise InputError(f"a floating base or a ball joint integrates with "
                         f"{', '.join(solvers)}, not "
                         f"{step_control.method}", field="method")
    solver_class = solvers[step_control.method]
    options = {} if step_control.max_step is None else {"max_step": step_control.max_step}
    grid = np.linspace(t0, t_end, save_at.samples)
    y0 = np.concatenate([chart.z0(q0), v0])
    # a rate that overflows the accelerations at once: refused (simulation/guards.py)
    rates = tuple(n if n not in state.q_names else f"{n}_dot" for n in state.v_names)
    # the robot's own motion: the controller is not called for it (its calls are the run's)
    given = tuple(initial.given if isinstance(initial, State) else initial or ())
    check_start(lambda t, y: rhs(t, y, controlled=False), t0, y0, rates, given)
    guarded = GuardedRhs(rhs, step_control.method, len(y0), t0, t_end)
    solver = None  # built in the loop's try: its first step size calls the guarded rhs
    user = None if stop is None else _stop_event(stop, state, model, system.parameters)
    limit, beyond = _limit_event(joint_limits, state, q0)
    event = user if limit is None else limit if user is None else (
        lambda q, v, t: max(user(q, v, t), limit(q, v, t)))
    samples, times = [np.concatenate([q0, v0])], [t0]
    k, steps, status, message = 1, 0, RunStatus.FINISHED, STATUS_MESSAGES["finished"]
    armed = event is not None and event(q0, v0, t0) < 0  # true at the start: not a crossing
    began = time.perf_counter()

    try:
        # overflow in a failing step is the run's verdict, not numpy's or the tree's text
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", DynamicsWarning)
            solver = solver_class(guarded, t0, y0, t_end, rtol=step_control.rtol,
                                  atol=step_control.atol, **options)
            while k < len(grid):
                message_of_step = solver.step()
                steps += 1
                if solver.status == "failed" or not np.all(np.isfinite(solver.y)):
                    status = RunStatus.FAILED
                    message = f"the step failed at t = {solver.t:.6g} s: {message_of_step}"
                    break
                guarded.accepted(solver.t)
                step = solver.dense_output()
                dense = lambda t, step=step: full(step(t))  # noqa: E731 - in q's layout
                # the base's quaternion back on the unit sphere: |q| drifts by the step's error
                if state.floating:
                    solver.y[3:7] /= np.linalg.norm(solver.y[3:7])
                y_new = full(solver.y)
                t_stop, hit = solver.t, False
                if event is not None:
                    g_new = event(y_new[:nq], y_new[nq:], solver.t)
                    touch = None if not armed or g_new >= 0 else touch_inside(
                        event, dense, solver.t_old, solver.t, nq)
                    if armed and (g_new >= 0 or touch is not None):  # as the fixed base's loop
                        end = solver.t if touch is None else touch
                        t_stop = crossing_time(event, dense, solver.t_old, end, nq)
                        hit = True
                    elif g_new < 0:
                        armed = True
                while k < len(grid) and grid[k] <= t_stop:
                    samples.append(dense(grid[k]))
                    times.append(float(grid[k]))
                    k += 1
                if hit:
                    if t_stop > times[-1]:
                        samples.append(dense(t_stop))
                        times.append(float(t_stop))
                    status, message = RunStatus.STOPPED, f"stop condition met at t = {t_stop:.12g} s"
                    break
                if solver.status == "finished" and k < len(grid):
                    samples.append(y_new)
                    times.append(float(grid[k]))
                    k += 1
                if progress is not None:
                    progress(solver.t)
                restart = solver.y.copy()
                if solver.status == "running" and chart.recentre(restart):
                    # the step size carries over: a restart costs one call (the solver's f)
                    first = min(solver.step_size or np.inf, t_end - solver.t)
                    solver = solver_class(guarded, solver.t, restart, t_end,
                                          rtol=step_control.rtol, atol=step_control.atol,
                                          first_step=first if 0 < first < np.inf else None,
                                          **options)
    except KeyboardInterrupt:
        reached = t0 if solver is None else solver.t
        status, message = RunStatus.INTERRUPTED, f"interrupted at t = {reached:.6g} s"
    except StepCollapse as collapse:
        status, message = RunStatus.FAILED, collapse.message
    except ValueError:  # Radau's or BDF's LU of a Jacobian that is not finite
        collapse = guarded.jacobian_failure()
        if collapse is None:
            raise
        status, message = RunStatus.FAILED, collapse.message
    wall = time.perf_counter() - began
    Y = np.array(samples)
    t = np.array(times)
    if status == RunStatus.STOPPED and beyond is not None:  # a joint's limit, or the condition
        y = Y[-1]
        there = None if user is None else user(y[:nq], y[nq:], t[-1])
        joints = LoopRun(t[-1:], np.r_[state.joints_q(y[:nq]), state.joints_v(y[nq:])][None],
                         status, message, steps, 0)
        decided = at_limit(joints, [m for m in joint_limits if m.lower is not None
                                    and m.upper is not None], beyond,
                           None if there is None else (lambda *_: there), state.n)
        status, message = decided.status, decided.message
    if beyond_at_start:
        message = f"{message}; warning: {beyond_at_start}"
    q, v = Y[:, :nq], Y[:, nq:]
    kinetic = dynamics.kinetic_energy(q, v)
    energy = kinetic + dynamics.potential_energy(q)
    own = state.on_joints(_joint_forces(model, system.parameters))  # the model's tau_<joint>
    power = v @ own
    if control is not None:  # the controller's power at the samples: the work balance
        power = power + np.einsum("ij,ij->i", v, np.array([control(ti, qi, vi) for ti, qi, vi
                                                             in zip(t, q, v, strict=True)]))
    working = bool(np.any(own != 0)) or control is not None
    kind = InvariantKind.WORK_BALANCE if working else InvariantKind.ENERGY
    return SimulationResult(
        model=model, coordinates=tuple(dynamics.coordinates), constraint_names=(),
        parameters=dict(system.parameters), t=t, q=q, q_dot=v, energy=energy, power=power,
        multipliers=np.zeros((len(t), 0)), residuals=np.zeros((len(t), 0)),
        step_control=step_control, status=status, message=message, steps=steps,
        nfev=evaluations[0], wall_time=wall, backend=f"scipy {solver_class.__name__}",
        energy_conserved=not working, t_end=float(t_end), kinetic_energy=kinetic,
        invariant=kind, invariant_values=energy,
        work=cumulative_work(t, power) if working else None,
        velocity_names=tuple(dynamics.velocity_names),
        stop_when=stop.text if stop is not None else None,
        limits_exceeded=exceeded_limits(joint_limits, system.parameters, t, state.joints_v(v)))


def _joint_forces(model, parameters: Mapping[str, float]) -> np.ndarray:
    """Each joint's generalized force from the model's loads (N m or N) at the parameter
    values; a robot's are constant (tau_<joint> parameters)."""
    import sympy as sp

    given: dict[str, list] = {}
    for coordinate, force in model.generalized_forces:
        given.setdefault(coordinate, []).append(force)
    values = {p.symbol: parameters[p.name] for p in model.parameters
              if parameters.get(p.name) is not None}
    return np.array([float(sp.Add(*given.get(c.name, [])).xreplace(values))
                     for c in model.coordinates])
