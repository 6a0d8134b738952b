"""The equations of motion as CasADi Functions, built from our sympy trees node by node.

Each sympy node becomes the CasADi SX operation of the same name (no text is printed or
parsed), so CasADi's automatic differentiation gives exact Jacobians of M(q), f(q, q_dot, u)
and x_dot = rhs(x, u). Units SI throughout.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import sympy as sp
from sympy.functions.elementary.piecewise import ExprCondPair

from ..derivation.equations import EquationsOfMotion
from ..errors import ModelError, require_extra
from ..model.inputs import input_parameter
from ..model.values import resolve_parameters

# sympy function -> the casadi function of the same mathematics (looked up by name on casadi).
_UNARY = {sp.sin: "sin", sp.cos: "cos", sp.tan: "tan", sp.exp: "exp", sp.log: "log",
          sp.asin: "asin", sp.acos: "acos", sp.atan: "atan", sp.sinh: "sinh",
          sp.cosh: "cosh", sp.tanh: "tanh", sp.Abs: "fabs", sp.sign: "sign",
          sp.floor: "floor", sp.ceiling: "ceil"}


def casadi_module():
    """The casadi package, imported on first use (the extra [casadi]), refused in one line
    where it is not installed."""
    require_extra("casadi", ["casadi"], "a CasADi bridge (to_casadi, optimize)")
    import casadi

    return casadi


def sympy_to_sx(exprs: Sequence[sp.Expr], env: Mapping[sp.Symbol, object]) -> list:
    """Each expression as a casadi SX, its symbols taken from ``env`` (symbol -> SX or float).

    Shared sub-expressions are converted once; a node with no CasADi counterpart (an undefined
    function, a derivative left in the equations) is refused by name."""
    ca = casadi_module()
    exprs = [sp.sympify(e) for e in exprs]  # safe: sympy objects (derived), no text
    done: dict = {}
    for root in exprs:  # post-order: each node after its arguments, each node once
        stack = [(root, False)]
        while stack:
            node, ready = stack.pop()
            if node in done:
                continue
            if ready:
                done[node] = _node(ca, node, env, done)
            else:
                stack.append((node, True))
                stack.extend((a, False) for a in node.args if a not in done)
    return [done[e] for e in exprs]


def _node(ca, node, env, done):
    if node.is_Symbol:
        if node not in env:
            raise ModelError(f"'{node}' has no value for CasADi (not a state, input or "
                             "parameter with a value)", field="parameters")
        return env[node]
    if node.is_Number or node in (sp.pi, sp.E):
        return ca.SX(float(node))
    if node is sp.true or node is sp.false:
        return ca.SX(float(bool(node)))
    if isinstance(node, ExprCondPair):  # read by its Piecewise
        return None
    args = [done[a] for a in node.args]
    if isinstance(node, sp.Add):
        return _fold(args, lambda a, b: a + b)
    if isinstance(node, sp.Mul):
        return _fold(args, lambda a, b: a * b)
    if isinstance(node, sp.Pow):
        base, exponent = args
        if node.exp == sp.Rational(1, 2):
            return ca.sqrt(base)
        if node.exp.is_Integer:
            return ca.constpow(base, exponent) if node.exp > 0 else 1 / ca.constpow(
                base, ca.SX(float(-node.exp)))
        return ca.power(base, exponent)
    if node.func in _UNARY:
        return getattr(ca, _UNARY[node.func])(args[0])
    if isinstance(node, sp.atan2):
        return ca.atan2(args[0], args[1])
    if isinstance(node, (sp.Min, sp.Max)):
        pick = ca.fmin if isinstance(node, sp.Min) else ca.fmax
        return _fold(args, pick)
    if isinstance(node, sp.Heaviside):
        return ca.if_else(args[0] > 0, 1.0, ca.if_else(args[0] < 0, 0.0, 0.5))
    if isinstance(node, sp.Piecewise):
        value = ca.SX(float("nan"))
        for pair in reversed(node.args):
            value = done[pair.expr] if pair.cond is sp.true else \
                ca.if_else(done[pair.cond], done[pair.expr], value)
        return value
    relations = {sp.StrictGreaterThan: "gt", sp.GreaterThan: "ge", sp.StrictLessThan: "lt",
                 sp.LessThan: "le"}
    if type(node) in relations:
        a, b = args
        return {"gt": a > b, "ge": a >= b, "lt": a < b, "le": a <= b}[relations[type(node)]]
    if isinstance(node, sp.And):
        return _fold(args, ca.logic_and)
    if isinstance(node, sp.Or):
        return _fold(args, ca.logic_or)
    raise ModelError(f"CasADi has no counterpart of {type(node).__name__} in the equations "
                     f"({str(node)[:60]})", field="to_casadi")


def _fold(args, op):
    value = args[0]
    for a in args[1:]:
        value = op(value, a)
    return value


@dataclass(frozen=True)
class CasadiFunctions:
    """CasADi Functions of a model (SI units), x = [q; q_dot]:

    ``rhs(x, u)`` -> x_dot (with constraints, the KKT solve simulate uses), ``mass_matrix(q)``
    -> M, ``forcing(q, q_dot, u)`` -> f of M q_ddot (+ Phi_q^T lambda) = f, ``constraints(q,
    q_dot)`` -> the residuals Phi (holonomic) and A q_dot + b (velocity), None without
    constraints. ``inputs`` name the entries of u (as ``linearize(inputs=...)``): a generalized
    force on a coordinate, or added to a load's parameter (as simulate's controller does).
    Equations with t explicit (``time_dependent``): each Function takes t (s) last.
    A robot whose q and v differ (a floating base, ball joints, a free flyer below the root)
    has x = [q (nq); v (nv)] in our dynamics' layout, named by ``configuration`` and
    ``velocities`` (dynamics/standalone/casadi_tree.py), M nv x nv, f and tau nv."""

    coordinates: tuple[str, ...]
    inputs: tuple[str, ...]
    constraint_names: tuple[str, ...]
    rhs: object
    mass_matrix: object
    forcing: object
    constraints: object | None
    # per input, the coordinate whose generalized force it is (its index), None for a load
    input_coordinates: tuple[int | None, ...] = ()
    # the names of q and v where they differ (a floating base's numbers first, a quaternion's
    # four); () where x = [q; q_dot] of the coordinates
    configuration: tuple[str, ...] = ()
    velocities: tuple[str, ...] = ()
    # x starts with a floating base's seven and six numbers (base_x .. base_wz)
    floating: bool = False
    # the equations hold t explicitly (a driven support, a force of time): each Function then
    # takes t (s) as its last argument, rhs(x, u, t), mass_matrix(q, t), ...
    time_dependent: bool = False

    @property
    def floating_base(self) -> bool:
        """Whether x holds a floating base's seven and six numbers first."""
        return self.floating

    @property
    def states(self) -> tuple[str, ...]:
        """The names of x: the coordinates, then their velocities (``theta_dot``); a floating
        base's numbers first in each (base_x .. base_qw, base_vx .. base_wz), a ball's four
        and three (shoulder_qw .. shoulder_qz, shoulder_wx .. shoulder_wz)."""
        if self.configuration:
            return self.configuration + self.velocities
        return self.coordinates + tuple(f"{c}_dot" for c in self.coordinates)

    def __repr__(self) -> str:
        extra = f", constraints={list(self.constraint_names)}" if self.constraint_names else ""
        extra += ", time_dependent=True" if self.time_dependent else ""
        return (f"CasadiFunctions(states={list(self.states)}, inputs={list(self.inputs)}"
                f"{extra})")


