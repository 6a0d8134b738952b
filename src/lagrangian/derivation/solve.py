"""Symbolic accelerations for small systems; larger ones keep the implicit form M q_ddot = f."""

from __future__ import annotations

import sympy as sp

# Above these sizes a symbolic solve for q_ddot swells; users get the implicit form only.
SYMBOLIC_SOLVE_MAX_UNKNOWNS = 3
SYMBOLIC_SOLVE_MAX_OPS = 200
# cancel() is superlinear in expression size: past this the closed form is not worth showing.
SYMBOLIC_SOLUTION_MAX_OPS = 1500


def solve_accelerations(mass_matrix, forcing, jacobian, gamma) -> sp.ImmutableMatrix | None:
    """Solve [[M, Phi_q^T], [Phi_q, 0]] [q_ddot; lambda] = [f; gamma] for q_ddot, when small."""
    n, m = mass_matrix.shape[0], jacobian.shape[0]
    if n + m > SYMBOLIC_SOLVE_MAX_UNKNOWNS:
        return None
    if sp.count_ops(mass_matrix) + sp.count_ops(forcing) > SYMBOLIC_SOLVE_MAX_OPS:
        return None
    if m:
        system = sp.Matrix(sp.BlockMatrix([[mass_matrix, jacobian.T],
                                           [jacobian, sp.zeros(m, m)]]))
        rhs = sp.Matrix.vstack(sp.Matrix(forcing), sp.Matrix(gamma))
    else:
        system, rhs = sp.Matrix(mass_matrix), sp.Matrix(forcing)
    try:
        solution = system.LUsolve(rhs)
    except (ValueError, ZeroDivisionError, sp.matrices.exceptions.NonInvertibleMatrixError):
        return None
    if any(value.has(sp.nan, sp.zoo) for value in solution):
        return None
    if sp.count_ops(solution) > SYMBOLIC_SOLUTION_MAX_OPS:
        return None
    # Small by the guards above, so a rational cancellation is cheap and much more readable.
    return sp.ImmutableMatrix(n, 1, [sp.factor_terms(sp.cancel(v)) for v in solution[:n]])
