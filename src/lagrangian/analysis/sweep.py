"""Parameter studies and ensembles: the grid of points and the numbers at each, chunk by chunk.

A study varies parameters (and, for simulations, initial values) over a grid, one axis per
varied name, and may add an ensemble axis ``member`` of values drawn from distributions. The
grid is flattened and cut into chunks; ``evaluate_chunk`` computes every point of one chunk and
never raises for one point: a point that fails is NaN with its reason in ``status``. What runs
the chunks (Dask, api/sweep.py) and writes the Dataset (output/sweep.py) live downstream.

Per chunk the compiled functions are built once per process (``prepared``): the equations at
rest with the parameters as inputs (compile/parametric_at_rest.py) for modes and equilibria, the
model's C module (loaded from the on-disk cache the client filled) for simulations.
"""

from __future__ import annotations

import hashlib
import math
import pickle
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..compile.parametric_at_rest import (
    ParametricStaticFunctions,
    StaticFunctionsAt,
    integrate_ensemble,
)
from ..derivation.equations import EquationsOfMotion
from ..errors import ModelError
from ..model.values import resolve_state
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
    ROUND_OFF_TOLERANCE,
    ZERO_SQUARED_TOLERANCE,
    ZERO_TOLERANCE,
    is_stable,
    modal_analysis,
)
from .speed_form import speed_study_chunk

COMPUTES = ("modes", "equilibria", "simulate", "speeds")
OK = "ok"
NOT_COMPUTED = "not computed"

# -- distributions of an ensemble: a small grammar, read without evaluating anything -----------

_NUMBER = r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*"
_DISTRIBUTION = re.compile(rf"^\s*(normal|uniform)\s*\({_NUMBER},{_NUMBER}\)\s*$")


@dataclass(frozen=True)
class Distribution:
    """normal(mean, standard deviation) or uniform(low, high), in SI units."""

    kind: str
    a: float
    b: float

    def draw(self, rng: np.random.Generator, size: int) -> np.ndarray:
        if self.kind == "normal":
            return rng.normal(self.a, self.b, size)
        return rng.uniform(self.a, self.b, size)

    def __str__(self) -> str:
        return f"{self.kind}({self.a!r}, {self.b!r})"


def parse_distribution(text: str, field: str = "sample") -> Distribution:
    """'normal(0.3, 0.01)' (mean, standard deviation) or 'uniform(0, 1)' (low, high), SI."""
    match = _DISTRIBUTION.match(text) if isinstance(text, str) else None
    if not match:
        raise ModelError(f"expected normal(MEAN, STD) or uniform(LOW, HIGH) with numbers, got "
                         f"{text!r}", field=field)
    kind, a, b = match.group(1), float(match.group(2)), float(match.group(3))
    if not (math.isfinite(a) and math.isfinite(b)):
        raise ModelError(f"the numbers of {text!r} must be finite", field=field)
    if kind == "normal" and b < 0:
        raise ModelError(f"the standard deviation of {text!r} must not be negative", field=field)
    if kind == "uniform" and not b > a:
        raise ModelError(f"uniform(LOW, HIGH) needs LOW < HIGH, got {text!r}", field=field)
    return Distribution(kind, a, b)


# -- the study ------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SimulationOptions:
    """What each member of an ensemble integrates: to t_end (s), saved on ``samples`` times."""

    t_end: float
    method: str = "DOP853"
    rtol: float = 1e-9
    atol: float = 1e-9
    samples: int = 201
    stop_when: str | None = None
    trajectories: bool = False


