"""Rotation of rigid bodies in space: their kinetic energy and the virtual work of moments.

The rotational kinetic energy T = 1/2 omega^T I omega (J; omega in body axes, rad/s, I about
the centre of mass in body axes, kg m^2) goes through the general Euler-Lagrange formula, so an
inertia or a rotation that depends on q or t gives exactly the equations of the printed L.
A moment M (N m) does virtual work M . delta(phi) through the virtual rotation delta(phi), whose
component per delta q_i is d omega/d q_dot_i: Q_i = M . d omega/d q_dot_i.
"""

from __future__ import annotations

import sympy as sp

from ..model.rotations import Moment, RigidBody
from .kinematics import Differentiator
from .trig import combined_terms, parts, product


def rotational_kinetic_energy(body: RigidBody) -> sp.Expr:
    """1/2 omega^T I omega in J (omega in body axes)."""
    omega, inertia = body.angular_velocity, body.inertia
    terms = []
    for i in range(3):
        if omega[i] == 0:
            continue
        if inertia[i][i] != 0:
            terms.append(inertia[i][i] * omega[i] ** 2 / 2)
        for j in range(i + 1, 3):
            if inertia[i][j] != 0 and omega[j] != 0:
                terms.append(inertia[i][j] * omega[i] * omega[j])
    return sp.Add(*terms)


def rotational_equations(body: RigidBody, q, q_dot, t, d: Differentiator):
    """The Euler-Lagrange operator on T = 1/2 omega^T I omega, term by term and tidied:
    W_ij = J_i^T I J_j (J_i = d omega/d q_dot_i) and
    f_i = dT/dq_i - d/dt(J_i^T I omega)|_(q_ddot = 0), i.e. the general formula
    W q_ddot = dT/dq - (d^2T/dq_dot dq) q_dot - d^2T/dq_dot dt written with omega's structure,
    so sin^2 + cos^2 of the spin angle cancels (kg m^2 and N m).

    Returns ({(i, j): W_ij for j >= i}, [f_i]).
    """
    omega, inertia = body.angular_velocity, body.inertia
    n = len(q)
    columns = [tuple(d(w, v) for w in omega) for v in q_dot]
    rate = [d.rate(w, q, q_dot, t) for w in omega]
    inertia_rate = tuple(tuple(d.rate(e, q, q_dot, t) for e in row) for row in inertia)
    mass = {}
    forcing = []
    for i in range(n):
        if not any(c != 0 for c in columns[i]):
            forcing.append(_tidy([*_quadratic(omega, _partial(inertia, q[i], d), omega,
                                              sp.Rational(1, 2)),
                                  *_quadratic(tuple(d(w, q[i]) for w in omega), inertia,
                                              omega)]))
            continue
        for j in range(i, n):
            entry = _tidy(_quadratic(columns[i], inertia, columns[j]))
            if entry != 0:
                mass[(i, j)] = entry
        column_rate = tuple(d.rate(c, q, q_dot, t) for c in columns[i])
        items = [*_quadratic(omega, _partial(inertia, q[i], d), omega, sp.Rational(1, 2)),
                 *_quadratic(tuple(d(w, q[i]) for w in omega), inertia, omega),
                 *_quadratic(column_rate, inertia, omega, -1),
                 *_quadratic(columns[i], inertia_rate, omega, -1),
                 *_quadratic(columns[i], inertia, tuple(rate), -1)]
        forcing.append(_tidy(items))
    return mass, forcing


def _partial(inertia, x, d: Differentiator):
    return tuple(tuple(d(e, x) for e in row) for row in inertia)


def _terms(expr: sp.Expr) -> list:
    if expr == 0:
        return []
    return [parts(x) for x in sp.Add.make_args(sp.expand(expr))]


def _quadratic(a, inertia, b, factor=sp.S.One) -> list:
    """The decomposed terms of factor * a^T I b."""
    scale = parts(factor)
    items = []
    for j in range(3):
        left = _terms(a[j])
        if not left:
            continue
        for k in range(3):
            middle = _terms(inertia[j][k])
            right = _terms(b[k]) if middle else []
            items += [product(scale, product(x, product(y, z)))
                      for x in left for y in middle for z in right]
    return items


def _tidy(items: list) -> sp.Expr:
    return sp.Add(*combined_terms(items))


def moment_projection(load: Moment, q_dot, d: Differentiator | None = None) -> list[sp.Expr]:
    """Q_i = M . d omega/d q_dot_i, omega in the axes M is given in (N m per unit delta q_i)."""
    d = d or Differentiator()
    rows = [d.row(w, q_dot) for w in load.angular_velocity]
    return [sp.Add(*(m * rows[k][i] for k, m in enumerate(load.moment)
                     if m != 0 and rows[k][i] != 0))
            for i in range(len(q_dot))]
