"""The working of Lagrange's method, step by step, for a reader to follow (``derive --steps``).

Each step is derived from L = T - V by differentiation (derivation_steps, in
derivation/equations.py), not restated from M and f: per coordinate q_i, the momentum
p_i = dL/dq_dot_i (kg m^2/s for an angle, kg m/s for a length), its rate
d/dt(p_i) = sum_j (dp_i/dq_j q_dot_j + dp_i/dq_dot_j q_ddot_j) + dp_i/dt, the force term
dL/dq_i, the generalized force Q_i of the non-potential loads and, with constraints, the
multiplier terms (Phi_q^T lambda)_i; the equation is d/dt(p_i) - dL/dq_i - Q_i + (Phi_q^T
lambda)_i = 0. Per load, the virtual displacement of what it acts on (delta r = sum_i dr/dq_i
delta q_i for a point, delta(angle) for a torque, delta(length) for a damper) and its virtual
work delta W = sum_i Q_i delta q_i. Here: the steps' types and each load kind's working.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import singledispatch

import sympy as sp

from ..kinds import LoadStepKind
from ..model.model import Damper, Model, PointForce, Torque
from ..model.notation import latex_printer
from ..model.rotations import Moment
from .display import model_scalar


def _dotted(step) -> None:
    """Every expression of a step shown with its rates dotted in Jupyter (equal to itself)."""
    for name, value in vars(step).items():
        if isinstance(value, sp.Basic):
            object.__setattr__(step, name, model_scalar(value))
        elif isinstance(value, tuple) and all(isinstance(v, sp.Basic) for v in value):
            object.__setattr__(step, name, tuple(model_scalar(v) for v in value))


@dataclass(frozen=True)
class CoordinateStep:
    """Lagrange's equation for one coordinate, term by term (units of a generalized force)."""

    coordinate: str
    momentum: sp.Expr            # dL/dq_dot_i
    momentum_rate: sp.Expr       # d/dt(dL/dq_dot_i)
    force_gradient: sp.Expr      # dL/dq_i
    generalized_force: sp.Expr   # Q_i (N or N m)
    multiplier_terms: sp.Expr    # (Phi_q^T lambda)_i
    equation: sp.Expr            # momentum_rate - force_gradient - Q_i + multiplier terms (= 0)

    def __post_init__(self):
        _dotted(self)


@dataclass(frozen=True)
class LoadStep:
    """One load's virtual work: what it acts on moves by ``displacement`` (in the delta q),
    and delta W = ``virtual_work`` (J) = sum_i ``shares`` Q_i delta q_i."""

    load: str
    kind: LoadStepKind                   # force, torque, moment, damper, dissipation, given
    acts_at: tuple[sp.Expr, ...]         # the point r, the angle, the damper's rate; () if none
    displacement: tuple[sp.Expr, ...]    # delta r, delta(angle) or delta(length); () if none
    work_form: sp.Expr | None            # delta W as the load writes it (F . delta r, tau d angle)
    virtual_work: sp.Expr                # sum_i Q_i delta q_i
    shares: tuple[tuple[str, sp.Expr], ...]

    def __post_init__(self):
        _dotted(self)


@dataclass(frozen=True)
class ConstraintStep:
    """One constraint: Phi (or A q_dot + b), its row of Phi_q and its multiplier."""

    constraint: str
    kind: str
    expression: sp.Expr
    jacobian: tuple[sp.Expr, ...]
    multiplier: sp.Symbol

    def __post_init__(self):
        _dotted(self)


