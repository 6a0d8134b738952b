"""Routh's reduction: the cyclic coordinates' momenta made constants, the rest kept.

Sign convention (Goldstein, Landau): the Routhian is R = sum_k p_k q_dot_k - L over the cyclic
coordinates, with their rates eliminated through p_k = dL/dq_dot_k. The reduced model's
Lagrangian is L_R = -R = L - sum_k p_k q_dot_k (J), so Lagrange's equations of L_R in the
kept coordinates are the full motion's. Each p_k becomes a parameter ``p_<name>``
(kg m^2/s for an angle, kg m/s for a length); steady motions of the full system are then
equilibria of L_R, whose potential part V_R = -L_R(q_dot = 0) is the effective potential.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..errors import ModelError, did_you_mean
from ..model.model import Model, Parameter
from ..model.values import resolve_state
from .conserved import ConservedKind, conserved_quantities


def momentum_unit(unit: str) -> str | None:
    """The unit of dL/dq_dot for a coordinate of ``unit``."""
    if unit in ("rad", "radian", "deg", "degree", "rev", ""):
        return "kg*m^2/s"
    if unit == "m":
        return "kg*m/s"
    return None


def routhian_model(eom: EquationsOfMotion, cyclic: Sequence[str]) -> Model:
    """The reduced model in the coordinates not named in ``cyclic`` (each named one must be
    cyclic with its momentum conserved); p_<name> defaults to its value at the initial state."""
    model = eom.model
    names = [c.name for c in model.coordinates]
    if not cyclic:
        raise ModelError("name the cyclic coordinates to reduce", field="routh")
    for name in cyclic:
        if name not in names:
            raise ModelError(f"'{name}' is not a coordinate{did_you_mean(name, names)}",
                             field="routh")
    if len(set(cyclic)) != len(cyclic):
        raise ModelError("a coordinate is named twice", field="routh")
    found = conserved_quantities(eom) if model.kinematic_tree is None else None
    if found is None:
        raise ModelError("Routh's reduction needs a derived L; a robot's tree has none",
                         field="routh")
    momenta = {q.name: q for q in found.of_kind(ConservedKind.MOMENTUM)}
    for name in cyclic:
        if f"p_{name}" in momenta:
            continue
        why = dict(found.not_cyclic).get(name)
        broken = [b for b in found.broken if b.name == f"p_{name}"]
        if why is not None:
            raise ModelError(f"'{name}' is not cyclic: L depends on it through {why}",
                             field="routh")
        raise ModelError(f"the momentum of '{name}' is not conserved: {broken[0].reason}",
                         field="routh")
    if len(cyclic) == len(names):
        raise ModelError("Routh's reduction keeps at least one coordinate", field="routh")
    existing = {p.name for p in model.parameters} | set(names)
    L = eom.lagrangian
    index = [names.index(n) for n in cyclic]
    v_c = [model.q_dot[i] for i in index]
    p_symbols = []
    for name in cyclic:
        if f"p_{name}" in existing:
            raise ModelError(f"the model already has a name p_{name}", field="routh")
        p_symbols.append(sp.Symbol(f"p_{name}"))
    rows = [sp.expand(L.diff(v)) for v in v_c]  # p_k = A v_c + b, linear in v_c
    A = sp.Matrix([[row.diff(v) for v in v_c] for row in rows])
    if any(entry.free_symbols & set(v_c) for entry in A):
        raise ModelError("L is not quadratic in the cyclic rates: p = dL/dq_dot cannot be "
                         "solved for them", field="routh")
    zero = dict.fromkeys(v_c, sp.S.Zero)
    b = sp.Matrix([row.xreplace(zero) for row in rows])
    if A.det() == 0:
        raise ModelError("the cyclic rates have no inertia: p = dL/dq_dot cannot be solved",
                         field="routh")
    solved = (A.inv() if len(v_c) > 1 else sp.Matrix([[1 / A[0, 0]]])) \
        * (sp.Matrix(p_symbols) - b)
    # L does not depend on a cyclic coordinate, though it may still show it (sin^2 psi +
    # cos^2 psi): it is set to 0, so the reduced model has the kept coordinates only
    absent = {model.q[i]: sp.S.Zero for i in index}
    rates = {v: sp.factor_terms(sp.together(s.xreplace(absent)))
             for v, s in zip(v_c, solved, strict=True)}
    L = L.xreplace(absent)
    reduced = sp.expand(L.xreplace(rates) - sum((p * rates[v] for p, v in
                                                 zip(p_symbols, v_c, strict=True)), sp.S.Zero))
    kept = [c for c in model.coordinates if c.name not in cyclic]
    kept_velocities = dict.fromkeys((c.velocity for c in kept), sp.S.Zero)
    potential = -reduced.xreplace(kept_velocities)
    kinetic = sp.expand(reduced + potential)
    if sp.count_ops(kinetic) < 400:
        kinetic = sp.expand(sp.simplify(kinetic))
    if sp.count_ops(potential) < 2000:  # the effective potential, tidied (the top's: 3 s)
        potential = sp.simplify(potential)
    start = resolve_state(model)
    state = {**dict(zip(model.q, start.q_array(), strict=True)),
             **dict(zip(model.q_dot, start.q_dot_array(), strict=True)), model.time: 0.0}
    values = {p.symbol: p.value for p in model.parameters if p.value is not None}
    parameters = list(model.parameters)
    for name, symbol, i in zip(cyclic, p_symbols, index, strict=True):
        value = sp.sympify(rows[cyclic.index(name)]).xreplace({**values, **state})  # safe: derived
        number = float(value) if value.is_number else None
        parameters.append(Parameter(symbol.name, symbol, number,
                                    momentum_unit(model.coordinates[i].unit)))
    forces = tuple((c.name, Q.xreplace(absent).xreplace(rates)) for c, Q in
                   zip(model.coordinates, eom.generalized_forces, strict=True)
                   if c.name not in cyclic and Q != 0)
    return Model(name=f"{model.name}, reduced by Routh ({', '.join(cyclic)} cyclic)",
                 coordinates=tuple(kept), parameters=tuple(parameters),
                 kinetic_energy=kinetic, potential_energy=potential,
                 generalized_forces=forces,
                 description=(f"L_R = L - {' - '.join(f'p_{n}*{n}_dot' for n in cyclic)} "
                              f"with {', '.join(f'p_{n}' for n in cyclic)} constant "
                              "(the Routhian R = -L_R)"),
                 source=model.source, time=model.time)


__all__ = ["momentum_unit", "routhian_model"]
