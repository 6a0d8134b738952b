"""The equations of motion in opty's form: implicit first-order equations in functions of time,
eom(x, x', r, p) = 0 with x = [q(t); u(t)] (u = q'), r(t) the specified inputs and p the
parameters, ready for ``opty.Problem(obj, obj_grad, eom, states, num_nodes, interval,
known_parameter_map=parameters)``. sympy only: opty itself is not needed to build them.

    q_i' - u_i = 0,   M(q) u' - f(q, u, p) - B r = 0
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..errors import ModelError
from ..model.inputs import input_parameter
from ..model.values import resolve_parameters


@dataclass(frozen=True)
class OptyEquations:
    """``eom`` (2n x 1 sympy Matrix, = 0), ``states`` (q_i(t) then u_i(t), u_i = q_i'),
    ``specified`` (r_k(t), one per input, SI), ``parameters`` {symbol: SI value} for opty's
    known_parameter_map, ``time`` the symbol t."""

    eom: sp.Matrix
    states: tuple
    specified: tuple
    parameters: dict
    time: sp.Symbol

    def __repr__(self) -> str:
        return (f"OptyEquations(states={[str(s) for s in self.states]}, "
                f"specified={[str(s) for s in self.specified]})")


def opty_equations(eom: EquationsOfMotion, inputs: Sequence[str] = (),
                   parameters: Mapping[str, float] | None = None) -> OptyEquations:
    """opty's eom, states and specified of an unconstrained model; ``inputs`` as in linearize
    (a load's r(t) is added to its parameter's value, a coordinate's is a generalized force)."""
    model = eom.model
    if model.constraints:
        raise ModelError("opty's equations are written for models without constraints (yet)",
                         field="to_opty")
    t = model.time
    n = len(model.q)
    q = [sp.Function(c.name)(t) for c in model.coordinates]
    u = [sp.Function(c.velocity.name)(t) for c in model.coordinates]
    inputs = tuple(inputs)
    if len(set(inputs)) != len(inputs):
        raise ModelError(f"an input is named twice: {list(inputs)}", field="inputs")
    specified = tuple(sp.Function(f"r_{name}")(t) for name in inputs)
    swap = {**dict(zip(model.q, q, strict=True)), **dict(zip(model.q_dot, u, strict=True))}
    names = [c.name for c in model.coordinates]
    generalized = [sp.S.Zero] * n
    for name, r in zip(inputs, specified, strict=True):
        symbol = input_parameter(model, name)
        if symbol is None:
            generalized[names.index(name)] += r
        else:
            if any(symbol in sp.sympify(e).free_symbols  # safe: sympy objects
                   for e in (eom.mass_matrix,)):
                raise ModelError("an input enters the mass matrix: inputs are loads",
                                 field="inputs")
            swap[symbol] = symbol + r
    values = resolve_parameters(model, parameters, require=False).symbol_values(model)
    used = set().union(eom.mass_matrix.free_symbols, eom.forcing.free_symbols)
    missing = sorted(str(s) for s in used if s in {p.symbol for p in model.parameters}
                     and s not in values)
    if missing:
        raise ModelError(f"parameters without a value: {', '.join(missing)}",
                         field="parameters")
    M = sp.Matrix(eom.mass_matrix).xreplace(swap)
    f = sp.Matrix(eom.forcing).xreplace(swap) + sp.Matrix(generalized)
    rates = sp.Matrix([ui.diff(t) for ui in u])
    kinematics = sp.Matrix([qi.diff(t) - ui for qi, ui in zip(q, u, strict=True)])
    dynamics = M * rates - f
    return OptyEquations(
        eom=kinematics.col_join(dynamics), states=(*q, *u), specified=specified,
        parameters={s: float(v) for s, v in values.items() if s in used}, time=t)


__all__ = ["OptyEquations", "opty_equations"]
