"""The recursions over a robot's kinematic tree, written against the emitter: joint
kinematics, Newton-Euler inverse dynamics, the composite-rigid-body mass matrix, articulated-body
(or Cholesky) forward dynamics and the energies (SI units).

A floating base (a free flyer first, free_flyer.py) takes q and v with its 7 and 6 numbers
first: the joints read q[7:] and v[6:] by their coordinate, the base its own (_free_*). A ball
joint (4 numbers in q, 3 in v) or a free flyer below the root (7 and 6) reads its own q and v
slices (tree_floating.several_*): q is nq wide, v, a and tau nv."""

from __future__ import annotations

from ...kinds import JointKind
from ...model.tree import KinematicTree
from ..tree.joint_models import joint_model
from .tree_emitter import Term, _Emitter, _Layout
from .tree_floating import (
    free_root_acceleration,
    free_root_motion,
    quaternion_rotation,
    several,
    several_acceleration,
    several_articulated,
    several_columns,
    several_placement,
    several_rates,
)


def _rotation(E: _Emitter, joint, c: Term, s: Term):
    """Rot(u, theta) = c 1 + s [u]x + (1 - c) u u^T as terms (c = cos, s = sin theta)."""
    u = joint.axis
    one_minus_c = E.sub(1.0, c)
    R = [[E.mul(one_minus_c, u[i] * u[j]) for j in range(3)] for i in range(3)]
    for i in range(3):
        # along a coordinate axis the diagonal entry is exactly 1, not c + (1 - c)
        R[i][i] = 1.0 if abs(u[i]) == 1.0 else E.add(c, R[i][i])
    cross = ((0, 1, -u[2]), (0, 2, u[1]), (1, 0, u[2]), (1, 2, -u[0]), (2, 0, -u[1]),
             (2, 1, u[0]))
    for i, j, k in cross:
        R[i][j] = E.add(R[i][j], E.mul(s, k))
    return R


def _free(joint) -> bool:
    """The floating base's free flyer (the root's, its numbers before the joints')."""
    return joint.kind == JointKind.FREE_FLYER and joint.coordinate < 0


def _free_placement(E: _Emitter, joint, q):
    """The floating base's R = R_0 R(quaternion) and p = t_0 + R_0 (x, y, z): the rotation of
    the quaternion made unit (2 / |q|^2 in place of 2)."""
    R0 = [list(row) for row in joint.rotation]
    return (E.matmul(R0, quaternion_rotation(E, *q[3:7])),
            E.vadd(list(joint.translation), E.apply(R0, list(q[:3]))))


def _starts(tree: KinematicTree) -> list[int]:
    """Each joint's first number among the joints' own velocity numbers (v after the base)."""
    return [tree.velocity_index(j.coordinate) if j.coordinate >= 0 else -1 for j in tree.joints]


def _columns(joint, start: int):
    """(S's column (s_w, s_v), its index in the joints' v, the rate's multiplier) of a joint."""
    if several(joint):
        return [(column, start + k, 1.0) for k, column in enumerate(several_columns(joint))]
    return [(joint_model(joint.kind).subspace(joint.axis, joint.pitch), start, joint.multiplier)]


def _kinematics(E: _Emitter, tree: KinematicTree, q):
    """Each body's rotation R (body -> parent axes) and origin p (in its parent), as terms."""
    placements = []
    base, q = q, q[tree.base_nq:]  # the joints' own numbers
    for joint in tree.joints:
        if _free(joint):
            placements.append(_free_placement(E, joint, base))
            continue
        if several(joint):
            width = joint_model(joint.kind).nq
            placements.append(several_placement(
                E, joint, q[joint.coordinate:joint.coordinate + width]))
            continue
        theta = E.add(E.mul(q[joint.coordinate], joint.multiplier), joint.offset)
        placements.append(joint_model(joint.kind).placement_terms(E, joint, theta, _rotation))
    return placements


