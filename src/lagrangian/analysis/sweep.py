"""Parameter studies and ensembles: the grid of points and the numbers at each, chunk by chunk.

A study varies parameters (and, for simulations, initial values) over a grid, one axis per
varied name, and may add an ensemble axis ``member`` of values drawn from distributions. The
grid is flattened and cut into chunks; ``evaluate_chunk`` computes every point of one chunk and
never raises for one point: a point that fails is NaN with its reason in ``status``. What runs
the chunks (Dask, study/engine.py) and writes the Dataset (output/sweep.py) live downstream.

Per chunk the compiled functions are built once per process (``prepared``): the equations at
rest with the parameters as inputs (compile/at_rest.py, parametric) for modes and equilibria, the
model's C module (loaded from the on-disk cache the client filled) for simulations.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..compile.at_rest import AtRestFunctions
from ..kinds import RunStatus
from ..model.values import resolve_state
from ..simulation.ensemble import (
    integrate_ensemble,
)
from .equilibria import (
    _difference,
    _Solver,
    coordinate_spans,
    find_equilibria,
    initial_multipliers,
    neutral_coordinates,
    periodic_coordinates,
    resolve_equilibrium,
    starting_points,
)
from .linearization import linear_model_at, total_stiffness
from .modes import (
    EIGEN_RESIDUAL_TOLERANCE,
    ROUND_OFF_TOLERANCE,
    ZERO_SQUARED_TOLERANCE,
    ZERO_TOLERANCE,
    is_stable,
    modal_analysis,
)
from .speed_form import speed_study_chunk
from .steady import steady_linear_model
from .study import (
    OK,
    Study,
    layout,
)

# -- the per-process cache of compiled functions --------------------------------------------------

_PREPARED: dict[str, object] = {}


def prepared(study: Study):
    """The compiled functions a chunk needs, built once per process and model (every study of
    the same equations shares them)."""
    key = study.functions_key + ("/speeds" if study.compute == "speeds" else "")
    hit = _PREPARED.get(key)
    if hit is None:
        if study.compute == "simulate":
            hit = _prepare_simulation(study)
        elif study.compute == "speeds":
            hit = {}  # speed forms fitted so far, by the values of the other parameters
        else:
            hit = AtRestFunctions(study.eom, parametric=True)
        if len(_PREPARED) > 8:
            _PREPARED.pop(next(iter(_PREPARED)))
        _PREPARED[key] = hit
    return hit


def evaluate_chunk(study: Study, start: int, stop: int) -> dict[str, np.ndarray]:
    """Every variable at the flat points [start, stop), and ``status`` ('ok' or why not)."""
    values = study.values_at(start, stop)
    if study.compute == "modes":
        return _modes_chunk(study, prepared(study), values, stop - start)
    if study.compute == "equilibria":
        return _equilibria_chunk(study, prepared(study), values, stop - start)
    if study.compute == "speeds":
        return speed_study_chunk(study.eom, values, stop - start, prepared(study))
    return _simulation_chunk(study, prepared(study), values, stop - start)


def _empty(study: Study, count: int, sizes: Mapping[str, int]) -> dict[str, np.ndarray]:
    out = {}
    for name, (dims, dtype) in layout(study).items():
        out[name] = np.full((count, *(sizes[d] for d in dims)), np.nan, dtype=dtype)
    out["status"] = np.full(count, OK, dtype=object)
    return out


def _reason(exc: BaseException) -> str:
    text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return text or type(exc).__name__


def _parameter_vectors(parametric: AtRestFunctions, values: Mapping[str, np.ndarray],
                       count: int) -> np.ndarray:
    # A parameter without a value is varied (make_study checked): its column is filled below.
    base = np.array([np.nan if p.value is None else float(p.value)
                     for p in parametric.model.parameters])
    vectors = np.tile(base, (count, 1))
    for i, name in enumerate(parametric.parameter_names):
        if name in values:
            vectors[:, i] = values[name]
    return vectors


# -- modes ----------------------------------------------------------------------------------------


def _modes_chunk(study, parametric: AtRestFunctions, values, count):
    n = parametric.n
    out = _empty(study, count, {"mode": n, "coordinate": n})
    vectors = _parameter_vectors(parametric, values, count)
    todo = np.arange(count)
    about = dict(study.about) or None
    steady = study.eom.model.steady_motion
    if steady is not None and about is None:  # as `lagrangian modes` takes such a model
        return _steady_modes_chunk(study, steady, values, count, out)
    if parametric.m == 0 and not parametric.static_names and about is None:
        try:
            with np.errstate(all="ignore"):
                todo = _modes_batched(study, parametric, vectors, out)
        except (np.linalg.LinAlgError, ValueError, ZeroDivisionError, FloatingPointError):
            todo = np.arange(count)  # something in the batch is singular: point by point
    for i in todo:
        try:
            view = parametric.at(vectors[i])
            q, lam = resolve_equilibrium(view, about)
            analysis = modal_analysis(linear_model_at(view, q, lam))
        except Exception as exc:  # a failing point is recorded, the study goes on
            out["status"][i] = _reason(exc)
            continue
        _store_modes(out, i, analysis, n)
    return out


def _steady_modes_chunk(study, steady, values, count, out):
    """Modes about the model's [steady] motion at each point's parameter values."""
    n = len(study.eom.model.coordinates)
    for i in range(count):
        point = {name: float(values[name][i]) for name in values}
        try:
            linear = steady_linear_model(study.eom, dict(steady.about) or None,
                                         dict(steady.rates), point)
            analysis = modal_analysis(linear)
        except Exception as exc:  # a failing point is recorded, the study goes on
            out["status"][i] = _reason(exc)
            continue
        _store_modes(out, i, analysis, n)
    return out


def _store_modes(out, i, analysis, n):
    for k, mode in enumerate(analysis.modes):
        out["frequency"][i, k] = mode.frequency
        out["damping_ratio"][i, k] = np.nan if mode.damping_ratio is None else mode.damping_ratio
        out["growth_rate"][i, k] = mode.growth_rate
        out["shape"][i, k] = [mode.shape[c] for c in analysis.linear_model.user_coordinates]
    out["stable"][i] = float(analysis.stable)
    out["equilibrium"][i] = list(analysis.equilibrium.values())
    out["status"][i] = OK


def _modes_batched(study, parametric, vectors, out) -> np.ndarray:
    """Modes of an unconstrained model at many parameter points at once: the same equilibrium
    (the one nearest the initial values), linear model and eigenproblem as System.modes, with
    numpy's stacked solvers. Returns the points left for the point-by-point path."""
    model = parametric.model
    count, n = len(vectors), parametric.n
    lengths = [i for i, p in enumerate(model.parameters)
               if p.unit in ("m", "meter", "metre")]
    # The search sees the parameters of the forces at rest and, through its spans, the
    # lengths: it runs once per distinct set of those, in groups of equal spans.
    search = sorted(set(parametric.search_parameters) | set(lengths))
    distinct, back = np.unique(vectors[:, search], axis=0, return_inverse=True)
    back = np.asarray(back).ravel()
    representatives = vectors[np.unique(back, return_index=True)[1]]
    spans = [search.index(i) for i in lengths]
    _, group = np.unique(distinct[:, spans], axis=0, return_inverse=True)
    group = np.asarray(group).ravel()
    found_q = np.full((len(distinct), n), np.nan)
    for g in range(group.max() + 1 if len(group) else 0):
        members = np.flatnonzero(group == g)
        view = parametric.at(representatives[members[0]])
        found_q[members] = _nearest_equilibria(parametric, view, representatives[members])
    q_star = found_q[back]
    found = np.all(np.isfinite(q_star), axis=-1)
    values = parametric.evaluate(np.where(found[:, None], q_star, 0.0), parameters=vectors)
    M, K, C = values["mass"], values["stiffness"], values["damping"]
    scale = np.maximum(np.abs(K).max(axis=(-1, -2)), 1e-300)
    symmetric = (~np.any(C != 0, axis=(-1, -2))) & np.all(
        np.abs(K - np.swapaxes(K, -1, -2)) <= 1e-10 * scale[:, None, None], axis=(-1, -2))
    frequency = np.full((count, n), np.nan)
    zeta = np.full((count, n), np.nan)
    growth = np.full((count, n), np.nan)
    shapes = np.full((count, n, n), np.nan + 0j)
    done = np.zeros(count, bool)

    sym = np.flatnonzero(found & symmetric)
    if sym.size:
        Ms = (M[sym] + np.swapaxes(M[sym], -1, -2)) / 2
        Ks = (K[sym] + np.swapaxes(K[sym], -1, -2)) / 2
        L = np.linalg.cholesky(Ms)  # raises for a mass matrix that is not positive definite
        Linv = np.linalg.inv(L)
        squared, w = np.linalg.eigh(Linv @ Ks @ np.swapaxes(Linv, -1, -2))
        vectors_ = np.swapaxes(Linv, -1, -2) @ w
        zero = ZERO_SQUARED_TOLERANCE * np.maximum(np.abs(squared).max(axis=-1), 1e-300)
        is_zero = np.abs(squared) <= zero[:, None]
        frequency[sym] = np.where(is_zero | (squared < 0), 0.0, np.sqrt(np.abs(squared)))
        growth[sym] = np.where(is_zero | (squared > 0), 0.0, np.sqrt(np.abs(squared)))
        zeta[sym] = 0.0
        shapes[sym] = np.swapaxes(vectors_, -1, -2).astype(complex)
        # as in modes._symmetric_modes: each pair satisfies K v = w^2 M v to 1e-9 relative,
        # else the point goes the verified point-by-point way
        w2 = np.where(is_zero, 0.0, squared)[:, None, :]
        residual = np.linalg.norm(Ks @ vectors_ - (Ms @ vectors_) * w2, axis=-2)
        bound = (np.linalg.norm(Ks, 2, axis=(-2, -1))[:, None]
                 + np.abs(w2[:, 0]) * np.linalg.norm(Ms, 2, axis=(-2, -1))[:, None]) \
            * np.linalg.norm(vectors_, axis=-2)
        done[sym] = np.all(residual <= EIGEN_RESIDUAL_TOLERANCE * bound, axis=-1)

    general = np.flatnonzero(found & ~symmetric)
    if general.size:
        Minv = np.linalg.inv(M[general])
        eye, zeros = np.broadcast_to(np.eye(n), (general.size, n, n)), np.zeros((general.size, n, n))
        A = np.concatenate([np.concatenate([zeros, eye], axis=-1),
                            np.concatenate([-Minv @ K[general], -Minv @ C[general]], axis=-1)],
                           axis=-2)
        s, V = np.linalg.eig(A)
        big = np.maximum(np.abs(s).max(axis=-1), 1e-300)[:, None]
        s = np.where(np.abs(s) <= ZERO_TOLERANCE * big, 0j, s)
        noise = ROUND_OFF_TOLERANCE * big
        s = np.where(np.abs(s.real) <= noise, 1j * s.imag, s)
        s = np.where(np.abs(s.imag) <= noise, s.real + 0j, s)
        # Every eigenvalue in a conjugate pair: each upper one is a mode. Real eigenvalues
        # (overdamped, divergent, rigid-body) pair by shape, which the single-point path does.
        upper = s.imag > 0
        # each pair satisfies A v = s v to 1e-9 relative (modes.verified_eigenpairs), else the
        # point goes the verified point-by-point way
        residual = np.linalg.norm(A @ V - V * s[:, None, :], axis=-2)
        bound = np.linalg.norm(A, 2, axis=(-2, -1))[:, None] * np.linalg.norm(V, axis=-2)
        accurate = np.all(residual <= EIGEN_RESIDUAL_TOLERANCE * bound, axis=-1)
        simple = (upper.sum(axis=-1) == n) & accurate
        rows = np.flatnonzero(simple)
        if rows.size:
            order = np.argsort(~upper[rows], axis=-1, kind="stable")[:, :n]
            picked = np.take_along_axis(s[rows], order, axis=-1)
            vecs = np.take_along_axis(V[rows][:, :n, :], order[:, None, :], axis=-1)
            magnitude = np.abs(picked)
            points = general[rows]
            frequency[points] = magnitude
            zeta[points] = -picked.real / magnitude
            growth[points] = picked.real + 0.0
            shapes[points] = np.swapaxes(vecs, -1, -2)
            done[points] = True
    # Sorted as modal_analysis sorts: by frequency, then the fastest growth first.
    rows = np.flatnonzero(done)
    order = np.lexsort((-growth[rows], frequency[rows]), axis=-1)
    for name, array in (("frequency", frequency), ("damping_ratio", zeta),
                        ("growth_rate", growth)):
        out[name][rows] = np.take_along_axis(array[rows], order, axis=-1) + 0.0
    shapes = np.take_along_axis(shapes[rows], order[:, :, None], axis=1)
    out["shape"][rows] = _normalized_shapes(shapes)
    out["stable"][rows] = (~np.any(out["growth_rate"][rows] > 0, axis=-1)).astype(float)
    out["equilibrium"][rows] = q_star[rows]
    missing = np.flatnonzero(~found)
    out["status"][missing] = ("no equilibrium found (the forces at rest balanced at none of "
                              "the configurations searched); name one to analyse about")
    return np.flatnonzero(found & ~done)