def casadi_functions(eom: EquationsOfMotion, inputs: Sequence[str] = (),
                     parameters: Mapping[str, float] | None = None) -> CasadiFunctions:
    """rhs, mass_matrix, forcing and constraints of ``eom`` as CasADi Functions; the named
    ``inputs`` (parameters, loads or coordinates: a generalized force on it) are the entries
    of u, the other parameters their model values overridden by ``parameters`` (SI)."""
    ca = casadi_module()
    model = eom.model
    inputs = tuple(inputs)
    if len(set(inputs)) != len(inputs):
        raise ModelError(f"an input is named twice: {list(inputs)}", field="inputs")
    n, m, r = len(model.q), len(model.constraints), len(inputs)
    timed = _uses(eom, {model.time})  # t explicit: every function takes it last
    q, v, u = ca.SX.sym("q", n), ca.SX.sym("q_dot", n), ca.SX.sym("u", r)
    t = ca.SX.sym("t")
    extra, extra_name = ([t], ["t"]) if timed else ([], [])
    symbols = {p.symbol for p in model.parameters}
    input_symbols: dict[sp.Symbol, int] = {}
    generalized: list[tuple[int, int]] = []  # (coordinate row, input index)
    names = [c.name for c in model.coordinates]
    for k, name in enumerate(inputs):
        symbol = input_parameter(model, name)
        if symbol is None:
            generalized.append((names.index(name), k))
        else:
            input_symbols[symbol] = k
    if _uses(eom, set(input_symbols), forcing=False):
        raise ModelError("an input enters the mass matrix or the constraints: inputs are loads "
                         "(forces, torques), not masses or lengths", field="inputs")
    values = resolve_parameters(model, parameters, require=False)
    env: dict = {s: float(x) for s, x in values.symbol_values(model).items()}
    missing = sorted(p.name for p in model.parameters
                     if p.symbol not in env and p.symbol not in input_symbols)
    needed = {str(s) for s in _free(eom)} & set(missing)
    if needed:
        raise ModelError(f"parameters without a value: {', '.join(sorted(needed))}",
                         field="parameters")
    env.update({s: q[i] for i, s in enumerate(model.q)})
    env.update({s: v[i] for i, s in enumerate(model.q_dot)})
    # an input on a parameter is added to the parameter's own value, as simulate's controller
    env.update({s: env.get(s, 0.0) + u[k] for s, k in input_symbols.items()})
    env.update({s: 0.0 for s in symbols if s not in env})  # unused parameters
    env[model.time] = t
    mass = ca.reshape(ca.vertcat(*sympy_to_sx(list(eom.mass_matrix), env)), n, n).T
    forcing = ca.vertcat(*sympy_to_sx(list(eom.forcing), env))
    for row, k in generalized:
        forcing[row] = forcing[row] + u[k]
    if m:
        jacobian = ca.reshape(ca.vertcat(*sympy_to_sx(list(eom.constraint_jacobian), env)),
                              n, m).T
        gamma = ca.vertcat(*sympy_to_sx(list(eom.acceleration_rhs), env))
        kkt = ca.blockcat([[mass, jacobian.T], [jacobian, ca.SX.zeros(m, m)]])
        q_ddot = ca.solve(kkt, ca.vertcat(forcing, gamma))[:n]
        residual = ca.vertcat(*sympy_to_sx([c.expression for c in model.constraints], env))
        constraints = ca.Function("constraints", [q, v, *extra], [residual],
                                  ["q", "q_dot", *extra_name], ["residual"])
    else:
        q_ddot = ca.solve(mass, forcing)
        constraints = None
    x = ca.vertcat(q, v)
    return CasadiFunctions(
        coordinates=tuple(names), inputs=inputs,
        constraint_names=tuple(c.name for c in model.constraints),
        rhs=ca.Function("rhs", [x, u, *extra], [ca.vertcat(v, q_ddot)],
                        ["x", "u", *extra_name], ["x_dot"]),
        mass_matrix=ca.Function("mass_matrix", [q, *extra], [mass], ["q", *extra_name], ["M"]),
        forcing=ca.Function("forcing", [q, v, u, *extra], [forcing],
                            ["q", "q_dot", "u", *extra_name], ["f"]),
        constraints=constraints,
        input_coordinates=tuple(names.index(k) if k in names else None for k in inputs),
        time_dependent=timed)


def _free(eom: EquationsOfMotion) -> set:
    parts = [eom.mass_matrix, eom.forcing, eom.constraint_jacobian, eom.acceleration_rhs,
             *(sp.sympify(c.expression) for c in eom.model.constraints)]  # safe: sympy objects
    return set().union(*(p.free_symbols for p in parts))


def _uses(eom: EquationsOfMotion, symbols: set, forcing: bool = True) -> bool:
    parts = [eom.mass_matrix, eom.constraint_jacobian, eom.acceleration_rhs,
             *(sp.sympify(c.expression) for c in eom.model.constraints)]  # safe: sympy objects
    if forcing:
        parts.append(eom.forcing)
    return any(p.free_symbols & symbols for p in parts)


__all__ = ["CasadiFunctions", "casadi_functions", "casadi_module", "sympy_to_sx"]