def _project(E: _Emitter, subspace, moment, force) -> Term:
    """S^T (n, f) = s_w . n + s_v . f: a wrench's share along a joint's motion (N m or N)."""
    s_w, s_v = subspace
    return E.add(0.0 if s_w is None else E.dot(s_w, moment),
                 0.0 if s_v is None else E.dot(s_v, force))


def _unit_rate_wrench(E: _Emitter, subspace, m, h, J):
    """The body's momentum (f, n) about its origin at one unit of joint rate along S:
    f = m s_v + s_w x h, n = J s_w + h x s_v."""
    s_w, s_v = subspace
    zero = [0.0] * 3
    force = E.vadd(zero if s_v is None else E.scale(m, s_v),
                   zero if s_w is None else E.cross(s_w, h))
    moment = E.vadd(zero if s_w is None else E.apply(J, s_w),
                    zero if s_v is None else E.cross(h, s_v))
    return force, moment


def _inverse_dynamics(E: _Emitter, tree: KinematicTree, layout: _Layout, q, v, a):
    """Recursive Newton-Euler: the generalized forces tau_i (N m or N) for q, q_dot, q_ddot,
    minus each actuator parameter (the model's own load)."""
    placements = _kinematics(E, tree, q)
    g = layout.gravity
    up = [E.mul(g, -d) for d in tree.gravity_direction]  # the ground accelerates up by g
    w, dw, acc, f, n = [], [], [], [], []
    (vb, v), (ab, a) = (v[:tree.base_nv], v[tree.base_nv:]), (a[:tree.base_nv], a[tree.base_nv:])
    starts = _starts(tree)
    for i, joint in enumerate(tree.joints):
        R, p = placements[i]
        if _free(joint):  # the base: its twist (v, w) and its derivative; origin v_dot + w x v
            w_i, dw_i = list(vb[3:]), list(ab[3:])
            a_i = E.vadd(E.apply_transpose(R, up), E.vadd(list(ab[:3]), E.cross(w_i, list(vb[:3]))))
        elif joint.parent < 0:
            wl, dwl, al = [0.0] * 3, [0.0] * 3, up
        else:
            wl, dwl, al = w[joint.parent], dw[joint.parent], acc[joint.parent]
        if several(joint):  # S v = (ws, vs), S a = (aw, av), S constant in the child's axes
            k, nv = starts[i], joint_model(joint.kind).nv
            ws, vs = several_rates(E, joint, v[k:k + nv])
            aw, av = several_rates(E, joint, a[k:k + nv])
            w_in = E.apply_transpose(R, wl)
            origin = E.vadd(al, E.vadd(E.cross(dwl, p), E.cross(wl, E.cross(wl, p))))
            w_i = E.vadd(w_in, ws)
            dw_i = E.vadd(E.apply_transpose(R, dwl), E.vadd(E.cross(w_in, ws), aw))
            # the origin's: Coriolis 2 w_in x vs, and vs turned by ws in the child's axes
            a_i = E.vadd(E.apply_transpose(R, origin),
                         E.vadd(E.vadd(E.scale(2.0, E.cross(w_in, vs)), E.cross(ws, vs)), av))
        elif not _free(joint):
            s_w, s_v = joint_model(joint.kind).subspace(joint.axis, joint.pitch)
            rate = E.mul(v[starts[i]], joint.multiplier)
            accel = E.mul(a[starts[i]], joint.multiplier)
            w_in = E.apply_transpose(R, wl)
            dw_in = E.apply_transpose(R, dwl)
            origin = E.vadd(al, E.vadd(E.cross(dwl, p), E.cross(wl, E.cross(wl, p))))
            a_i = E.apply_transpose(R, origin)
            w_i, dw_i = w_in, dw_in
            if s_w is not None:  # turning: w += rate s_w, dw += w_in x rate s_w + accel s_w
                w_i = E.vadd(w_in, E.scale(rate, s_w))
                dw_i = E.vadd(dw_in, E.vadd(E.cross(w_in, E.scale(rate, s_w)),
                                            E.scale(accel, s_w)))
            if s_v is not None:  # sliding: the Coriolis term 2 w x rate s_v and accel s_v
                a_i = E.vadd(a_i, E.vadd(E.scale(2.0, E.cross(w_i, E.scale(rate, s_v))),
                                         E.scale(accel, s_v)))
        w.append(w_i)
        dw.append(dw_i)
        acc.append(a_i)
        m, h, J = joint.mass, list(joint.first_moment), [list(r) for r in joint.inertia]
        # about the body's origin: f = m a + dw x h + w x (w x h), n = J dw + w x J w + h x a
        f.append(E.vadd(E.scale(m, a_i), E.vadd(E.cross(dw_i, h), E.cross(w_i, E.cross(w_i, h)))))
        n.append(E.vadd(E.vadd(E.apply(J, dw_i), E.cross(w_i, E.apply(J, w_i))),
                        E.cross(h, a_i)))
    tau: list[Term] = [0.0] * (layout.n - tree.base_nv)
    base: list[Term] = []
    for i in reversed(range(len(tree.joints))):
        joint = tree.joints[i]
        if _free(joint):  # the wrench on the base, force then moment, in its axes
            base = f[i] + n[i]
            continue
        for subspace, k, multiplier in _columns(joint, starts[i]):
            tau[k] = E.add(tau[k], E.mul(_project(E, subspace, n[i], f[i]), multiplier))
        if joint.parent >= 0:
            R, p = placements[i]
            force = E.apply(R, f[i])
            f[joint.parent] = E.vadd(f[joint.parent], force)
            n[joint.parent] = E.vadd(n[joint.parent],
                                     E.vadd(E.apply(R, n[i]), E.cross(p, force)))
    return base + [E.sub(t, actuator) for t, actuator in zip(tau, layout.actuators, strict=True)]