def _normalized_shapes(shapes: np.ndarray) -> np.ndarray:
    """Each shape (last axis) scaled so that its first component of largest magnitude is +1,
    real part, round-off below 1e-12 set to 0 (modes.normalized_shape, batched)."""
    magnitude = np.abs(shapes)
    top = magnitude.max(axis=-1, keepdims=True)
    reference = np.argmax(magnitude >= top * (1 - 1e-9), axis=-1)[..., None]
    pivot = np.take_along_axis(shapes, reference, axis=-1)
    safe = np.where(top > 0, pivot, 1.0)
    scaled = shapes / safe
    np.put_along_axis(scaled, reference, np.where(top > 0, 1.0 + 0j, pivot), axis=-1)
    real = scaled.real
    return np.where(np.abs(real) < 1e-12, 0.0, real)


def _nearest_equilibria(parametric, view: AtRestFunctions, vectors: np.ndarray) -> np.ndarray:
    """For each parameter point (rows of ``vectors``, sharing the search spans of ``view``):
    the equilibrium found nearest the model's initial values (resolve_equilibrium without
    ``about``), or NaN where none was found."""
    model = view.model
    count = len(vectors)
    free = ~neutral_coordinates(view)
    points = starting_points(model, free)
    low, high, _ = coordinate_spans(model)
    periodic = periodic_coordinates(view)
    batch_view = parametric.at(vectors[:, None, :], model)
    values = batch_view.evaluate(np.broadcast_to(points, (count, *points.shape)))
    lam = initial_multipliers(values)
    span = np.abs(high - low)
    sizes = (np.linalg.norm(values["forcing"], axis=-1)
             + np.linalg.norm(np.einsum("...ij,j->...i", total_stiffness(values, lam), span),
                              axis=-1)
             + np.linalg.norm(values["static_jacobian"] @ span, axis=-1))
    scale = np.median(sizes, axis=-1)
    scale = np.where(scale > 0, scale, 1e-300)[:, None]
    solver = _Solver(batch_view, 0.0, scale)
    limit = np.where(periodic, 1.0, np.maximum(np.abs(high - low) / 4, 1e-12))
    start = np.ascontiguousarray(np.broadcast_to(points, (count, *points.shape)))
    q, _, converged = solver.solve(start, lam, free, limit)
    wrapped = q.copy()
    wrapped[..., periodic] = low[periodic] + np.mod(q[..., periodic] - low[periodic], 2 * np.pi)
    flip = periodic & (low < 0) & np.isclose(wrapped, low, rtol=0, atol=1e-9)
    wrapped = np.where(flip, wrapped + 2 * np.pi, wrapped)
    ranged = np.array([c.range is not None for c in model.coordinates])
    margin = 1e-9 * (1 + np.abs(high - low))
    inside = np.all(~ranged | ((wrapped >= low - margin) & (wrapped <= high + margin)), axis=-1)
    wrapped = np.where(np.abs(wrapped) < 1e-12, 0.0, wrapped)
    initial = resolve_state(model).q_array()
    distance = np.linalg.norm(_difference(wrapped, initial, periodic), axis=-1)
    distance = np.where(converged & inside, distance, np.inf)
    best = np.argmin(distance, axis=-1)
    chosen = wrapped[np.arange(count), best]
    chosen[~np.isfinite(distance[np.arange(count), best])] = np.nan
    return chosen


