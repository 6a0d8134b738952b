"""What the user's own L conserves: cyclic momenta, the Jacobi integral, Noether quantities.

A coordinate q_i is cyclic when dL/dq_i = 0; p_i = dL/dq_i_dot is then conserved unless a
non-potential load does virtual work along it (Q_i != 0) or a constraint holds it. The energy
function h = q_dot . dL/dq_dot - L is conserved when L has no explicit t and the loads do no
work; it equals T + V only when T is quadratic in q_dot (not on a driven hoop). Noether's
theorem: a generator xi(q) = a + B q with delta L = xi . dL/dq + (B q_dot) . dL/dq_dot = 0
conserves J = xi . dL/dq_dot, unless the loads' virtual work Q . xi is nonzero.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np
import sympy as sp

from ..compile.lambdified import numpy_function
from ..derivation.equations import EquationsOfMotion
from ..derivation.readable import readable
from ..derivation.regularity import vanishes
from ..errors import ModelError
from ..kinds import InvariantKind
from ..model.expressions import format_expression, tree_size

# The affine search solves for n + n^2 unknowns from sampled values: kept to small models.
NOETHER_MAX_COORDINATES = 6
_SAMPLES_PER_UNKNOWN = 3
_SMALL_OPERATIONS = 400  # L expanded and its momenta tidied below this many operations
_SIMPLIFY_NODES = 600  # identities confirmed by simplify below this tree size
_SHOWN_NODES = 2000  # a quantity's readable form tried below this tree size
_SHOWN_RATIO = 0.8  # and kept where it has at most this share of the operations


class ConservedKind(StrEnum):
    """A cyclic coordinate's momentum, the Jacobi energy function, or a Noether quantity."""

    MOMENTUM = "momentum"
    JACOBI = "jacobi"
    NOETHER = "noether"


@dataclass(frozen=True)
class ConservedQuantity:
    """One conserved quantity: its expression (sympy, in the model's symbols; kg m^2/s, kg m/s
    or J) and the generator xi it comes from (a coordinate's unit vector for a momentum)."""

    name: str
    kind: ConservedKind
    expression: sp.Expr
    generator: tuple[sp.Expr, ...] = ()
    equals_energy: bool | None = None  # jacobi only: whether h = T + V
    coordinates: tuple[sp.Symbol, ...] = field(default=(), repr=False)
    velocities: tuple[sp.Symbol, ...] = field(default=(), repr=False)
    time: sp.Symbol = field(default=sp.Symbol("t"), repr=False)
    values: tuple[tuple[sp.Symbol, float], ...] = field(default=(), repr=False)

    @property
    def text(self) -> str:
        """The expression in the model-file grammar."""
        return format_expression(self.expression)

    def value(self, q: Sequence[float], q_dot: Sequence[float], t: float = 0.0) -> float:
        """The quantity at a state (SI, the system's coordinate order), at the model's values."""
        q, q_dot = np.asarray(q, dtype=float), np.asarray(q_dot, dtype=float)
        n = len(self.coordinates)
        if q.shape != (n,) or q_dot.shape != (n,):
            raise ModelError(f"q and q_dot take {n} values each, in the order "
                             f"{', '.join(map(str, self.coordinates))}", field="value")
        expression = self.expression.xreplace(dict(self.values))
        missing = expression.free_symbols - set(self.coordinates) - set(self.velocities) \
            - {self.time}
        if missing:
            raise ModelError("parameters without a value: "
                             f"{', '.join(sorted(map(str, missing)))}", field="parameters")
        function = numpy_function([*self.coordinates, *self.velocities, self.time], expression)
        return float(function(*q, *q_dot, float(t)))

    def __repr__(self) -> str:
        extra = "" if self.equals_energy is None else \
            f", equals T + V: {'yes' if self.equals_energy else 'no'}"
        return f"ConservedQuantity({self.kind} {self.name} = {self.text}{extra})"


@dataclass(frozen=True)
class NotConserved:
    """A candidate that is not conserved, and why (one sentence)."""

    name: str
    kind: ConservedKind
    reason: str
    expression: sp.Expr | None = None  # a Noether candidate's xi . dL/dq_dot


