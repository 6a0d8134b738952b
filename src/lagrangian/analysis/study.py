"""A parameter study or ensemble, as data: the grid of points (one axis per varied name, and
an ensemble axis ``member`` of values drawn from distributions), its options, its limits and the
variables each kind of study computes (``layout``). Checked in ``make_study`` before any work;
the numbers are computed chunk by chunk in sweep.py, the chunks run by the engine in api/."""

from __future__ import annotations

import hashlib
import math
import pickle
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..errors import ModelError
from ..kinds import DistributionKind
from ..model.values import resolve_state

COMPUTES = ("modes", "equilibria", "simulate", "speeds")
OK = "ok"
NOT_COMPUTED = "not computed"

# -- distributions of an ensemble: a small grammar, read without evaluating anything -----------

_NUMBER = r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*"
_DISTRIBUTION = re.compile(rf"^\s*({'|'.join(DistributionKind)})\s*\({_NUMBER},{_NUMBER}\)\s*$")


@dataclass(frozen=True)
class Distribution:
    """normal(mean, standard deviation) or uniform(low, high), in SI units."""

    kind: DistributionKind
    a: float
    b: float

    def __post_init__(self):
        object.__setattr__(self, "kind", DistributionKind(self.kind))

    def draw(self, rng: np.random.Generator, size: int) -> np.ndarray:
        if self.kind == DistributionKind.NORMAL:
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
    if kind == DistributionKind.NORMAL and b < 0:
        raise ModelError(f"the standard deviation of {text!r} must not be negative", field=field)
    if kind == DistributionKind.UNIFORM and not b > a:
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


def _digest(*expressions) -> str:
    """The expressions' content as a digest, the same in every process: a hash of each node from
    its class and its arguments' hashes, each shared node hashed once (printing the bicycle's M
    and f took 1-3 s; this takes milliseconds). sympy keeps arguments in a canonical order."""
    memo: dict[int, tuple[str, object]] = {}

    def node(x) -> str:
        seen = memo.get(id(x))
        if seen is not None:
            return seen[0]
        if x.args:
            text = type(x).__name__ + "(" + ",".join(node(a) for a in x.args) + ")"
        elif isinstance(x, sp.Float):
            text = "Float" + repr(x._mpf_)  # every bit, not the printed digits
        elif isinstance(x, sp.Symbol):
            text = type(x).__name__ + ":" + x.name + repr(sorted(x.assumptions0.items()))
        else:
            text = type(x).__name__ + ":" + str(x)
        digest = hashlib.blake2b(text.encode(), digest_size=16).hexdigest()
        memo[id(x)] = (digest, x)  # x held, so that its id is not reused meanwhile
        return digest

    trees = [sp.sympify(e) for e in expressions]  # safe: derived sympy objects, never text
    return hashlib.sha256(",".join(node(t) for t in trees).encode()).hexdigest()


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
    equations = _digest(eom.lagrangian, eom.forcing, eom.mass_matrix)
    key = hashlib.sha256(pickle.dumps((model.name, equations, compute,
                                       [(n, v.tobytes()) for n, v in axes],
                                       [(n, v.tobytes()) for n, v in draws],
                                       simulation, chunk_size, about_values))).hexdigest()[:20]
    simulation_kind = None if simulation is None else (simulation.method, simulation.stop_when)
    functions_key = hashlib.sha256(pickle.dumps((model.name, equations,
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
                "eigenvalues against it with compute='speeds' (sweep --compute speeds)")
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