# -- equilibria ---------------------------------------------------------------------------------


def equilibria_at(view: AtRestFunctions):
    """find_equilibria with linear stability, as System.equilibria does, at one point."""

    def stable(q, multipliers) -> bool:
        return is_stable(linear_model_at(view, q, multipliers))

    return find_equilibria(view, stability=stable)


def _equilibria_chunk(study, parametric, values, count):
    n = parametric.n
    found, status = [], []
    vectors = _parameter_vectors(parametric, values, count)
    for i in range(count):
        try:
            found.append(equilibria_at(parametric.at(vectors[i])))
            status.append(OK)
        except Exception as exc:
            found.append(None)
            status.append(_reason(exc))
    width = max([len(e) for e in found if e is not None] + [1])
    out = _empty(study, count, {"equilibrium": width, "coordinate": n})
    out["status"][:] = status
    for i, equilibria in enumerate(found):
        if equilibria is None:
            continue
        out["count"][i] = len(equilibria)
        for k, e in enumerate(equilibria):
            out["configuration"][i, k] = list(e.coordinates.values())
            out["stable"][i, k] = float(e.stable)
    return out


# -- ensembles of simulations -------------------------------------------------------------------


# Ensembles use the model's module with the vector kernel (codegen.generate(vector=True)) built
# for this processor (-O3 -march=native, keyed by the CPU: another machine builds its own): with
# AVX the ensemble loop integrates four members per vector operation instead of two. study/engine.py
# builds it on the client, the workers load it. (native=True names only this module.)
ENSEMBLE_NATIVE = True


