"""Whether a model's velocity terms are the Coriolis and centrifugal terms of its mass matrix:
f(q, q_dot) - f(q, 0) = -C(q, q_dot) q_dot with C_ij = sum_k Gamma_ijk q_dot_k and the
Christoffel symbols Gamma_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2.

Only then is C(q, q_dot) (with M_dot - 2 C skew-symmetric) the matrix of the velocity terms: a
damper, a gyroscopic load, a moving support or a mass matrix that changes with t adds velocity
terms that are not M's, and a C built from them would be a wrong equation."""

from __future__ import annotations

import sympy as sp

from ..model.expressions import as_expression
from .equations import EquationsOfMotion
from .regularity import _Evaluator, _random_point


def christoffel_velocity_terms(eom: EquationsOfMotion) -> list[sp.Expr]:
    """c_i = sum_jk Gamma_ijk q_dot_j q_dot_k from M (N m or N per coordinate)."""
    model = eom.model
    q, v = model.q, model.q_dot
    n = len(q)
    M = [[as_expression(eom.mass_matrix[i, j]) for j in range(n)] for i in range(n)]
    dM = [[[M[i][j].diff(q[k]) for k in range(n)] for j in range(n)] for i in range(n)]
    return [sp.Add(*(sp.Rational(1, 2) * (dM[i][j][k] + dM[i][k][j] - dM[j][k][i]) * v[j] * v[k]
                     for j in range(n) for k in range(n)))
            for i in range(n)]


def velocity_terms_are_christoffel(eom: EquationsOfMotion, samples: int = 3) -> bool:
    """f(q, q_dot) - f(q, 0) + c(q, q_dot) = 0 (c from M's Christoffel symbols) at random
    points, parameters included, and neither M nor f depends on t."""
    model = eom.model
    if model.constraints:
        return False
    forcing = [as_expression(e) for e in eom.forcing]
    mass = [as_expression(e) for e in eom.mass_matrix]
    if any(model.time in e.free_symbols for e in (*forcing, *mass)):
        return False
    at_rest = {v: sp.S.Zero for v in model.q_dot}
    velocity_terms = [f - f.xreplace(at_rest) for f in forcing]
    christoffel = christoffel_velocity_terms(eom)
    symbols = set().union(*(e.free_symbols for e in (*velocity_terms, *christoffel, *mass)))
    for seed in range(samples):
        evaluate = _Evaluator(_random_point(model, symbols, seed=3000 + seed))
        try:
            for f, c in zip(velocity_terms, christoffel, strict=True):
                a, b = evaluate(f), evaluate(c)
                if abs(a + b) > 1e-9 * max(1.0, abs(a), abs(b)):
                    return False
        except (TypeError, ValueError, ZeroDivisionError, OverflowError):
            return False
    return True


__all__ = ["christoffel_velocity_terms", "velocity_terms_are_christoffel"]