@dataclass(frozen=True)
class DerivationSteps:
    """The steps of ``derive --steps``: L, then each coordinate, load and constraint."""

    model: Model
    kinetic_energy: sp.Expr
    potential_energy: sp.Expr
    lagrangian: sp.Expr
    variations: tuple[sp.Symbol, ...]    # delta q_i, one per coordinate
    coordinates: tuple[CoordinateStep, ...]
    loads: tuple[LoadStep, ...]
    constraints: tuple[ConstraintStep, ...]

    def __post_init__(self):
        _dotted(self)

    def coordinate(self, name: str) -> CoordinateStep:
        for step in self.coordinates:
            if step.coordinate == name:
                return step
        raise KeyError(name)

    def __repr__(self) -> str:
        lines = [f"DerivationSteps({self.model.name!r})", f"  L = {self.lagrangian}"]
        for s in self.coordinates:
            lines += [f"  [{s.coordinate}] dL/dq_dot = {s.momentum}",
                      f"  [{s.coordinate}] d/dt(dL/dq_dot) = {s.momentum_rate}",
                      f"  [{s.coordinate}] dL/dq = {s.force_gradient}",
                      f"  [{s.coordinate}] Q = {s.generalized_force}",
                      f"  [{s.coordinate}] {s.equation} = 0"]
        lines += [f"  {load.load}: delta W = {load.virtual_work}" for load in self.loads]
        return "\n".join(lines)

    def _repr_latex_(self) -> str:
        tex = latex_printer(self.model)
        rows = [rf"\mathcal{{L}} &= {tex(self.lagrangian)}"]
        for c, s in zip(self.model.coordinates, self.coordinates, strict=True):
            q, v = tex(c.symbol), tex(c.velocity)
            rows += [rf"\frac{{\partial \mathcal{{L}}}}{{\partial {v}}} &= {tex(s.momentum)}",
                     rf"\frac{{d}}{{dt}}\frac{{\partial \mathcal{{L}}}}{{\partial {v}}} &= "
                     rf"{tex(s.momentum_rate)}",
                     rf"\frac{{\partial \mathcal{{L}}}}{{\partial {q}}} &= "
                     rf"{tex(s.force_gradient)}",
                     rf"\mathcal{{Q}}_{{{q}}} &= {tex(s.generalized_force)}",
                     rf"0 &= {tex(s.equation)}"]
        rows += [rf"\delta W_{{\mathrm{{{_latex_text(load.load)}}}}} &= {tex(load.virtual_work)}"
                 for load in self.loads]
        return r"$\begin{aligned}" + r"\\ ".join(rows) + r"\end{aligned}$"


def _latex_text(name: str) -> str:
    """A name as LaTeX text: its special characters escaped, never read as commands."""
    special = {"\\": r"\textbackslash{}", "^": r"\^{}", "~": r"\~{}"}
    return "".join(special.get(ch, "\\" + ch if ch in "_&%$#{}" else ch) for ch in name)


def variation_symbols(model: Model) -> tuple[sp.Symbol, ...]:
    """delta_q for each coordinate q (delta_q_ when a model name is already delta_q)."""
    taken = {p.name for p in model.parameters} | {c.name for c in model.coordinates}
    out = []
    for c in model.coordinates:
        name = f"delta_{c.name}"
        while name in taken:
            name += "_"
        out.append(sp.Symbol(name))
    return tuple(out)


__all__ = ["ConstraintStep", "CoordinateStep", "DerivationSteps", "LoadStep", "load_working",
           "variation_symbols"]


# one entry per load kind and Damper (tests/model/test_component_tables.py walks every kind)
@singledispatch
def load_working(component, q, q_dot, moved) -> tuple[LoadStepKind, tuple, tuple, sp.Expr]:
    """A load's kind, what it acts on, the virtual displacement of that (``moved(expr, x)`` is
    sum_i d expr/d x_i delta q_i) and delta W as the load writes it (J)."""
    raise TypeError(f"no virtual work for a component of kind {type(component).__name__}")


@load_working.register
def _(load: PointForce, q, q_dot, moved):
    displacement = tuple(moved(r, q) for r in load.point)  # delta r
    form = sp.Add(*(f * dr for f, dr in zip(load.force, displacement, strict=True)))
    return LoadStepKind.FORCE, tuple(load.point), displacement, form


@load_working.register
def _(load: Torque, q, q_dot, moved):
    displacement = (moved(load.angle, q),)  # delta(angle)
    return LoadStepKind.TORQUE, (load.angle,), displacement, load.torque * displacement[0]


@load_working.register
def _(load: Moment, q, q_dot, moved):
    # delta phi_k = sum_i d omega_k/d q_dot_i delta q_i, in the axes the moment is given in
    displacement = tuple(moved(w, q_dot) for w in load.angular_velocity)
    form = sp.Add(*(m * dp for m, dp in zip(load.moment, displacement, strict=True)))
    return LoadStepKind.MOMENT, (), displacement, form


@load_working.register
def _(damper: Damper, q, q_dot, moved):
    # the rate l_dot is linear in q_dot: delta l = sum_i d l_dot/d q_dot_i delta q_i
    displacement = (moved(damper.rate, q_dot),)
    form = -damper.coefficient * damper.rate * displacement[0]
    return LoadStepKind.DAMPER, (damper.rate,), displacement, form
