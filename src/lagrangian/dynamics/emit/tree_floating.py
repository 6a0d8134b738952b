"""The floating base in the articulated-body algorithm (tree_algorithms._forward_dynamics): the
free-flyer root's motion and its 6 x 6 solve, as Pinocchio's aba does for JointModelFreeFlyer.

The base's velocity v[:6] is its twist in its own axes, linear then angular (free_flyer.py); its
generalized force tau[:6] the wrench on it, force then moment (N, N m). With S = 1 the root's
articulated inertia IA (after every child's share) gives its spatial acceleration outright:
IA a = tau - pA, gravity entering as the ground's upward acceleration g. Below, the joints of
several numbers below the root (ball joints, free flyers between links): their placement and
motion subspace for the other recursions."""

from __future__ import annotations

from ...kinds import JointKind
from ..tree.joint_models import joint_model
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


# -- the joints of several numbers below the root: a ball joint (MuJoCo's, q w x y z, v the
# child's angular velocity in its own axes) and a free flyer (q x y z qx qy qz qw, v its twist in
# its own axes, linear then angular), as the numpy reference's (algorithms/recursions.py) --

def several(joint) -> bool:
    """Whether ``joint`` is a ball joint or a free flyer below the root (several numbers)."""
    return joint.coordinate >= 0 and joint.kind in (JointKind.SPHERICAL, JointKind.FREE_FLYER)


def several_columns(joint) -> list[tuple[list | None, list | None]]:
    """S's columns (s_w, s_v) in the child's axes, one per velocity number (None: zero)."""
    return [(None if s_w is None else [float(x) for x in s_w],
             None if s_v is None else [float(x) for x in s_v])
            for s_w, s_v in joint_model(joint.kind).columns()]


def quaternion_rotation(E: _Emitter, x: Term, y: Term, z: Term, w: Term):
    """The rotation of the quaternion (x, y, z, w) made unit (2 / |q|^2 in place of 2)."""
    s = E.div(2.0, E.sum([E.mul(c, c) for c in (x, y, z, w)]))
    xx, yy, zz = E.mul(x, x), E.mul(y, y), E.mul(z, z)
    xy, xz, yz = E.mul(x, y), E.mul(x, z), E.mul(y, z)
    wx, wy, wz = E.mul(w, x), E.mul(w, y), E.mul(w, z)
    return [[E.sub(1.0, E.mul(s, E.add(yy, zz))), E.mul(s, E.sub(xy, wz)), E.mul(s, E.add(xz, wy))],
            [E.mul(s, E.add(xy, wz)), E.sub(1.0, E.mul(s, E.add(xx, zz))), E.mul(s, E.sub(yz, wx))],
            [E.mul(s, E.sub(xz, wy)), E.mul(s, E.add(yz, wx)), E.sub(1.0, E.mul(s, E.add(xx, yy)))]]


def several_placement(E: _Emitter, joint, q):
    """R = R_0 R(quaternion), p = t_0 (a ball, q = w x y z) or t_0 + R_0 (x, y, z) (a free
    flyer, q = x y z qx qy qz qw): the joint's own numbers ``q``."""
    R0 = [list(row) for row in joint.rotation]
    if joint.kind == JointKind.SPHERICAL:
        w, x, y, z = q[:4]
        return E.matmul(R0, quaternion_rotation(E, x, y, z, w)), list(joint.translation)
    return (E.matmul(R0, quaternion_rotation(E, *q[3:7])),
            E.vadd(list(joint.translation), E.apply(R0, list(q[:3]))))


def several_rates(E: _Emitter, joint, rates) -> tuple[list[Term], list[Term]]:
    """S times the joint's own rates (or accelerations): its angular and linear part."""
    w: list[Term] = [0.0] * 3
    v: list[Term] = [0.0] * 3
    for rate, (s_w, s_v) in zip(rates, several_columns(joint), strict=True):
        if s_w is not None:
            w = E.vadd(w, E.scale(rate, s_w))
        if s_v is not None:
            v = E.vadd(v, E.scale(rate, s_v))
    return w, v