def _mass_matrix(E: _Emitter, tree: KinematicTree, layout: _Layout, q):
    """Composite-rigid-body algorithm: M (lower triangle, row-major entries i >= j)."""
    placements = _kinematics(E, tree, q)
    nb = len(tree.joints)
    mass = [j.mass for j in tree.joints]
    h = [list(j.first_moment) for j in tree.joints]
    J = [[list(r) for r in j.inertia] for j in tree.joints]
    entries, first, starts = {}, tree.base_nv, _starts(tree)

    def add(r, c, x):  # M[first + r, first + c] (c < 0: the base's column first + c)
        entries[first + r, first + c] = E.add(entries.get((first + r, first + c), 0.0), x)

    for i in reversed(range(nb)):
        joint = tree.joints[i]
        if _free(joint):  # the composite inertia of the whole robot, [[m, -[h]x], [[h]x, J]]
            m, (hx, hy, hz) = mass[i], h[i]
            block = [[m, 0.0, 0.0], [0.0, m, 0.0], [0.0, 0.0, m],
                     [0.0, E.neg(hz), hy, J[i][0][0]], [hz, 0.0, E.neg(hx), J[i][1][0], J[i][1][1]],
                     [E.neg(hy), hx, 0.0, J[i][2][0], J[i][2][1], J[i][2][2]]]
            for r, row in enumerate(block):
                for c, x in enumerate(row):
                    entries[r, c] = E.add(entries.get((r, c), 0.0), x)
            continue
        own = _columns(joint, starts[i])
        for subspace, ci, ki in own:  # one column of M per velocity number of the joint
            force, moment = _unit_rate_wrench(E, subspace, mass[i], h[i], J[i])
            for row, ri, kr in own:
                if ri >= ci:
                    add(ri, ci, E.mul(_project(E, row, moment, force), ki * kr))
            k = i
            while tree.joints[k].parent >= 0:
                R, p = placements[k]
                force = E.apply(R, force)
                moment = E.vadd(E.apply(R, moment), E.cross(p, force))
                k = tree.joints[k].parent
                ancestor = tree.joints[k]
                if _free(ancestor):  # S = 1: the wrench itself, force then moment
                    for c, x in enumerate(force + moment):
                        add(ci, c - first, E.mul(x, ki))
                    continue
                for space, ak, ka in _columns(ancestor, starts[k]):
                    x = E.mul(_project(E, space, moment, force), ki * ka)
                    if ci >= ak:
                        add(ci, ak, x)
                    if ak >= ci:  # both where a mimic joint shares its ancestor's coordinate
                        add(ak, ci, x)
        parent = joint.parent
        if parent >= 0:  # the composite inertia of body i, moved into its parent's axes
            R, p = placements[i]
            hr = E.apply(R, h[i])
            A = [E.apply(R, [J[i][0][c], J[i][1][c], J[i][2][c]]) for c in range(3)]  # columns
            RJRt = [[None] * 3 for _ in range(3)]
            for r in range(3):
                for c in range(r, 3):
                    RJRt[r][c] = RJRt[c][r] = E.dot([A[0][r], A[1][r], A[2][r]], R[c])
            ph = E.dot(p, hr)
            pp = E.dot(p, p)
            for r in range(3):
                for c in range(r, 3):
                    # J' = R J R^T + m (|p|^2 1 - p p^T) + 2 (p.h) 1 - p h^T - h p^T
                    shift = E.sub(E.neg(E.mul(mass[i], E.mul(p[r], p[c]))),
                                  E.add(E.mul(p[r], hr[c]), E.mul(hr[r], p[c])))
                    if r == c:
                        shift = E.add(shift, E.add(E.mul(mass[i], pp), E.mul(2.0, ph)))
                    entry = E.add(J[parent][r][c], E.add(RJRt[r][c], shift))
                    J[parent][r][c] = J[parent][c][r] = entry
            h[parent] = E.vadd(h[parent], E.vadd(hr, E.scale(mass[i], p)))
            mass[parent] = mass[parent] + mass[i]
    return entries


