"""What a Newton-Euler crosscheck reports (check/newton_euler.py symbolically,
check/newton_euler_numeric.py for a deep tree): the agreement per coordinate and the reactions.
Apart from both, so that the numeric route returns them without importing the symbolic one."""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..derivation.display import latex_with_rates
from ..model.expressions import format_expression as fmt


@dataclass(frozen=True)
class CoordinateAgreement:
    """Newton-Euler vs Lagrange on one coordinate; ``difference`` = E_NE - E_Lagrange."""

    coordinate: str
    agree: bool
    difference: str | None
    newton_euler: sp.Expr | None  # None where it was formed numerically (a deep tree)


@dataclass(frozen=True)
class Reaction:
    """The resultant reaction on one body (the 'joint' is named after the body it acts on):
    force components (N) and, for a rigid body, the moment about its centre of mass (N m).
    For a body in space: the force and moment (about its joint, world axes x, y, z) at its
    joint, on it and the bodies it carries."""

    joint: str
    labels: tuple[str, ...]
    components: tuple[sp.Expr, ...]
    # N and N m at the model's initial state, the accelerations and multipliers from the
    # equations of motion there; None where a parameter has no value or M is singular there
    at_initial_state: tuple[float, ...] | None = None

    def _repr_latex_(self) -> str:
        rows = [rf"{label} &= {latex_with_rates(value)}" for label, value in zip(self.labels,
                                                                       self.components,
                                                                       strict=True)]
        return r"$\begin{aligned}" + r"\\ ".join(rows) + r"\end{aligned}$"


@dataclass(frozen=True)
class CrosscheckReport:
    """Whether Newton-Euler and Lagrange agree on every coordinate, with the reactions found."""

    model: str
    coordinates: tuple[CoordinateAgreement, ...]
    reactions: tuple[Reaction, ...]
    notes: tuple[str, ...]

    @property
    def agree(self) -> bool:
        return all(c.agree for c in self.coordinates)

    @property
    def passed(self) -> bool:
        """The crosscheck passed: the two derivations agree on every coordinate (``agree``)."""
        return self.agree

    def reaction(self, joint: str) -> Reaction:
        for r in self.reactions:
            if r.joint == joint:
                return r
        raise KeyError(joint)

    def __repr__(self) -> str:
        lines = [f"CrosscheckReport(agree={self.agree})"]
        lines += [f"  {c.coordinate}: {'agree' if c.agree else 'differ by ' + str(c.difference)}"
                  for c in self.coordinates]
        lines += [f"  reaction on {r.joint}: " + ", ".join(
            f"{label} = {fmt(v)}" for label, v in zip(r.labels, r.components, strict=True))
            for r in self.reactions]
        return "\n".join(lines)