@dataclass(frozen=True)
class Study:
    """A grid over ``axes`` (name -> values, SI; one dimension each, in order) and, for an
    ensemble, ``draws`` (name -> values per member, dimension ``member``)."""

    eom: EquationsOfMotion
    compute: str
    axes: tuple[tuple[str, np.ndarray], ...]
    draws: tuple[tuple[str, np.ndarray], ...] = ()
    simulation: SimulationOptions | None = None
    compiled_key: str | None = None  # the compiled module's cache key (compile/compiled.py)
    chunk_size: int = 1000
    key: str = field(default="", compare=False)
    functions_key: str = field(default="", compare=False)
    about: tuple[tuple[str, float], ...] = ()  # modes: the equilibrium, as System.modes(about)
    warnings: tuple[str, ...] = field(default=(), compare=False)  # one line each, for the user

    @property
    def model(self):
        return self.eom.model

    @property
    def dims(self) -> tuple[str, ...]:
        return (*(n for n, _ in self.axes), *(("member",) if self.draws else ()))

    @property
    def shape(self) -> tuple[int, ...]:
        members = (len(self.draws[0][1]),) if self.draws else ()
        return (*(len(v) for _, v in self.axes), *members)

    @property
    def size(self) -> int:
        return int(np.prod(self.shape, dtype=np.int64))

    @property
    def chunks(self) -> list[tuple[int, int]]:
        return [(a, min(a + self.chunk_size, self.size))
                for a in range(0, self.size, self.chunk_size)]

    @property
    def varied(self) -> tuple[str, ...]:
        return (*(n for n, _ in self.axes), *(n for n, _ in self.draws))

    def values_at(self, start: int, stop: int) -> dict[str, np.ndarray]:
        """name -> the value at each flat point index in [start, stop)."""
        index = np.unravel_index(np.arange(start, stop), self.shape)
        values = {name: np.asarray(v, float)[index[i]] for i, (name, v) in enumerate(self.axes)}
        if self.draws:
            members = index[-1]
            values.update({name: np.asarray(v, float)[members] for name, v in self.draws})
        return values