@dataclass(frozen=True)
class ConservedQuantities(Sequence):
    """The quantities conserved along every motion, and the candidates the loads break."""

    quantities: tuple[ConservedQuantity, ...]
    broken: tuple[NotConserved, ...] = ()
    not_cyclic: tuple[tuple[str, str], ...] = ()  # coordinate -> the terms of L it is in
    note: str | None = None  # why the Noether search was not run

    def __getitem__(self, index):
        return self.quantities[index]

    def __len__(self) -> int:
        return len(self.quantities)

    def named(self, name: str) -> ConservedQuantity:
        for quantity in self.quantities:
            if quantity.name == name:
                return quantity
        raise KeyError(name)

    def of_kind(self, kind: str) -> list[ConservedQuantity]:
        return [quantity for quantity in self.quantities if quantity.kind == kind]

    def __repr__(self) -> str:
        lines = [f"ConservedQuantities ({len(self)}):"]
        lines += [f"  {q.kind}: {q.name} = {q.text}" + (
            "" if q.equals_energy is None else
            f"  (h {'=' if q.equals_energy else '!='} T + V)") for q in self.quantities]
        lines += [f"  not conserved: {b.name}: {b.reason}" for b in self.broken]
        return "\n".join(lines)


def conserved_quantities(eom: EquationsOfMotion) -> ConservedQuantities:
    """Every conserved quantity of the derived equations that the three searches find."""
    model = eom.model
    if model.kinematic_tree is not None:
        raise ModelError("conserved quantities are searched in a model file's L (energies, "
                         "particles, bodies); a robot's kinematic tree (URDF, MJCF) is not "
                         "searched", field="conserved")
    L = eom.lagrangian
    small = sp.count_ops(L) < _SMALL_OPERATIONS if tree_size(L, 4000) < 4000 else False
    L = sp.expand(L) if small else L  # a large L (the bicycle's) is only differentiated
    q, q_dot = model.q, model.q_dot
    names = [c.name for c in model.coordinates]
    values = tuple((p.symbol, float(p.value)) for p in model.parameters if p.value is not None)
    common = {"coordinates": q, "velocities": q_dot, "time": model.time, "values": values}
    quantities: list[ConservedQuantity] = []
    broken: list[NotConserved] = []
    not_cyclic: list[tuple[str, str]] = []
    cyclic: list[int] = []
    for i, (name, coordinate) in enumerate(zip(names, q, strict=True)):
        momentum_name = f"p_{name}"
        if coordinate in L.free_symbols and not _is_zero(L.diff(coordinate), model):
            terms = [t for t in sp.Add.make_args(L) if coordinate in t.free_symbols]
            not_cyclic.append((name, _sum_text(terms[:4]) + (" + ..." if len(terms) > 4 else "")))
            continue
        cyclic.append(i)
        generator = tuple(sp.S.One if j == i else sp.S.Zero for j in range(len(q)))
        reason = _work_along(eom, generator)
        momentum = L.diff(q_dot[i])
        momentum = sp.factor_terms(sp.trigsimp(momentum) if small else momentum)
        if reason is not None:
            broken.append(NotConserved(momentum_name, ConservedKind.MOMENTUM, reason))
            continue
        quantities.append(ConservedQuantity(momentum_name, ConservedKind.MOMENTUM,
                                            _shown(momentum, model), generator, **common))
    jacobi = _jacobi(eom, common)
    if isinstance(jacobi, NotConserved):
        broken.append(jacobi)
    elif jacobi is not None:
        quantities.append(jacobi)
    note = None
    if len(q) > NOETHER_MAX_COORDINATES:
        note = (f"no search for symmetries that no coordinate shows: over "
                f"{NOETHER_MAX_COORDINATES} coordinates")
    else:
        for k, generator in enumerate(_affine_generators(L, eom, cyclic), start=1):
            name = f"J{k}"
            reason = _work_along(eom, generator)
            expression = sp.factor_terms(sp.expand(sum(
                (x * L.diff(v) for x, v in zip(generator, q_dot, strict=True)), sp.S.Zero)))
            if reason is not None:
                broken.append(NotConserved(name, ConservedKind.NOETHER, reason, expression))
                continue
            quantities.append(ConservedQuantity(name, ConservedKind.NOETHER,
                                                _shown(expression, model), generator, **common))
    return ConservedQuantities(tuple(quantities), tuple(broken), tuple(not_cyclic), note)


def _shown(expression: sp.Expr, model) -> sp.Expr:
    """The derivation's readable form of a small quantity (equal to it) where it is clearly
    shorter: the heavy top's h as Goldstein's, with no psi (its T is written in body rates)."""
    if tree_size(expression, _SHOWN_NODES) >= _SHOWN_NODES:
        return expression
    shown = readable(expression, frozenset(model.q_dot), {c.symbol: tuple(c.range)
                                                           for c in model.coordinates if c.range})
    return shown if sp.count_ops(shown) < _SHOWN_RATIO * sp.count_ops(expression) else expression


