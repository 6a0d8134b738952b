"""Stop conditions: 'EXPR < EXPR' in the model grammar, read without evaluating anything.

A run stops when its condition first turns true (a crossing of g = 0, g > 0 where it holds).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

import sympy as sp

from ..errors import InputError
from ..model.expressions import parse_expression
from ..model.model import Model

_COMPARISON = re.compile(r"<=|>=|==|!=|<|>")


@dataclass(frozen=True)
class StopCondition:
    """``lhs OP rhs`` in the model grammar; the run stops when it turns true (crossing)."""

    text: str
    lhs: sp.Expr
    operator: str
    rhs: sp.Expr

    @property
    def function(self) -> sp.Expr:
        """g with g > 0 exactly where the condition holds."""
        return self.lhs - self.rhs if self.operator in (">", ">=") else self.rhs - self.lhs


def parse_stop_condition(text: str, model: Model, *, field: str = "stop_when",
                         names: Mapping[str, sp.Expr] | None = None) -> StopCondition:
    """Parse 'EXPR < EXPR' (or >, <=, >=) with the model grammar; nothing is evaluated.
    ``names`` adds names the model does not hold (a floating base's base_x .. base_wz)."""
    if not isinstance(text, str) or not text.strip():
        raise InputError("the stop condition is empty; write e.g. 'theta < 0'", field=field)
    operators = _COMPARISON.findall(text)
    if len(operators) != 1:
        what = "no comparison" if not operators else f"{len(operators)} comparisons"
        raise InputError(
            f"a stop condition has exactly one comparison (<, >, <=, >=), found {what} "
            f"in {text!r}", field=field)
    operator = operators[0]
    if operator in ("==", "!="):
        raise InputError(f"'{operator}' is not allowed; use <, >, <= or >= (a crossing) "
                         f"in {text!r}", field=field)
    left, right = _COMPARISON.split(text)
    names = {**_condition_names(model), **(names or {})}
    sides = []
    for side, part in (("left", left), ("right", right)):
        if not part.strip():
            raise InputError(f"the {side} side of {text!r} is empty", field=field)
        sides.append(parse_expression(part, names, field=field))
    return StopCondition(text.strip(), sides[0], operator, sides[1])


def _condition_names(model: Model) -> dict[str, sp.Expr]:
    names: dict[str, sp.Expr] = {"t": model.time}
    names.update({p.name: p.symbol for p in model.parameters})
    names.update(dict(model.definitions))
    for c in model.coordinates:
        names[c.name] = c.symbol
        names[c.velocity.name] = c.velocity
    return names