@dataclass
class _SimulationFunctions:
    module: object
    names: tuple[str, ...]
    defaults: np.ndarray


def _prepare_simulation(study: Study):
    from ..compile import compiled
    from ..compile.codegen import CodegenError, generate
    from ..simulation.invariants import energy_is_conserved

    module = None
    # The compiled loop where it applies: no constraints (no projection), no stop condition
    # (no event location) and T + V the invariant (the module evaluates it); otherwise each
    # member is the single-point simulation itself.
    fast = (study.compiled_key is not None and study.eom.model.constraints == ()
            and study.simulation.stop_when is None and study.simulation.method == "DOP853"
            and energy_is_conserved(study.eom))
    if fast:
        try:
            # from the on-disk cache the caller filled; a worker on another machine builds it
            module = compiled.load_keyed(study.compiled_key,
                                         lambda: generate(study.eom, vector=True),
                                         native=ENSEMBLE_NATIVE)
        except (compiled.BackendUnavailable, CodegenError):
            module = None
    model = study.model
    defaults = np.array([np.nan if p.value is None else float(p.value) for p in model.parameters])
    return _SimulationFunctions(module, tuple(p.name for p in model.parameters), defaults)


def _simulation_chunk(study, functions: _SimulationFunctions, values, count):
    model = study.model
    options = study.simulation
    n = len(model.coordinates)
    out = _empty(study, count, {"state": 2 * n, "time": options.samples})
    if functions.module is not None:
        return _simulation_chunk_compiled(study, functions, values, count, out)
    parameter_names = set(functions.names)
    for i in range(count):
        point = {name: float(v[i]) for name, v in values.items()}
        parameters = {k: v for k, v in point.items() if k in parameter_names}
        state = {k: v for k, v in point.items() if k not in parameter_names}
        try:
            run = _simulate_member(study, functions, parameters, state)
        except Exception as exc:
            out["status"][i] = _reason(exc)
            continue
        t, y, drift, status, message, stop_time = run
        if status == RunStatus.FAILED:
            out["status"][i] = message
            continue
        out["final"][i] = y[-1]
        out["minimum"][i] = y.min(axis=0)
        out["maximum"][i] = y.max(axis=0)
        out["t_final"][i] = t[-1]
        out["invariant_drift"][i] = np.nan if drift is None else drift
        out["stop_time"][i] = np.nan if stop_time is None else stop_time
        if options.trajectories:
            out["trajectory"][i, : len(t)] = y
        out["status"][i] = OK if status in (RunStatus.FINISHED, RunStatus.STOPPED) else status
    return out


