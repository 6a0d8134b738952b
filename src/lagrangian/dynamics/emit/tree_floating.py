"""The floating base in the articulated-body algorithm (tree_algorithms._forward_dynamics): the
free-flyer root's motion and its 6 x 6 solve, as Pinocchio's aba does for JointModelFreeFlyer.

The base's velocity v[:6] is its twist in its own axes, linear then angular (free_flyer.py); its
generalized force tau[:6] the wrench on it, force then moment (N, N m). With S = 1 the root's
articulated inertia IA (after every child's share) gives its spatial acceleration outright:
IA a = tau - pA, gravity entering as the ground's upward acceleration g."""

from __future__ import annotations

from .tree_emitter import Term, _cholesky_solve, _Emitter


def free_root_motion(v) -> tuple[list[Term], list[Term]]:
    """The base's angular and linear velocity (w, v) in its axes (rad/s, m/s) from v[:6]."""
    return list(v[3:6]), list(v[0:3])


def free_root_acceleration(E: _Emitter, R, A, B, C, pn, pf, tau, up):
    """Solve IA a = tau - pA for the base: IA = [[A, B], [B^T, C]] (n = A w + B v,
    f = B^T w + C v, body axes about its origin), pA = (pn, pf), tau the base's wrench (force,
    moment). Gives (aw, av), the base's spatial acceleration with the ground's upward g in it
    (what its children read), and q_ddot[:6] = (av - R^T up, aw), the base's own (m/s^2,
    rad/s^2)."""
    # unknowns (av, aw) so that the rows read (f, n), tau's order: [[C, B^T], [B, A]]
    block = {}
    for r in range(6):
        for c in range(r + 1):
            if r < 3:
                block[r, c] = C[r][c]
            elif c < 3:
                block[r, c] = B[r - 3][c]
            else:
                block[r, c] = A[r - 3][c - 3]
    rhs = [E.sub(tau[k], pf[k]) for k in range(3)] + [E.sub(tau[3 + k], pn[k]) for k in range(3)]
    x = _cholesky_solve(E, block, rhs)
    av, aw = x[:3], x[3:]
    gravity = E.apply_transpose(R, up)  # the ground's upward acceleration in the base's axes
    return (aw, av), [E.sub(a, g) for a, g in zip(av, gravity, strict=True)] + aw