def _sum_text(terms: Sequence[sp.Expr]) -> str:
    """Terms in the order given, joined by their signs (a - b, not a + -b)."""
    text = ""
    for term in terms:
        written = format_expression(term)
        if not text:
            text = written
        elif written.startswith("-"):
            text += f" - {written[1:]}"
        else:
            text += f" + {written}"
    return text


def _is_zero(expr: sp.Expr, model) -> bool:
    """expr == 0 identically: at random points first, then by simplification where small (a
    large expression rests on the random points, the project's identity test)."""
    if expr == 0:
        return True
    if not vanishes(expr, model):
        return False
    if tree_size(expr, _SIMPLIFY_NODES) >= _SIMPLIFY_NODES:
        return True
    return sp.simplify(expr) == 0


def _work_along(eom: EquationsOfMotion, generator: Sequence[sp.Expr]) -> str | None:
    """Why the loads or constraints break a quantity of generator xi (None: they do not):
    the loads' virtual work Q . xi, or a constraint's Phi_q xi, must vanish."""
    model = eom.model
    work = sp.Add(*(Q * x for Q, x in zip(eom.generalized_forces, generator, strict=True)))
    if not _is_zero(work, model) and not _is_zero(work.xreplace(_values(model)), model):
        loads = sorted({c.load for c in eom.load_contributions
                        if generator[[c_.name for c_ in model.coordinates]
                                     .index(c.coordinate)] != 0})
        return (f"the loads ({', '.join(loads)}) do virtual work along it: Q . xi = "
                f"{format_expression(sp.factor_terms(work))}")
    for k, constraint in enumerate(model.constraints):
        row = eom.constraint_jacobian.row(k)
        if not _is_zero(sp.Add(*(a * x for a, x in zip(row, generator, strict=True))), model):
            return f"the constraint {constraint.name} does work along it"
    return None


def _values(model) -> dict:
    """The parameters that have a value: a load switched off (F = 0) does no work."""
    return {p.symbol: sp.Float(p.value) if p.value != 0 else sp.S.Zero
            for p in model.parameters if p.value is not None}


def _jacobi(eom: EquationsOfMotion, common: dict) -> ConservedQuantity | NotConserved | None:
    """h = q_dot . dL/dq_dot - L when conserved (with whether it is T + V), else why not; a
    load that the model's values switch off (F = 0) does no work."""
    kind = eom.invariant_kind
    if kind == InvariantKind.WORK_BALANCE and _is_zero(
            eom.power.xreplace(_values(eom.model)), eom.model):
        T, V, h = eom.kinetic_energy, eom.potential_energy, eom.jacobi_integral
        equals = _is_zero(h - T - V, eom.model)
        return ConservedQuantity("h", ConservedKind.JACOBI,
                                 _shown(T + V if equals else sp.expand(h), eom.model), (),
                                 equals_energy=equals, **common)
    if kind == InvariantKind.WORK_BALANCE:
        model = eom.model
        causes = []
        if eom.explicit_time_power != 0 and not vanishes(eom.explicit_time_power, model):
            causes.append("L depends on t explicitly")
        if any(Q != 0 for Q in eom.generalized_forces):
            loads = sorted({c.load for c in eom.load_contributions})
            causes.append(f"the loads ({', '.join(loads)}) do work")
        if model.constraints and not causes:
            causes.append("a moving constraint does work")
        return NotConserved("h", ConservedKind.JACOBI,
                            "; ".join(causes) or "the loads do work")
    equals = kind == InvariantKind.ENERGY
    expression = eom.kinetic_energy + eom.potential_energy if equals \
        else sp.expand(eom.jacobi_integral)
    return ConservedQuantity("h", ConservedKind.JACOBI, _shown(expression, eom.model), (),
                             equals_energy=equals, **common)


