"""Rigid bodies in space through their Jacobians, with the kinematics left unexpanded.

For a body of constant mass m (kg) and constant inertia I (kg m^2, body axes) whose position
r(q) and rotation R(q) do not depend on t, the Euler-Lagrange operator on
T = 1/2 m v.v + 1/2 omega^T I omega is, with J_v = dr/dq and J_w = d omega/d q_dot (body axes),

    M += m J_v^T J_v + J_w^T I J_w
    f -= m J_v^T (J_v_dot q_dot) + J_w^T (I J_w_dot q_dot + omega x I omega)

(Euler's I omega_dot + omega x I omega projected on the virtual rotations): exactly
d/dt dT/dq_dot - dT/dq, since v = J_v q_dot and omega = J_w q_dot hold without a t term.

The term-by-term path of lagrange.py expands each product of rotation matrices, which keeps
small models in textbook form (sin^2 + cos^2 cancels, a cyclic angle drops out) but grows like
the Fibonacci numbers down a chain of bodies. Here the Jacobians are taken by the memoized
structural differentiator of the nested rotation products, so every rotation-matrix entry and
axis is one shared sub-expression (sympy does not expand a product of sums unless asked) and
code generation with cse stays small. A body takes this path only where its expanded
kinematics would be large (see ``takes_jacobian_form``).
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..model.model import Gravity
from ..model.rotations import RigidBody
from .kinematics import Differentiator
from .rigid_bodies import rotational_kinetic_energy

# Above this many terms in an expanded component of r or omega, a body goes through its
# Jacobians: a chain's third body has 4, its fourth 7 and its eighth 54 (Fibonacci growth),
# while a top or a rolling disc on Euler angles has 2.
EXPANDED_TERMS_LIMIT = 4


def expanded_terms(expr: sp.Expr, memo: dict) -> int:
    """How many terms ``sp.expand(expr)`` would have at most (memoized, nothing is expanded)."""
    found = memo.get(expr)
    if found is None:
        if expr.is_Add:
            found = sum(expanded_terms(a, memo) for a in expr.args)
        elif expr.is_Mul:
            found = 1
            for a in expr.args:
                found *= expanded_terms(a, memo)
        elif expr.is_Pow and expr.exp.is_Integer and expr.exp > 0:
            found = expanded_terms(expr.base, memo) ** int(expr.exp)
        else:
            found = 1
        memo[expr] = found
    return found


def is_scleronomic_with_constant_inertia(body: RigidBody, q: Sequence[sp.Symbol],
                                         t: sp.Symbol, d: Differentiator) -> bool:
    """True when m and I are constants and r, R and omega do not depend on t explicitly
    (then omega = J_w q_dot and v = J_v q_dot, the premise of the Jacobian form)."""
    moving = {t}
    varying = {t, *q}
    if any(d.free_symbols(e) & varying for e in (body.mass, *(x for row in body.inertia
                                                               for x in row))):
        return False
    return not any(d.free_symbols(e) & moving
                   for e in (*body.position, *body.angular_velocity,
                             *(x for row in body.rotation for x in row)))


def takes_jacobian_form(body: RigidBody, q: Sequence[sp.Symbol], t: sp.Symbol,
                        d: Differentiator, memo: dict, force: bool | None = None) -> bool:
    """Whether ``body`` is derived through its Jacobians: it must be scleronomic with constant
    inertia; then ``force`` True/False decides, or (None) the size of its expanded kinematics."""
    if force is False or not is_scleronomic_with_constant_inertia(body, q, t, d):
        return False
    if force:
        return True
    return max(expanded_terms(e, memo) for e in (*body.position, *body.angular_velocity)) \
        > EXPANDED_TERMS_LIMIT


class TimeRate:
    """d/dt of expressions in q along the motion with q_ddot = 0 (q_dot held constant), by the
    chain rule on the expression's own structure, memoized node by node: a nested product of
    rotations costs its number of distinct sub-expressions, where summing dexpr/dq_i q_dot_i
    would differentiate the whole nest once per coordinate (and twice for an acceleration)."""

    def __init__(self, q: Sequence[sp.Symbol], q_dot: Sequence[sp.Symbol], d: Differentiator):
        self.rates = dict(zip(q, q_dot, strict=True))
        self.coordinates = frozenset(q)
        self.q, self.q_dot, self.d = q, q_dot, d
        self.memo: dict[sp.Expr, sp.Expr] = {}

    def __call__(self, expr: sp.Expr) -> sp.Expr:
        if not self.d.free_symbols(expr) & self.coordinates:
            return sp.S.Zero
        found = self.memo.get(expr)
        if found is None:
            found = self.memo[expr] = self._rate(expr)
        return found

    def _rate(self, expr: sp.Expr) -> sp.Expr:
        if expr in self.rates:
            return self.rates[expr]
        if expr.is_Add:
            return sp.Add(*(r for r in map(self, expr.args) if r != 0))
        if expr.is_Mul:
            args = expr.args
            terms = []
            for k, factor in enumerate(args):
                rate = self(factor)
                if rate != 0:
                    terms.append(sp.Mul(*args[:k], rate, *args[k + 1:]))
            return sp.Add(*terms)
        if isinstance(expr, sp.sin):
            return sp.cos(expr.args[0]) * self(expr.args[0])
        if isinstance(expr, sp.cos):
            return -sp.sin(expr.args[0]) * self(expr.args[0])
        if expr.is_Pow and not self.d.free_symbols(expr.exp) & self.coordinates:
            base, exponent = expr.args
            return exponent * base ** (exponent - 1) * self(base)
        # anything else: the chain rule through its partial derivatives
        return self.d.rate(expr, self.q, self.q_dot, sp.Dummy())


def _dot(a: Sequence[sp.Expr], b: Sequence[sp.Expr]) -> sp.Expr:
    # Zeros are skipped, never multiplied: 0 * (a deep tree) makes sympy ask is_finite of it.
    return sp.Add(*(x * y for x, y in zip(a, b, strict=True) if x != 0 and y != 0))


def _apply(matrix, vector: Sequence[sp.Expr]) -> list[sp.Expr]:
    return [_dot(row, vector) for row in matrix]


def _cross(a: Sequence[sp.Expr], b: Sequence[sp.Expr]) -> list[sp.Expr]:
    return [_dot((a[1], -a[2]), (b[2], b[1])), _dot((a[2], -a[0]), (b[0], b[2])),
            _dot((a[0], -a[1]), (b[1], b[0]))]


def _scaled(factor: sp.Expr, expr: sp.Expr) -> sp.Expr:
    return sp.S.Zero if expr == 0 else factor * expr


def jacobian_equations(body: RigidBody, q: Sequence[sp.Symbol], q_dot: Sequence[sp.Symbol],
                       t: sp.Symbol, gravity: Gravity | None, d: Differentiator):
    """This body's part of M (kg, kg m^2) and f (N, N m), weight included, and its T (J).

    Returns ({(i, j): M_ij for j >= i}, [f_i], T).
    """
    n = len(q)
    m, inertia = body.mass, body.inertia
    omega = tuple(body.angular_velocity)
    linear = [[d(r, x) for r in body.position] for x in q]  # J_v columns (world axes)
    angular = [[d(w, v) for w in omega] for v in q_dot]  # J_w columns (body axes)
    rate = TimeRate(q, q_dot, d)
    velocity = [rate(r) for r in body.position]  # = J_v q_dot
    # J_dot q_dot: the acceleration and the angular acceleration at q_ddot = 0.
    acceleration = [rate(v) for v in velocity]
    angular_rate = [rate(w) for w in omega]
    momentum = _apply(inertia, omega)  # I omega, body axes
    euler = [sp.Add(a, b) for a, b in zip(_apply(inertia, angular_rate),
                                          _cross(omega, momentum), strict=True)]
    weight = ([_scaled(m * gravity.magnitude, c) for c in gravity.direction]
              if gravity is not None else [sp.S.Zero] * 3)
    mass: dict[tuple[int, int], sp.Expr] = {}
    forcing = []
    for i in range(n):
        moving, turning = any(x != 0 for x in linear[i]), any(x != 0 for x in angular[i])
        if not (moving or turning):
            forcing.append(sp.S.Zero)
            continue
        turned = _apply(inertia, angular[i]) if turning else [sp.S.Zero] * 3
        for j in range(i, n):
            entry = sp.Add(_scaled(m, _dot(linear[i], linear[j])), _dot(turned, angular[j]))
            if entry != 0:
                mass[(i, j)] = entry
        forcing.append(sp.Add(_dot(linear[i], weight),
                              -_scaled(m, _dot(linear[i], acceleration)),
                              -_dot(angular[i], euler)))
    kinetic = sp.Add(_scaled(m / 2, sp.Add(*(v**2 for v in velocity if v != 0))),
                     rotational_kinetic_energy(body))
    return mass, forcing, kinetic