def _articulated(tree: KinematicTree) -> bool:
    """Whether the articulated-body algorithm applies: each coordinate drives one joint, as
    its angle or distance (no mimic joint); a floating base's free flyer is the root's."""
    joints = [j for j in tree.joints if not _free(j)]
    used = [j.coordinate for j in joints]
    return len(set(used)) == len(used) and all(j.multiplier == 1.0 for j in joints)


def _forward_dynamics(E: _Emitter, tree: KinematicTree, layout: _Layout, q, v, tau):
    """Articulated-body algorithm (Featherstone): q_ddot for q, q_dot and tau (on top of the
    actuator parameters), O(n). Spatial vectors in body axes about the body's origin: motion
    (w, v), force (n, f); inertia blocks [[A, B], [B^T, C]] with n = A w + B v, f = B^T w + C v.
    A floating base (the root, S = 1) is solved by its 6 x 6 articulated inertia
    (tree_floating.py); its 6 numbers come first in v, tau and q_ddot. A ball joint or a free
    flyer below the root (S of 3 or 6 columns, constant in its body's axes) by its 3 x 3 or
    6 x 6 D = S^T IA S (tree_floating.several_articulated)."""
    placements = _kinematics(E, tree, q)
    nb = len(tree.joints)
    first, starts = tree.base_nv, _starts(tree)
    base_v, base_tau, v, tau = v[:first], tau[:first], v[first:], tau[first:]
    w, vel, c, A, B, C, pn, pf = [], [], [], [], [], [], [], []
    for i, joint in enumerate(tree.joints):
        R, p = placements[i]
        zero = [0.0] * 3
        if _free(joint):  # the base's own twist; S = 1 is constant, so no bias motion
            w_i, v_i = free_root_motion(base_v)
            c.append((zero, zero))
        elif several(joint):  # v_i = X v_parent + S v_j, c = v_i x S v_j (S constant)
            k = starts[i]
            ws, vs = several_rates(E, joint, v[k:k + joint_model(joint.kind).nv])
            wl, vl = ([0.0] * 3, [0.0] * 3) if joint.parent < 0 else (w[joint.parent],
                                                                     vel[joint.parent])
            w_i = E.vadd(E.apply_transpose(R, wl), ws)
            v_i = E.vadd(E.apply_transpose(R, E.vadd(vl, E.cross(wl, p))), vs)
            c.append((E.cross(w_i, ws), E.vadd(E.cross(w_i, vs), E.cross(v_i, ws))))
        else:
            s_w, s_v = joint_model(joint.kind).subspace(joint.axis, joint.pitch)
            rate = v[starts[i]]
            wl, vl = ([0.0] * 3, [0.0] * 3) if joint.parent < 0 else (w[joint.parent],
                                                                     vel[joint.parent])
            w_i = E.apply_transpose(R, wl)
            v_i = E.apply_transpose(R, E.vadd(vl, E.cross(wl, p)))
            if s_w is not None:
                w_i = E.vadd(w_i, E.scale(rate, s_w))
            if s_v is not None:
                v_i = E.vadd(v_i, E.scale(rate, s_v))
            # (w, v) x S q_dot = (w x s_w q_dot, w x s_v q_dot + v x s_w q_dot)
            cw = zero if s_w is None else E.cross(w_i, E.scale(rate, s_w))
            cv = E.vadd(zero if s_v is None else E.cross(w_i, E.scale(rate, s_v)),
                        zero if s_w is None else E.cross(v_i, E.scale(rate, s_w)))
            c.append((cw, cv))
        w.append(w_i)
        vel.append(v_i)
        m, h, J = joint.mass, list(joint.first_moment), [list(r) for r in joint.inertia]
        # the rigid body's inertia: A = J_O, B = [h]x, C = m 1
        A.append([row[:] for row in J])
        B.append([[0.0, E.neg(h[2]), h[1]], [h[2], 0.0, E.neg(h[0])],
                  [E.neg(h[1]), h[0], 0.0]])
        C.append([[m if r == k else 0.0 for k in range(3)] for r in range(3)])
        # bias force (w, v) x* (I (w, v)): n0 = J w + h x v, f0 = m v + w x h
        n0 = E.vadd(E.apply(J, w_i), E.cross(h, v_i))
        f0 = E.vadd(E.scale(m, v_i), E.cross(w_i, h))
        pn.append(E.vadd(E.cross(w_i, n0), E.cross(v_i, f0)))
        pf.append(E.cross(w_i, f0))
    U, D, uu = [None] * nb, [None] * nb, [None] * nb
    for i in reversed(range(nb)):
        joint = tree.joints[i]
        if _free(joint):  # the root: solved in the forward pass below
            continue
        if several(joint):
            k = starts[i]
            efforts = [E.add(tau[k + a], layout.actuators[k + a])
                       for a in range(joint_model(joint.kind).nv)]
            (U[i], D[i], uu[i]), (Aa, Ba, Ca, an, af) = several_articulated(
                E, joint, A[i], B[i], C[i], pn[i], pf[i], c[i], efforts)
            if joint.parent < 0:
                continue
            _into_parent(E, placements[i], joint.parent, A, B, C, pn, pf, Aa, Ba, Ca, an, af)
            continue
        s_w, s_v = joint_model(joint.kind).subspace(joint.axis, joint.pitch)
        zero = [0.0] * 3
        # U = IA S: Un = A s_w + B s_v, Uf = B^T s_w + C s_v
        Un = E.vadd(zero if s_w is None else E.apply(A[i], s_w),
                    zero if s_v is None else E.apply(B[i], s_v))
        Uf = E.vadd(zero if s_w is None else E.apply_transpose(B[i], s_w),
                    zero if s_v is None else E.apply(C[i], s_v))
        drive_n, drive_f = s_w or zero, s_v or zero
        U[i] = (Un, Uf)
        D[i] = E.add(E.dot(drive_n, Un), E.dot(drive_f, Uf))
        effort = E.add(tau[starts[i]], layout.actuators[starts[i]])
        uu[i] = E.sub(effort, E.add(E.dot(drive_n, pn[i]), E.dot(drive_f, pf[i])))
        parent = joint.parent
        if parent < 0:
            continue
        inv = E.div(1.0, D[i])
        Uns, Ufs = E.scale(inv, Un), E.scale(inv, Uf)
        # Ia = IA - U U^T / D, pa = pA + Ia c + U u / D
        Aa = [[E.sub(A[i][r][k], E.mul(Un[r], Uns[k])) for k in range(3)] for r in range(3)]
        Ba = [[E.sub(B[i][r][k], E.mul(Un[r], Ufs[k])) for k in range(3)] for r in range(3)]
        Ca = [[E.sub(C[i][r][k], E.mul(Uf[r], Ufs[k])) for k in range(3)] for r in range(3)]
        cw, cv = c[i]
        Bt = [[Ba[k][r] for k in range(3)] for r in range(3)]
        an = E.vadd(pn[i], E.vadd(E.vadd(E.apply(Aa, cw), E.apply(Ba, cv)), E.scale(uu[i], Uns)))
        af = E.vadd(pf[i], E.vadd(E.vadd(E.apply(Bt, cw), E.apply(Ca, cv)), E.scale(uu[i], Ufs)))
        _into_parent(E, placements[i], parent, A, B, C, pn, pf, Aa, Ba, Ca, an, af)
    up = [E.mul(layout.gravity, -d) for d in tree.gravity_direction]
    acc_w, acc_v = [None] * nb, [None] * nb
    qdd: list[Term] = [0.0] * layout.n
    for i, joint in enumerate(tree.joints):
        R, p = placements[i]
        if _free(joint):
            (acc_w[i], acc_v[i]), qdd[:first] = free_root_acceleration(
                E, R, A[i], B[i], C[i], pn[i], pf[i], base_tau, up)
            continue
        if joint.parent < 0:
            aw_l, av_l = [0.0] * 3, up
        else:
            aw_l, av_l = acc_w[joint.parent], acc_v[joint.parent]
        cw, cv = c[i]
        aw = E.vadd(E.apply_transpose(R, aw_l), cw)
        av = E.vadd(E.apply_transpose(R, E.vadd(av_l, E.cross(aw_l, p))), cv)
        if several(joint):
            x, acc_w[i], acc_v[i] = several_acceleration(E, joint, (U[i], D[i], uu[i]), aw, av)
            qdd[first + starts[i]:first + starts[i] + len(x)] = x
            continue
        Un, Uf = U[i]
        x = E.div(E.sub(uu[i], E.add(E.dot(Un, aw), E.dot(Uf, av))), D[i])
        qdd[first + starts[i]] = x
        s_w, s_v = joint_model(joint.kind).subspace(joint.axis, joint.pitch)
        if s_w is not None:
            aw = E.vadd(aw, E.scale(x, s_w))
        if s_v is not None:
            av = E.vadd(av, E.scale(x, s_v))
        acc_w[i], acc_v[i] = aw, av
    return qdd


