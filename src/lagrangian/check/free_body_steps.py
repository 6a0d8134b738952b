"""The working of `crosscheck --steps`: each body's free-body equations, then their projection.

Newton-Euler (newton_euler.py) puts every applied force on the free body it acts on; here the
same forces are put on one element at a time (the weight, each load, spring and damper), so each
body's equations list what acts on it: m a_G = sum F + R (N) and, for a planar body,
I alpha = sum M_G + M_R (N m about G). Projected onto the virtual displacements dr_G/dq_i and
dangle/dq_i the reactions drop out (ideal: no virtual work), leaving

    E_i = sum_b (m a_G . dr_G/dq_i + I alpha dangle/dq_i) - sum_forces F . dr/dq_i,

which is Lagrange's (M q_ddot - f)_i; each share is listed so the mapping can be followed.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..errors import DerivationError
from ..kinds import FreeBodyKind
from ..model.model import Model
from ..model.notation import latex_symbol_names
from . import equivalence as eq
from .free_bodies import (
    _AppliedForces,
    _Clock,
    _free_bodies,
    _FreeBody,
    _projected_equations,
    _require_free_bodies,
)


@dataclass(frozen=True)
class AppliedForce:
    """One element's force on a body (N, world axes) and its moment about the body's G (N m)."""

    source: str                  # 'weight', or the load, spring or damper's name
    force: tuple[sp.Expr, ...]
    moment: tuple[sp.Expr, ...]  # (M_z,) for a planar body, (M_x, M_y, M_z) in space, () none


@dataclass(frozen=True)
class FreeBodyStep:
    """One free body: m a_G = sum F + R and, for a planar body, I alpha = sum M_G + M_R."""

    body: str
    kind: FreeBodyKind                    # particle, body, body in space
    mass: sp.Expr
    acceleration: tuple[sp.Expr, ...]     # a_G (m/s^2), by d^2 r_G/dt^2
    forces: tuple[AppliedForce, ...]
    reaction: tuple[sp.Expr, ...]         # R = m a_G - sum F (N)
    inertia: sp.Expr | None = None        # planar body: I about G (kg m^2)
    angular_acceleration: sp.Expr | None = None  # alpha = d^2 angle/dt^2
    reaction_moment: sp.Expr | None = None       # M_R = I alpha - sum M_G (N m)


@dataclass(frozen=True)
class ProjectionStep:
    """Coordinate q_i: each body's inertial share m a_G . dr_G/dq_i + I alpha dangle/dq_i,
    each element's virtual work F . dr/dq_i, their difference E_i and Lagrange's."""

    coordinate: str
    inertial: tuple[tuple[str, sp.Expr], ...]
    work: tuple[tuple[str, sp.Expr], ...]
    newton_euler: sp.Expr
    lagrange: sp.Expr
    agree: bool


@dataclass(frozen=True)
class CrosscheckSteps:
    """The steps of `crosscheck --steps` (bodies, then coordinates)."""

    model: str
    bodies: tuple[FreeBodyStep, ...]
    projections: tuple[ProjectionStep, ...]
    constrained: bool = False  # then Phi_q^T lambda stands on both sides, left out of E_i
    # symbol -> LaTeX (q_dot as a dot over q) for _repr_latex_
    latex_names: dict = field(default_factory=dict, compare=False, repr=False)

    @property
    def agree(self) -> bool:
        return all(p.agree for p in self.projections)

    def _repr_latex_(self) -> str:
        def tex(expr) -> str:
            return sp.latex(expr, symbol_names=self.latex_names)

        rows = []
        for b in self.bodies:
            axes = "xyz" if any(a != 0 for a in b.acceleration[2:]) else "xy"
            for k, axis in enumerate(axes):
                total = sp.Add(*(f.force[k] for f in b.forces))
                rows.append(rf"{tex(b.mass * b.acceleration[k])} &= {tex(total)} + "
                            rf"R_{{{axis}}} && \text{{({_latex_text(b.body)}, {axis})}}")
        for p in self.projections:
            rows.append(rf"0 &= {tex(p.newton_euler)} && \text{{({_latex_text(p.coordinate)})}}")
        return r"$\begin{aligned}" + r"\\ ".join(rows) + r"\end{aligned}$"

    def __repr__(self) -> str:
        lines = [f"CrosscheckSteps({self.model!r}, agree={self.agree})"]
        lines += [f"  {b.body}: m a_G = " + " + ".join(f.source for f in b.forces) + " + R"
                  for b in self.bodies]
        return "\n".join(lines)


def _latex_text(name: str) -> str:
    """A name as LaTeX text: its special characters escaped, never read as commands."""
    special = {"\\": r"\textbackslash{}", "^": r"\^{}", "~": r"\~{}"}
    return "".join(special.get(ch, "\\" + ch if ch in "_&%$#{}" else ch) for ch in name)


class _View:
    """The model with some component lists replaced (one element at a time)."""

    def __init__(self, model: Model, **only):
        self._model, self._only = model, only

    def __getattr__(self, name: str):
        if name in self._only:
            return self._only[name]
        return getattr(self._model, name)


class _Recorder(_AppliedForces):
    """The applied forces, element by element: what each adds to each body and to the work."""

    def __init__(self, model: Model, bodies: list[_FreeBody], points: eq.Points):
        super().__init__(model, bodies, points)
        self.full = model
        self.placed: dict[str, list[AppliedForce]] = {fb.name: [] for fb in bodies}
        self.shares: list[tuple[str, list[sp.Expr]]] = []

    def _record(self, source: str, apply) -> None:
        before = {fb.name: (list(fb.force), fb.moment, list(fb.moment3 or ())) for fb in self.bodies}
        counts = [len(w) for w in self.work]
        apply()
        for fb in self.bodies:
            force0, moment0, moment30 = before[fb.name]
            force = tuple(a - b for a, b in zip(fb.force, force0, strict=True))
            if fb.rotation is not None:
                moment = tuple(a - b for a, b in zip(fb.moment3, moment30, strict=True))
            elif fb.angle is not None:
                moment = (fb.moment - moment0,)
            else:
                moment = ()
            if any(c != 0 for c in (*force, *moment)):
                self.placed[fb.name].append(AppliedForce(source, force, moment))
        work = [sp.Add(*w[n:]) for w, n in zip(self.work, counts, strict=True)]
        if any(w != 0 for w in work):
            self.shares.append((source, work))

    def run(self, clock: _Clock) -> None:
        model = self.full
        self._record("weight", self.add_gravity)
        for load in model.loads:
            self._one(load.name, self.add_loads, loads=(load,))
        for spring in model.springs:
            self._one(spring.name, self.add_springs, springs=(spring,))
        for damper in model.dampers:
            self._one(damper.name, lambda: self.add_dampers(clock), dampers=(damper,))
        self._record("given in the model", self.add_given_generalized_forces)
        self.model = model

    def _one(self, source: str, method, **only) -> None:
        self.model = _View(self.full, **only)
        try:
            self._record(source, method)
        finally:
            self.model = self.full


def crosscheck_steps(eom: EquationsOfMotion) -> CrosscheckSteps:
    """Newton-Euler's free-body equations of ``eom.model`` and how they map to Lagrange's."""
    model = eom.model
    _require_free_bodies(model)
    from .newton_euler_numeric import NUMERIC_ABOVE, wants_numeric
    if wants_numeric(model):  # its symbolic working would take hours and print megabytes
        raise DerivationError(
            f"the free-body working is written for bodies in space at most {NUMERIC_ABOVE} "
            "elementary rotations from the ground; this model's go deeper, so crosscheck forms "
            "Newton-Euler with numbers instead, without a working to print")
    points = eq.random_points(model)
    clock = _Clock(model)
    bodies = _free_bodies(model, clock)
    recorder = _Recorder(model, bodies, points)
    recorder.run(clock)
    steps = []
    for fb in bodies:
        reaction = tuple(fb.mass * a - f for a, f in zip(fb.acceleration, fb.force, strict=True))
        kind = FreeBodyKind.BODY_IN_SPACE if fb.rotation is not None else \
            FreeBodyKind.BODY if fb.angle is not None else FreeBodyKind.PARTICLE
        planar = fb.angle is not None and fb.rotation is None
        steps.append(FreeBodyStep(
            fb.name, kind, fb.mass, tuple(fb.acceleration), tuple(recorder.placed[fb.name]),
            reaction,
            inertia=fb.inertia if planar else None,
            angular_acceleration=fb.angular_acceleration if planar else None,
            reaction_moment=fb.inertia * fb.angular_acceleration - fb.moment if planar else None))
    newton_euler = _projected_equations(model, bodies, recorder.work)
    lagrange = list(eom.mass_matrix * eom.acceleration_symbols - eom.forcing)
    # each body's inertial share m a_G . dr_G/dq_i + I alpha dangle/dq_i, all coordinates at once
    shares = {fb.name: _projected_equations(model, [fb], [[] for _ in model.q]) for fb in bodies}
    projections = []
    for i, c in enumerate(model.coordinates):
        inertial = [(fb.name, shares[fb.name][i]) for fb in bodies if shares[fb.name][i] != 0]
        work = tuple((source, values[i]) for source, values in recorder.shares if values[i] != 0)
        projections.append(ProjectionStep(c.name, tuple(inertial), work, newton_euler[i],
                                          lagrange[i],
                                          eq.identical(newton_euler[i], lagrange[i], points)))
    return CrosscheckSteps(model.name, tuple(steps), tuple(projections),
                           bool(model.constraints), latex_symbol_names(model))


__all__ = ["AppliedForce", "CrosscheckSteps", "FreeBodyStep", "ProjectionStep",
           "crosscheck_steps"]
