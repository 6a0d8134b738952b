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