def _into_parent(E: _Emitter, placement, parent: int, A, B, C, pn, pf, Aa, Ba, Ca, an, af):
    """Add a body's articulated inertia (Aa, Ba, Ca) and bias force (an, af) to its parent's:
    rotated into the parent's axes (R X R^T), then the reference point moved by p."""
    R, p = placement
    Ar, Br, Cr = _sandwich(E, R, Aa, True), _sandwich(E, R, Ba, False), _sandwich(E, R, Ca, True)
    P = [[0.0, E.neg(p[2]), p[1]], [p[2], 0.0, E.neg(p[0])], [E.neg(p[1]), p[0], 0.0]]
    K = E.matmul(P, Cr)  # [p]x C
    PBt = E.matmul(P, [[Br[k][r] for k in range(3)] for r in range(3)])  # [p]x B^T
    KP = E.matmul(K, P)
    for r in range(3):
        for k in range(r, 3):
            # A_P = A + [p]x B^T + ([p]x B^T)^T - [p]x C [p]x
            entry = E.add(Ar[r][k], E.sub(E.add(PBt[r][k], PBt[k][r]), KP[r][k]))
            A[parent][r][k] = E.add(A[parent][r][k], entry)
            if k != r:
                A[parent][k][r] = A[parent][r][k]
            C[parent][r][k] = E.add(C[parent][r][k], Cr[r][k])
            if k != r:
                C[parent][k][r] = C[parent][r][k]
    for r in range(3):
        for k in range(3):  # B_P = B + [p]x C
            B[parent][r][k] = E.add(B[parent][r][k], E.add(Br[r][k], K[r][k]))
    force = E.apply(R, af)
    pf[parent] = E.vadd(pf[parent], force)
    pn[parent] = E.vadd(pn[parent], E.vadd(E.apply(R, an), E.cross(p, force)))