def _affine_generators(L: sp.Expr, eom: EquationsOfMotion, cyclic: Sequence[int]
                       ) -> list[tuple[sp.Expr, ...]]:
    """Generators xi = a + B q with delta L = 0 identically, beyond the cyclic coordinates'
    unit vectors: the null space of delta L's coefficients sampled at random states, made
    exact (rationals) and each verified symbolically."""
    model = eom.model
    q, q_dot, t = model.q, model.q_dot, model.time
    n = len(q)
    values = {p.symbol: (float(p.value) if p.value is not None else 1.0 + 0.37 * k)
              for k, p in enumerate(model.parameters)}
    L_q = [L.diff(x).xreplace(values) for x in q]
    L_v = [L.diff(v).xreplace(values) for v in q_dot]
    arguments = [*q, *q_dot, t]
    function = numpy_function(arguments, [*L_q, *L_v])
    unknowns = n + n * n
    rng = np.random.default_rng(7)
    rows = []
    for _ in range(_SAMPLES_PER_UNKNOWN * unknowns + 8):
        point = rng.uniform(-1.3, 1.3, 2 * n + 1)
        point[:n] += 0.4  # away from q = 0, where an angle's symmetry can hide
        try:
            with np.errstate(all="raise"):
                evaluated = np.asarray(function(*point), dtype=float)
        except (FloatingPointError, ZeroDivisionError, ValueError):
            continue
        if not np.all(np.isfinite(evaluated)):
            continue
        dq, dv = evaluated[:n], evaluated[n:]
        qs, vs = point[:n], point[n:2 * n]
        # delta L = sum_i (a_i + sum_j B_ij q_j) L_qi + sum_ij B_ij v_j L_vi
        row = list(dq) + [qs[j] * dq[i] + vs[j] * dv[i] for i in range(n) for j in range(n)]
        rows.append(row)
    if len(rows) < unknowns + 4:
        return []
    A = np.asarray(rows)
    scale = np.maximum(np.abs(A).max(axis=0), 1e-300)
    A = A / scale
    _, s, vh = np.linalg.svd(A)
    tolerance = max(A.shape) * s[0] * 1e-9 if s.size else 0.0
    rank = int(np.sum(s > tolerance))
    null = vh[rank:] / scale  # back to the unscaled unknowns
    if null.shape[0] == 0:
        return []
    basis, _ = _exact_rref(null)
    known = [[1 if j == i else 0 for j in range(unknowns)] for i in cyclic]
    found: list[tuple[sp.Expr, ...]] = []
    span = sp.Matrix(known) if known else sp.zeros(0, unknowns)
    for row in basis:
        candidate = span.col_join(sp.Matrix([row])) if span.rows else sp.Matrix([row])
        if candidate.rank() <= span.rows:
            continue
        a = row[:n]
        B = [row[n + i * n:n + (i + 1) * n] for i in range(n)]
        # the sense: a rotation counter-clockwise (B below the diagonal positive, x y_dot -
        # y x_dot), a translation along +a
        lead = [B[i][j] for i in range(n) for j in range(i) if B[i][j] != 0] or \
            [x for x in a if x != 0]
        if lead and lead[0] < 0:
            a, B = [-x for x in a], [[-x for x in line] for line in B]
        generator = tuple(sp.nsimplify(a[i]) + sum((B[i][j] * q[j] for j in range(n)),
                                                   sp.S.Zero) for i in range(n))
        B_dot = [sum((B[i][j] * q_dot[j] for j in range(n)), sp.S.Zero) for i in range(n)]
        variation = sp.Add(*(x * L.diff(c) for x, c in zip(generator, q, strict=True)),
                           *(x * L.diff(v) for x, v in zip(B_dot, q_dot, strict=True)))
        if not _is_zero(variation, model):
            continue  # a symmetry of the model's values only, or a rounding
        span = candidate
        found.append(generator)
    return found


def _exact_rref(null: np.ndarray) -> tuple[list[list[sp.Rational]], list[int]]:
    """The null space's reduced row echelon form, its entries as nearby simple rationals."""
    M = null.copy()
    rows, cols = M.shape
    pivots: list[int] = []
    r = 0
    for c in range(cols):
        if r >= rows:
            break
        k = r + int(np.argmax(np.abs(M[r:, c])))
        if abs(M[k, c]) < 1e-9:
            continue
        M[[r, k]] = M[[k, r]]
        M[r] = M[r] / M[r, c]
        for i in range(rows):
            if i != r:
                M[i] -= M[i, c] * M[r]
        pivots.append(c)
        r += 1
    exact = [[sp.nsimplify(round(float(x), 9), rational=True) if abs(x) > 1e-9 else sp.S.Zero
              for x in M[i]] for i in range(r)]
    return exact, pivots


__all__ = ["ConservedKind", "ConservedQuantities", "ConservedQuantity", "NotConserved",
           "conserved_quantities"]