def make_study(eom: EquationsOfMotion, compute: str, vary: Mapping[str, Sequence[float]],
               sample: Mapping[str, str | Distribution] | None = None, members: int = 0,
               seed: int = 0, simulation: SimulationOptions | None = None,
               chunk_size: int | None = None,
               about: Mapping[str, float] | None = None) -> Study:
    """Check the names and values of a study and draw its ensemble (seeded)."""
    model = eom.model
    if compute not in COMPUTES:
        raise ModelError(f"compute must be one of {', '.join(COMPUTES)}, not {compute!r}",
                         field="compute")
    parameters = {p.name for p in model.parameters}
    state_names = {c.name for c in model.coordinates} | {c.velocity.name for c in model.coordinates}
    allowed = parameters | (state_names if compute == "simulate" else set())
    what = "parameter, coordinate or velocity" if compute == "simulate" else "parameter"
    axes = []
    for name, values in dict(vary or {}).items():
        _known(name, allowed, parameters, what, "vary")
        array = np.atleast_1d(np.asarray(values, dtype=float)).ravel()
        if array.size == 0:
            raise ModelError(f"no values for '{name}'", field=f"vary.{name}")
        if not np.all(np.isfinite(array)):
            raise ModelError(f"the values of '{name}' must be finite numbers", field=f"vary.{name}")
        axes.append((name, array))
    draws = []
    sample = dict(sample or {})
    if sample and members < 1:
        raise ModelError("an ensemble needs a number of members (at least 1)", field="members")
    if members and not sample:
        raise ModelError("members without a distribution to draw from: name one, e.g. "
                         "{'theta': 'normal(0.3, 0.01)'}", field="sample")
    rng = np.random.default_rng(seed)
    for name, distribution in sample.items():
        _known(name, allowed, parameters, what, "sample")
        if name in dict(axes):
            raise ModelError(f"'{name}' is both varied and sampled", field=f"sample.{name}")
        if not isinstance(distribution, Distribution):
            distribution = parse_distribution(distribution, field=f"sample.{name}")
        draws.append((name, distribution.draw(rng, int(members))))
    if compute == "speeds" and model.steady_motion is None:
        raise ModelError("compute='speeds' studies the steady motion of the model's [steady] "
                         "table, and this model has none", field="compute")
    if about and compute != "modes":
        raise ModelError("about names the equilibrium of a modes study", field="about")
    about_values = ()
    if about:
        given = resolve_state(model, about, field="about", velocities=False, time=False)
        about_values = tuple((c.name, float(v)) for c, v in zip(model.coordinates, given.q,
                                                                 strict=True)
                             if c.name in given.given)
    varied = {n for n, _ in axes} | {n for n, _ in draws}
    for p in model.parameters:
        if p.value is None and p.name not in varied:
            raise ModelError(f"parameter '{p.name}' has no value; give one or vary it",
                             field=f"parameters.{p.name}")
    if not axes and not draws:
        raise ModelError("nothing varies: give at least one name with its values", field="vary")
    speed = model.steady_motion.speed if compute == "speeds" else None
    warnings = _unused_parameters(eom, [n for n, _ in (*axes, *draws) if n != speed],
                                  parameters, allow_none=speed in varied)
    check_study_size([len(v) for _, v in axes] + ([int(members)] if draws else []),
                     _floats_per_point(compute, len(model.coordinates), simulation))
    if compute == "simulate" and simulation is None:
        raise ModelError("a simulation study needs t_end", field="t_end")
    if compute == "simulate" and not (math.isfinite(simulation.t_end) and simulation.t_end > 0):
        raise ModelError(f"the end time ({simulation.t_end} s) must be positive", field="t_end")
    if simulation is not None and simulation.samples < 2:
        raise ModelError("at least 2 samples", field="samples")
    if chunk_size is None:
        chunk_size = {"modes": 2000, "equilibria": 50, "simulate": 100, "speeds": 500}[compute]
        if compute == "simulate":
            # A compiled ensemble member costs ~0.1 ms and a Dask task a few ms: chunks of up
            # to 1000 members, at least 8 chunks so that every worker of a small cluster gets some
            size = int(np.prod([len(v) for _, v in axes], dtype=np.int64)) * max(int(members), 1)
            chunk_size = min(1000, max(100, -(-size // 8)))
    key = hashlib.sha256(pickle.dumps((model.name, str(eom.lagrangian), compute,
                                       [(n, v.tobytes()) for n, v in axes],
                                       [(n, v.tobytes()) for n, v in draws],
                                       simulation, chunk_size, about_values))).hexdigest()[:20]
    simulation_kind = None if simulation is None else (simulation.method, simulation.stop_when)
    functions_key = hashlib.sha256(pickle.dumps((model.name, str(eom.lagrangian),
                                                 str(eom.forcing), str(eom.mass_matrix),
                                                 compute == "simulate", simulation_kind))
                                   ).hexdigest()[:20]
    return Study(eom, compute, tuple(axes), tuple(draws), simulation, None, int(chunk_size), key,
                 functions_key, about_values, warnings)


def _unused_parameters(eom: EquationsOfMotion, varied: Sequence[str], parameters: set[str],
                       allow_none: bool = False) -> tuple[str, ...]:
    """A warning for each varied parameter the equations do not contain; a study that varies
    only such parameters would compute the same point again and again, and is refused."""
    unused = [n for n in varied if n in parameters and n not in eom.parameters_used]
    if not unused:
        return ()
    steady = eom.model.steady_motion
    hint = ""
    if steady is not None and steady.speed in unused:
        hint = (f"; '{steady.speed}' is the speed of the model's steady motion: study the "
                "eigenvalues against it with compute='speeds'")
    if len(unused) == len(varied) and not allow_none:
        names = ", ".join(f"'{n}'" for n in unused)
        raise ModelError(f"{names} does not appear in the equations of motion: varying it "
                         f"alone computes the same point again and again{hint}", field="vary")
    return tuple(f"'{n}' does not appear in the equations of motion: its values change "
                 f"nothing{hint}" for n in unused)


def _known(name: str, allowed: set, parameters: set, what: str, where: str) -> None:
    from ..errors import did_you_mean

    if name not in allowed:
        raise ModelError(f"'{name}' is not a {what} of this model{did_you_mean(name, allowed)}",
                         field=f"{where}.{name}" if name in parameters else where)


# -- what each compute returns: variable -> (dims after the study's own, dtype) -----------------


# A study's results are assembled in memory (one Dataset): its size is checked before any work,
# the product of the axes included, so a mistyped count is one line, not an exhausted machine.
MAX_STUDY_POINTS = 10_000_000
MAX_STUDY_BYTES = 4 * 2**30


def check_study_size(counts: Sequence[int], floats_per_point: int) -> None:
    """Refuse a study over MAX_STUDY_POINTS points or MAX_STUDY_BYTES of results."""
    points = math.prod(int(c) for c in counts)
    grid = " x ".join(str(int(c)) for c in counts)
    if points > MAX_STUDY_POINTS:
        raise ModelError(f"{grid} = {points:,} points is more than a study holds (at most "
                         f"{MAX_STUDY_POINTS:,}); use fewer values or split the study",
                         field="vary")
    size = points * floats_per_point * 8
    if size > MAX_STUDY_BYTES:
        raise ModelError(f"the results of {grid} points would take {size / 2**30:,.1f} GiB in "
                         f"memory (at most {MAX_STUDY_BYTES // 2**30} GiB); use fewer points, "
                         "fewer time samples or no trajectories", field="vary")


def _floats_per_point(compute: str, n: int, simulation: SimulationOptions | None) -> int:
    if compute == "modes":
        return 3 * n + 1 + n + n * n
    if compute == "equilibria":
        return n + 2
    if compute == "speeds":
        return 4 * n + 1
    per = 3 * 2 * n + 3
    if simulation is not None and simulation.trajectories:
        per += simulation.samples * 2 * n
    return per


def layout(study: Study) -> dict[str, tuple[tuple[str, ...], str]]:
    """The variables of one study's Dataset with their extra dimensions."""
    if study.compute == "modes":
        return {"frequency": (("mode",), "f8"), "damping_ratio": (("mode",), "f8"),
                "growth_rate": (("mode",), "f8"), "stable": ((), "f8"),
                "equilibrium": (("coordinate",), "f8"), "shape": (("mode", "coordinate"), "f8")}
    if study.compute == "equilibria":
        return {"configuration": (("equilibrium", "coordinate"), "f8"),
                "stable": (("equilibrium",), "f8"), "count": ((), "f8")}
    if study.compute == "speeds":
        return {"eigenvalue_real": (("eigenvalue",), "f8"),
                "eigenvalue_imag": (("eigenvalue",), "f8"), "stable": ((), "f8")}
    out = {"final": (("state",), "f8"), "minimum": (("state",), "f8"),
           "maximum": (("state",), "f8"), "t_final": ((), "f8"), "invariant_drift": ((), "f8"),
           "stop_time": ((), "f8")}
    if study.simulation.trajectories:
        out["trajectory"] = (("time", "state"), "f8")
    return out


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
            hit = ParametricStaticFunctions(study.eom)
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


def _parameter_vectors(parametric: ParametricStaticFunctions, values: Mapping[str, np.ndarray],
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


def _modes_chunk(study, parametric: ParametricStaticFunctions, values, count):
    n = parametric.n
    out = _empty(study, count, {"mode": n, "coordinate": n})
    vectors = _parameter_vectors(parametric, values, count)
    todo = np.arange(count)
    about = dict(study.about) or None
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
    values = parametric.evaluate(np.where(found[:, None], q_star, 0.0), vectors)
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
        done[sym] = True

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
        simple = upper.sum(axis=-1) == n
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


def _nearest_equilibria(parametric, view: StaticFunctionsAt, vectors: np.ndarray) -> np.ndarray:
    """For each parameter point (rows of ``vectors``, sharing the search spans of ``view``):
    the equilibrium found nearest the model's initial values (resolve_equilibrium without
    ``about``), or NaN where none was found."""
    model = view.model
    count = len(vectors)
    free = ~neutral_coordinates(view)
    points = starting_points(model, free)
    low, high, _ = coordinate_spans(model)
    periodic = periodic_coordinates(view)
    batch_view = StaticFunctionsAt(parametric, vectors[:, None, :], model)
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


def equilibria_at(view: StaticFunctionsAt):
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
# AVX the ensemble loop integrates four members per vector operation instead of two. api/sweep.py
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
        if status == "failed":
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
        out["status"][i] = OK if status in ("finished", "stopped") else status
    return out


def _simulation_chunk_compiled(study, functions: _SimulationFunctions, values, count, out):
    """The whole chunk in one call of the module's ensemble loop (compile/parametric_at_rest.py): each
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
    stop_time = float(result.t[-1]) if result.status == "stopped" else None
    return result.t, y, result.invariant_drift, result.status, result.message, stop_time


def _drift(energy: np.ndarray, kinetic: np.ndarray) -> float:
    """max |E - E0| / |E0| (relative to the largest T when E0 = 0), as SimulationResult's
    invariant_drift for the energy."""
    change = float(np.max(np.abs(energy - energy[0])))
    scale = abs(float(energy[0]))
    largest_t = float(np.max(np.abs(kinetic)))
    if scale <= 1e-9 * largest_t:
        scale = largest_t
    return change / scale if scale > 0 else 0.0