def _sandwich(E: _Emitter, R, X, symmetric: bool):
    """R X R^T (only the upper triangle computed when X is symmetric)."""
    RX = E.matmul(R, X)
    out = [[None] * 3 for _ in range(3)]
    for r in range(3):
        for k in range(3):
            if symmetric and k < r:
                continue
            out[r][k] = E.dot(RX[r], R[k])
            if symmetric:
                out[k][r] = out[r][k]
    return out


def _velocities(E: _Emitter, tree: KinematicTree, q, v):
    placements = _kinematics(E, tree, q)
    w, vel = [], []
    base, v = v[:tree.base_nv], v[tree.base_nv:]
    starts = _starts(tree)
    for i, joint in enumerate(tree.joints):
        R, p = placements[i]
        if _free(joint):  # the base's own twist
            w.append(list(base[3:]))
            vel.append(list(base[:3]))
            continue
        wl, vl = ([0.0] * 3, [0.0] * 3) if joint.parent < 0 else (w[joint.parent],
                                                                 vel[joint.parent])
        w_i = E.apply_transpose(R, wl)
        v_i = E.apply_transpose(R, E.vadd(vl, E.cross(wl, p)))
        if several(joint):  # its own S v added, in its axes
            k = starts[i]
            ws, vs = several_rates(E, joint, v[k:k + joint_model(joint.kind).nv])
            w.append(E.vadd(w_i, ws))
            vel.append(E.vadd(v_i, vs))
            continue
        rate = E.mul(v[starts[i]], joint.multiplier)
        s_w, s_v = joint_model(joint.kind).subspace(joint.axis, joint.pitch)
        if s_w is not None:
            w_i = E.vadd(w_i, E.scale(rate, s_w))
        if s_v is not None:
            v_i = E.vadd(v_i, E.scale(rate, s_v))
        w.append(w_i)
        vel.append(v_i)
    return w, vel