def _simulation_chunk_compiled(study, functions: _SimulationFunctions, values, count, out):
    """The whole chunk in one call of the module's ensemble loop (compile/at_rest.py, parametric): each
    member the same DOP853 steps as the single-point simulate, the summaries computed in C."""
    model = study.model
    options = study.simulation
    vectors = np.tile(functions.defaults, (count, 1))
    for i, name in enumerate(functions.names):
        if name in values:
            vectors[:, i] = values[name]
    start = resolve_state(model, field="initial")
    states = np.tile(np.concatenate([start.q_array(), start.q_dot_array()]), (count, 1))
    for i, c in enumerate(model.coordinates):
        for offset, name in ((0, c.name), (len(model.coordinates), c.velocity.name)):
            if name in values:
                states[:, offset + i] = values[name]
    grid = np.linspace(start.t, options.t_end, options.samples)
    run = integrate_ensemble(functions.module, vectors, states, grid, options.rtol, options.atol,
                             trajectories=options.trajectories)
    out["final"][:] = run.final
    out["minimum"][:] = run.minimum
    out["maximum"][:] = run.maximum
    out["t_final"][:] = run.t_final
    out["invariant_drift"][:] = run.drift
    if options.trajectories:
        out["trajectory"][:] = run.trajectory
    for i in np.flatnonzero(run.status != 0):
        out["status"][i] = f"integration failed at t = {run.t_reached[i]:.9g} s"
    return out


def _simulate_member(study, functions, parameters, state):
    """(t, y, invariant drift or None, status, message, stop time or None) of one member by the
    single-point simulate (constraints, stop conditions, other methods, no compiled module)."""
    options = study.simulation
    model = study.model
    from ..simulation.options import SaveAt, StepControl
    from ..simulation.simulate import parse_stop_condition, simulate

    stop = parse_stop_condition(options.stop_when, model) if options.stop_when else None
    result = simulate(study.eom, options.t_end, initial=state, parameters=parameters,
                      step_control=StepControl(options.method, options.rtol, options.atol),
                      save_at=SaveAt(options.samples), stop=stop)
    y = np.concatenate([result.q, result.q_dot], axis=1)
    stop_time = float(result.t[-1]) if result.status == RunStatus.STOPPED else None
    return result.t, y, result.invariant_drift, result.status, result.message, stop_time