def _columns_times(E: _Emitter, A, B, C, s_w, s_v):
    """U = IA S for one column: (A s_w + B s_v, B^T s_w + C s_v)."""
    zero: list[Term] = [0.0] * 3
    return (E.vadd(zero if s_w is None else E.apply(A, s_w), zero if s_v is None else E.apply(B, s_v)),
            E.vadd(zero if s_w is None else E.apply_transpose(B, s_w),
                   zero if s_v is None else E.apply(C, s_v)))


def _along(E: _Emitter, s_w, s_v, n, f) -> Term:
    """S_a^T (n, f) for one column."""
    return E.add(0.0 if s_w is None else E.dot(s_w, n), 0.0 if s_v is None else E.dot(s_v, f))


def several_articulated(E: _Emitter, joint, A, B, C, pn, pf, c, efforts):
    """The articulated-body step of a joint of several columns (k = 3 or 6): U = IA S,
    D = S^T U (k x k, its lower triangle), u = tau - S^T pA, and what the parent takes:
    Ia = IA - U D^-1 U^T and pa = pA + Ia c + U D^-1 u (D^-1 by straight-line Cholesky, its
    factor shared by value numbering). Gives ((U, D, u), (Aa, Ba, Ca, an, af))."""
    columns = several_columns(joint)
    U = [_columns_times(E, A, B, C, s_w, s_v) for s_w, s_v in columns]
    D = {(r, k): _along(E, *columns[r], *U[k]) for r in range(len(columns)) for k in range(r + 1)}
    u = [E.sub(effort, _along(E, s_w, s_v, pn, pf))
         for effort, (s_w, s_v) in zip(efforts, columns, strict=True)]
    count = len(columns)
    inverse = [_cholesky_solve(E, D, [1.0 if r == k else 0.0 for r in range(count)])
               for k in range(count)]  # D^-1's columns (= rows: D is symmetric)
    # W_a = sum_b (D^-1)_ab U_b, so U D^-1 U^T = sum_a U_a W_a^T and U D^-1 u = sum_a u_a W_a
    W = [tuple([E.sum(E.mul(inverse[a][b], U[b][part][r]) for b in range(count))
                for r in range(3)] for part in (0, 1)) for a in range(count)]

    def less(X, left, right):
        return [[E.sub(X[r][k], E.sum(E.mul(U[a][left][r], W[a][right][k]) for a in range(count)))
                 for k in range(3)] for r in range(3)]

    Aa, Ba, Ca = less(A, 0, 0), less(B, 0, 1), less(C, 1, 1)
    cw, cv = c
    Bt = [[Ba[k][r] for k in range(3)] for r in range(3)]
    an = E.vadd(E.vadd(pn, E.vadd(E.apply(Aa, cw), E.apply(Ba, cv))),
                [E.sum(E.mul(u[a], W[a][0][r]) for a in range(count)) for r in range(3)])
    af = E.vadd(E.vadd(pf, E.vadd(E.apply(Bt, cw), E.apply(Ca, cv))),
                [E.sum(E.mul(u[a], W[a][1][r]) for a in range(count)) for r in range(3)])
    return (U, D, u), (Aa, Ba, Ca, an, af)


def several_acceleration(E: _Emitter, joint, solved, aw, av):
    """q_ddot of the joint's numbers, D^-1 (u - U^T a'), and its body's spatial acceleration
    a' + S q_ddot, from a' = (aw, av), its parent's moved into its axes with the bias c."""
    U, D, u = solved
    rhs = [E.sub(u_a, E.add(E.dot(Un, aw), E.dot(Uf, av))) for u_a, (Un, Uf) in zip(u, U, strict=True)]
    x = _cholesky_solve(E, D, rhs)
    for x_a, (s_w, s_v) in zip(x, several_columns(joint), strict=True):
        if s_w is not None:
            aw = E.vadd(aw, E.scale(x_a, s_w))
        if s_v is not None:
            av = E.vadd(av, E.scale(x_a, s_v))
    return x, aw, av