def _kinetic_energy(E: _Emitter, tree: KinematicTree, q, v) -> Term:
    """T = sum 1/2 m v.v + v.(w x h) + 1/2 w.J_O w (J)."""
    w, vel = _velocities(E, tree, q, v)
    terms = []
    for joint, w_i, v_i in zip(tree.joints, w, vel, strict=True):
        twice = E.add(E.mul(joint.mass, E.dot(v_i, v_i)),
                      E.add(E.mul(2.0, E.dot(v_i, E.cross(w_i, list(joint.first_moment)))),
                            E.dot(w_i, E.apply([list(r) for r in joint.inertia], w_i))))
        terms.append(twice)
    return E.mul(E.sum(terms), 0.5)


def _potential_energy(E: _Emitter, tree: KinematicTree, layout: _Layout, q) -> Term:
    """V = g sum (m height of the origin + up.h), up in each body's axes (J)."""
    placements = _kinematics(E, tree, q)
    up_world = [-d + 0.0 for d in tree.gravity_direction]
    up, height, terms = [], [], []
    for i, joint in enumerate(tree.joints):
        R, p = placements[i]
        up_l, height_l = (up_world, 0.0) if joint.parent < 0 else (up[joint.parent],
                                                                   height[joint.parent])
        up.append(E.apply_transpose(R, up_l))
        height.append(E.add(height_l, E.dot(up_l, p)))
        terms.append(E.add(E.mul(joint.mass, height[i]), E.dot(up[i], list(joint.first_moment))))
    return E.mul(E.sum(terms), layout.gravity)



