"""Recursive rigid-body dynamics of a robot's kinematic tree (model/tree.py) as generated C.

Instead of expanding the equations of motion (whose size grows much faster than the number of
bodies), the generated code keeps the recursions over the tree, unrolled body by body with the
joint axes, placements and inertias as numbers (zeros and ones folded away, common terms
shared):

- inverse dynamics by recursive Newton-Euler: tau = M(q) a + C(q, q_dot) q_dot + g(q);
- the mass matrix by the composite-rigid-body algorithm;
- forward dynamics by the articulated-body algorithm, O(n), or M = L L^T, whichever takes
  fewer operations (Cholesky only with mimic joints);
- sin and cos of each joint angle once, by inline kernels (fdlibm's polynomials after a
  three-part reduction by pi/2, libm beyond |x| = 1e5): a libm call costs as much as the rest
  of the mass matrix of a 7-joint arm;
- kinetic energy 1/2 sum (m v.v + 2 v.(w x h) + w.J_O w), potential energy m g height.

Units SI. Gravity g (a runtime parameter) along the tree's direction; each coordinate's actuator
parameter tau_<joint> acts as a load, as in the symbolic equations (b = C q_dot + g - tau_p).
The same functions are written as standalone C99 (standalone.py) and, with the Python bindings
below and template.c, as a compiled module cached by compiled.py (a key of the tree's numbers,
taken before any code is generated).
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..compile.codegen import sincos_kernel
from ..errors import ModelError
from ..model.model import Model
from ..model.tree import KinematicTree
from ..model.values import resolve_parameters

Term = float | str  # a number, or the C name of a value computed before
VECTOR_LIMIT = 16  # coordinates up to which batches run several states per vector operation


class _Emitter:
    """Straight-line C with constants folded and equal operations computed once (value
    numbering): x*0, x*1, x+0 vanish, so a z axis or an identity placement costs nothing."""

    def __init__(self):
        self.lines: list[tuple[str, str, tuple[str, ...]]] = []
        self.memo: dict[tuple, str] = {}
        self.negated: dict[str, str] = {}  # name of -x -> name of x

    def _new(self, key: tuple, text: str, deps: tuple) -> str:
        hit = self.memo.get(key)
        if hit is not None:
            return hit
        name = f"t{len(self.lines)}"
        self.lines.append((name, text, tuple(d for d in deps if isinstance(d, str))))
        self.memo[key] = name
        return name

    @staticmethod
    def text(x: Term) -> str:
        if isinstance(x, str):
            return x
        return repr(float(x)) if x >= 0 else f"({float(x)!r})"

    def neg(self, a: Term) -> Term:
        if not isinstance(a, str):
            return -a + 0.0
        if a in self.negated:
            return self.negated[a]
        name = self._new(("-", a), f"-{a}", (a,))
        self.negated[name] = a
        return name

    def add(self, a: Term, b: Term) -> Term:
        if not isinstance(a, str) and not isinstance(b, str):
            return a + b
        if not isinstance(a, str) and a == 0:
            return b
        if not isinstance(b, str) and b == 0:
            return a
        if isinstance(b, str) and b in self.negated:
            return self.sub(a, self.negated[b])
        if isinstance(a, str) and a in self.negated:
            return self.sub(b, self.negated[a])
        x, y = sorted((a, b), key=repr)
        return self._new(("+", x, y), f"{self.text(x)} + {self.text(y)}", (x, y))

    def sub(self, a: Term, b: Term) -> Term:
        if not isinstance(a, str) and not isinstance(b, str):
            return a - b
        if not isinstance(b, str) and b == 0:
            return a
        if not isinstance(a, str) and a == 0:
            return self.neg(b)
        if a == b:
            return 0.0
        if isinstance(b, str) and b in self.negated:
            return self.add(a, self.negated[b])
        return self._new(("-", a, b), f"{self.text(a)} - {self.text(b)}", (a, b))

    def mul(self, a: Term, b: Term) -> Term:
        if not isinstance(a, str) and not isinstance(b, str):
            return a * b
        if not isinstance(a, str):
            a, b = b, a  # the constant second
        if not isinstance(b, str):
            if b == 0:
                return 0.0
            if b == 1:
                return a
            if b == -1:
                return self.neg(a)
            if a in self.negated:
                return self.mul(self.negated[a], -b)
            return self._new(("*", a, b), f"{a} * {self.text(b)}", (a,))
        if a in self.negated:
            return self.neg(self.mul(self.negated[a], b))
        if b in self.negated:
            return self.neg(self.mul(a, self.negated[b]))
        x, y = sorted((a, b))
        return self._new(("*", x, y), f"{x} * {y}", (x, y))

    def div(self, a: Term, b: Term) -> Term:
        if not isinstance(b, str):
            if b == 0:
                raise ZeroDivisionError("a joint moves nothing (massless subtree)")
            return self.mul(a, 1.0 / b)
        if not isinstance(a, str) and a == 0:
            return 0.0
        return self._new(("/", a, b), f"{self.text(a)} / {b}", (a, b))

    def sincos(self, a: Term) -> tuple[Term, Term]:
        """sin a and cos a from one lg_sincos call (the C preamble's inline kernels)."""
        if not isinstance(a, str):
            return float(np.sin(a)), float(np.cos(a))
        pair = self._new(("sincos", a), f"lg_sincos({a}, &@s, &@c)", (a,))
        names = []
        for part in "sc":
            name = f"{pair}{part}"
            if ("part", name) not in self.memo:
                self.lines.append((name, None, (pair,)))
                self.memo[("part", name)] = name
            names.append(name)
        return names[0], names[1]

    def call(self, function: str, a: Term) -> Term:
        if not isinstance(a, str):
            value = float(getattr(np, function)(a)) if function != "sqrt" or a >= 0 else np.nan
            if not np.isfinite(value):
                raise ZeroDivisionError(f"{function}({a})")
            return value
        return self._new((function, a), f"{function}({a})", (a,))

    # -- 3-vectors and 3x3 matrices of terms ----------------------------------------------------

    def sum(self, terms) -> Term:
        total: Term = 0.0
        for t in terms:
            total = self.add(total, t)
        return total

    def dot(self, a, b) -> Term:
        return self.sum(self.mul(x, y) for x, y in zip(a, b, strict=True))

    def vadd(self, a, b):
        return [self.add(x, y) for x, y in zip(a, b, strict=True)]

    def scale(self, s: Term, a):
        return [self.mul(s, x) for x in a]

    def cross(self, a, b):
        return [self.sub(self.mul(a[1], b[2]), self.mul(a[2], b[1])),
                self.sub(self.mul(a[2], b[0]), self.mul(a[0], b[2])),
                self.sub(self.mul(a[0], b[1]), self.mul(a[1], b[0]))]

    def apply(self, R, x):
        return [self.dot(row, x) for row in R]

    def apply_transpose(self, R, x):
        return [self.dot([R[0][i], R[1][i], R[2][i]], x) for i in range(3)]

    def matmul(self, A, B):
        return [[self.dot(A[i], [B[0][j], B[1][j], B[2][j]]) for j in range(3)]
                for i in range(3)]

    def count(self, outputs: list[tuple[str, Term]]) -> int:
        """How many operations ``body(outputs)`` performs (its statements)."""
        return self.body(outputs).count(";")

    def body(self, outputs: list[tuple[str, Term]], indent: str = "    ",
             vector: bool = False) -> str:
        """The C statements computing ``target = term`` for each output (dead temporaries
        dropped). ``vector``: values that depend on q, v, a or tau are lg_v4 (LG_LANES states),
        the others (parameters, numbers) stay double."""
        live = {t for _, t in outputs if isinstance(t, str)}
        keep = []
        for name, text, deps in reversed(self.lines):
            if name in live:
                keep.append((name, text, deps))
                live.update(deps)
        lanes: set[str] = set()
        statements = []
        for name, text, deps in reversed(keep):
            if vector and any(d in lanes or d.split("[")[0] in _STATE for d in deps):
                lanes.add(name)
            kind = "lg_v4" if name in lanes else "double"
            if text is None:  # one of a sincos pair, declared with it
                continue
            if text.startswith("lg_sincos("):
                call = "lg_vsincos(" if name in lanes else "lg_sincos("
                statements.append(f"{indent}{kind} {name}s, {name}c; "
                                  + text.replace("lg_sincos(", call).replace("@s", f"{name}s")
                                  .replace("@c", f"{name}c") + ";")
            elif vector and name in lanes:
                statements.append(f"{indent}const lg_v4 {name} = "
                                  + text.replace("sqrt(", "lg_vsqrt(") + ";")
            else:
                statements.append(f"{indent}const double {name} = {text};")
        for target, term in outputs:
            value = self.text(term)
            if vector and not (term in lanes or value.split("[")[0] in _STATE):
                value = f"LG_V4({value})"
            statements.append(f"{indent}{target} = {value};")
        return "\n".join(statements)


_STATE = {"q", "v", "a", "tau"}  # the inputs that differ between the states of one vector


class _Layout:
    """Where each input of the generated code lives: q[i], v[i], a[i], p[k]."""

    def __init__(self, tree: KinematicTree, parameters: tuple[str, ...]):
        self.tree = tree
        index = {name: k for k, name in enumerate(parameters)}
        missing = [name for name in (tree.gravity_parameter, *tree.actuators) if name not in index]
        if missing:
            raise ModelError(f"the tree's parameters {missing} are not the model's")
        self.gravity = f"p[{index[tree.gravity_parameter]}]"
        self.actuators = [f"p[{index[name]}]" for name in tree.actuators]
        self.n = len(tree.coordinates)


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


def _kinematics(E: _Emitter, tree: KinematicTree, q):
    """Each body's rotation R (body -> parent axes) and origin p (in its parent), as terms."""
    placements = []
    for joint in tree.joints:
        theta = E.add(E.mul(q[joint.coordinate], joint.multiplier), joint.offset)
        R0 = [list(row) for row in joint.rotation]
        if joint.kind == "revolute":
            sin, cos = E.sincos(theta)
            R = E.matmul(R0, _rotation(E, joint, cos, sin))
            p = list(joint.translation)
        else:
            R = R0
            p = E.vadd(joint.translation, E.scale(theta, E.apply(R0, joint.axis)))
        placements.append((R, p))
    return placements


def _inverse_dynamics(E: _Emitter, tree: KinematicTree, layout: _Layout, q, v, a):
    """Recursive Newton-Euler: the generalized forces tau_i (N m or N) for q, q_dot, q_ddot,
    minus each actuator parameter (the model's own load)."""
    placements = _kinematics(E, tree, q)
    g = layout.gravity
    up = [E.mul(g, -d) for d in tree.gravity_direction]  # the ground accelerates up by g
    w, dw, acc, f, n = [], [], [], [], []
    for i, joint in enumerate(tree.joints):
        R, p = placements[i]
        if joint.parent < 0:
            wl, dwl, al = [0.0] * 3, [0.0] * 3, up
        else:
            wl, dwl, al = w[joint.parent], dw[joint.parent], acc[joint.parent]
        u = list(joint.axis)
        rate = E.mul(v[joint.coordinate], joint.multiplier)
        accel = E.mul(a[joint.coordinate], joint.multiplier)
        w_in = E.apply_transpose(R, wl)
        dw_in = E.apply_transpose(R, dwl)
        origin = E.vadd(al, E.vadd(E.cross(dwl, p), E.cross(wl, E.cross(wl, p))))
        a_i = E.apply_transpose(R, origin)
        if joint.kind == "revolute":
            w_i = E.vadd(w_in, E.scale(rate, u))
            dw_i = E.vadd(dw_in, E.vadd(E.cross(w_in, E.scale(rate, u)), E.scale(accel, u)))
        else:
            w_i, dw_i = w_in, dw_in
            a_i = E.vadd(a_i, E.vadd(E.scale(2.0, E.cross(w_i, E.scale(rate, u))),
                                     E.scale(accel, u)))
        w.append(w_i)
        dw.append(dw_i)
        acc.append(a_i)
        m, h, J = joint.mass, list(joint.first_moment), [list(r) for r in joint.inertia]
        # about the body's origin: f = m a + dw x h + w x (w x h), n = J dw + w x J w + h x a
        f.append(E.vadd(E.scale(m, a_i), E.vadd(E.cross(dw_i, h), E.cross(w_i, E.cross(w_i, h)))))
        n.append(E.vadd(E.vadd(E.apply(J, dw_i), E.cross(w_i, E.apply(J, w_i))),
                        E.cross(h, a_i)))
    tau_full: list[Term] = [0.0] * len(tree.joints)
    for i in reversed(range(len(tree.joints))):
        joint = tree.joints[i]
        tau_full[i] = E.dot(joint.axis, n[i] if joint.kind == "revolute" else f[i])
        if joint.parent >= 0:
            R, p = placements[i]
            force = E.apply(R, f[i])
            f[joint.parent] = E.vadd(f[joint.parent], force)
            n[joint.parent] = E.vadd(n[joint.parent],
                                     E.vadd(E.apply(R, n[i]), E.cross(p, force)))
    tau: list[Term] = [0.0] * layout.n
    for i, joint in enumerate(tree.joints):
        tau[joint.coordinate] = E.add(tau[joint.coordinate], E.mul(tau_full[i], joint.multiplier))
    return [E.sub(t, actuator) for t, actuator in zip(tau, layout.actuators, strict=True)]


def _mass_matrix(E: _Emitter, tree: KinematicTree, layout: _Layout, q):
    """Composite-rigid-body algorithm: M (lower triangle, row-major entries i >= j)."""
    placements = _kinematics(E, tree, q)
    nb = len(tree.joints)
    mass = [j.mass for j in tree.joints]
    h = [list(j.first_moment) for j in tree.joints]
    J = [[list(r) for r in j.inertia] for j in tree.joints]
    full = {}
    for i in reversed(range(nb)):
        joint = tree.joints[i]
        u = list(joint.axis)
        if joint.kind == "revolute":  # unit rate about u: f = u x h, n = J u
            force, moment = E.cross(u, h[i]), E.apply(J[i], u)
        else:  # unit rate along u: f = m u, n = h x u
            force, moment = E.scale(mass[i], u), E.cross(h[i], u)
        full[i, i] = E.dot(u, moment if joint.kind == "revolute" else force)
        k = i
        while tree.joints[k].parent >= 0:
            R, p = placements[k]
            force = E.apply(R, force)
            moment = E.vadd(E.apply(R, moment), E.cross(p, force))
            k = tree.joints[k].parent
            ancestor = tree.joints[k]
            full[i, k] = E.dot(ancestor.axis, moment if ancestor.kind == "revolute" else force)
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
    entries = {}
    for (i, k), value in full.items():
        a, b = tree.joints[i], tree.joints[k]
        for (r, c, x) in ((a.coordinate, b.coordinate, value),) + (
                ((b.coordinate, a.coordinate, value),) if i != k else ()):
            if r >= c:
                entries[r, c] = E.add(entries.get((r, c), 0.0),
                                      E.mul(x, a.multiplier * b.multiplier))
    return entries


def _articulated(tree: KinematicTree) -> bool:
    """Whether the articulated-body algorithm applies: each coordinate drives one joint, as
    its angle or distance (no mimic joint)."""
    used = [j.coordinate for j in tree.joints]
    return len(set(used)) == len(used) and all(j.multiplier == 1.0 for j in tree.joints)


def _forward_dynamics(E: _Emitter, tree: KinematicTree, layout: _Layout, q, v, tau):
    """Articulated-body algorithm (Featherstone): q_ddot for q, q_dot and tau (on top of the
    actuator parameters), O(n). Spatial vectors in body axes about the body's origin: motion
    (w, v), force (n, f); inertia blocks [[A, B], [B^T, C]] with n = A w + B v, f = B^T w + C v."""
    placements = _kinematics(E, tree, q)
    nb = len(tree.joints)
    w, vel, c, A, B, C, pn, pf = [], [], [], [], [], [], [], []
    for i, joint in enumerate(tree.joints):
        R, p = placements[i]
        u = list(joint.axis)
        rate = v[joint.coordinate]
        wl, vl = ([0.0] * 3, [0.0] * 3) if joint.parent < 0 else (w[joint.parent],
                                                                 vel[joint.parent])
        w_i = E.apply_transpose(R, wl)
        v_i = E.apply_transpose(R, E.vadd(vl, E.cross(wl, p)))
        su = E.scale(rate, u)
        if joint.kind == "revolute":
            w_i = E.vadd(w_i, su)
            c.append((E.cross(w_i, su), E.cross(v_i, su)))  # (w, v) x S q_dot
        else:
            v_i = E.vadd(v_i, su)
            c.append(([0.0] * 3, E.cross(w_i, su)))
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
        u = list(joint.axis)
        if joint.kind == "revolute":  # U = IA S: the first column block times u
            Un = E.apply(A[i], u)
            Uf = E.apply_transpose(B[i], u)
            drive_n, drive_f = u, [0.0] * 3
        else:
            Un = E.apply(B[i], u)
            Uf = E.apply(C[i], u)
            drive_n, drive_f = [0.0] * 3, u
        U[i] = (Un, Uf)
        D[i] = E.add(E.dot(drive_n, Un), E.dot(drive_f, Uf))
        effort = E.add(tau[joint.coordinate], layout.actuators[joint.coordinate])
        uu[i] = E.sub(effort, E.add(E.dot(drive_n, pn[i]), E.dot(drive_f, pf[i])))
        parent = joint.parent
        if parent < 0:
            continue
        R, p = placements[i]
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
        # into the parent: rotate (R X R^T), then move the reference point by p
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
    up = [E.mul(layout.gravity, -d) for d in tree.gravity_direction]
    acc_w, acc_v = [None] * nb, [None] * nb
    qdd: list[Term] = [0.0] * layout.n
    for i, joint in enumerate(tree.joints):
        R, p = placements[i]
        if joint.parent < 0:
            aw_l, av_l = [0.0] * 3, up
        else:
            aw_l, av_l = acc_w[joint.parent], acc_v[joint.parent]
        cw, cv = c[i]
        aw = E.vadd(E.apply_transpose(R, aw_l), cw)
        av = E.vadd(E.apply_transpose(R, E.vadd(av_l, E.cross(aw_l, p))), cv)
        Un, Uf = U[i]
        x = E.div(E.sub(uu[i], E.add(E.dot(Un, aw), E.dot(Uf, av))), D[i])
        qdd[joint.coordinate] = x
        if joint.kind == "revolute":
            aw = E.vadd(aw, E.scale(x, joint.axis))
        else:
            av = E.vadd(av, E.scale(x, joint.axis))
        acc_w[i], acc_v[i] = aw, av
    return qdd


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
    for i, joint in enumerate(tree.joints):
        R, p = placements[i]
        wl, vl = ([0.0] * 3, [0.0] * 3) if joint.parent < 0 else (w[joint.parent],
                                                                 vel[joint.parent])
        rate = E.mul(v[joint.coordinate], joint.multiplier)
        w_i = E.apply_transpose(R, wl)
        v_i = E.apply_transpose(R, E.vadd(vl, E.cross(wl, p)))
        if joint.kind == "revolute":
            w_i = E.vadd(w_i, E.scale(rate, joint.axis))
        else:
            v_i = E.vadd(v_i, E.scale(rate, joint.axis))
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


def _inputs(name: str, n: int) -> list[str]:
    return [f"{name}[{i}]" for i in range(n)]


_SINCOS = r"""
/* sin and cos of x (fdlibm's kernels on [-pi/4, pi/4] after a three-part reduction by pi/2;
   libm beyond |x| = 1e5 and for NaN): within an ulp or two, no library call. */
static inline void lg_sincos(double x, double *sine, double *cosine)
{
    if (!(fabs(x) < 1.0e5)) { *sine = sin(x); *cosine = cos(x); return; }
""" + sincos_kernel("double") + r"""
    const double turn[4] = {s, c, -s, -c};
    const long k = (long)n;
    *sine = turn[k & 3];
    *cosine = turn[(k + 1) & 3];
}
"""


def dynamics_functions(tree: KinematicTree, parameters: tuple[str, ...], prefix: str,
                       storage: str = "static ", vector: bool = False) -> str:
    """C99 functions <prefix>_mass_matrix, _bias_forces, _gravity, _inverse_dynamics,
    _forward_dynamics, _kinetic_energy, _potential_energy (the standalone API); with
    ``vector``, also <prefix>4_<name> on LG_LANES states at once (GCC/Clang vector extensions, for
    the compiled module's batches)."""
    layout = _Layout(tree, parameters)
    n = layout.n
    q, v, a = _inputs("q", n), _inputs("v", n), _inputs("a", n)
    zeros = [0.0] * n
    P, S = prefix, storage
    R = "const double *restrict"
    sections = [_SINCOS]
    straight = []  # (name, inputs, emitter, [(output index, term)]) for the vector variants

    def function(signature: str, E: _Emitter, outputs, extra: str = "") -> None:
        sections.append(f"{S}{signature}\n{{\n    (void)p;\n{E.body(outputs)}\n{extra}}}\n")

    E = _Emitter()
    entries = _mass_matrix(E, tree, layout, q)
    outputs = []
    for r in range(n):
        for c in range(r + 1):
            outputs.append((r * n + c, entries.get((r, c), 0.0)))
    mirror = "".join(f"    M[{c * n + r}] = M[{r * n + c}];\n"
                     for r in range(n) for c in range(r))
    function(f"void {P}_mass_matrix({R} q, {R} p, double *restrict M)", E,
             [(f"M[{k}]", t) for k, t in outputs], mirror)
    straight.append(("mass_matrix", ("q",), E, outputs))
    for name, args, rates, accels, inputs in (
            ("inverse_dynamics", f"{R} q, {R} v, {R} a, {R} p, double *restrict tau", v, a,
             ("q", "v", "a")),
            ("bias_forces", f"{R} q, {R} v, {R} p, double *restrict tau", v, zeros, ("q", "v")),
            ("gravity", f"{R} q, {R} p, double *restrict tau", zeros, zeros, ("q",))):
        E = _Emitter()
        tau = _inverse_dynamics(E, tree, layout, q, rates, accels)
        function(f"void {P}_{name}({args})", E, [(f"tau[{i}]", t) for i, t in enumerate(tau)])
        straight.append((name, inputs, E, list(enumerate(tau))))
    E = _Emitter()
    T = _kinetic_energy(E, tree, q, v)
    function(f"double {P}_kinetic_energy({R} q, {R} v, {R} p)", E, [("double T", T)],
             "    return T;\n")
    straight.append(("kinetic_energy", ("q", "v"), E, [(0, T)]))
    E = _Emitter()
    V = _potential_energy(E, tree, layout, q)
    function(f"double {P}_potential_energy({R} q, {R} p)", E, [("double V", V)],
             "    return V;\n")
    straight.append(("potential_energy", ("q",), E, [(0, V)]))
    # forward dynamics: the articulated-body algorithm or M = L L^T straight-line (M and b
    # sharing their kinematics), whichever takes fewer operations; loops for a big M
    candidates = []
    tau_in = _inputs("tau", n)
    if _articulated(tree):
        E = _Emitter()
        try:
            qdd = _forward_dynamics(E, tree, layout, q, v, tau_in)
            candidates.append((E.count([(f"qdd[{i}]", x) for i, x in enumerate(qdd)]), E, qdd))
        except ZeroDivisionError:  # a joint that moves no mass: singular at every state
            pass
    if n <= 24:
        E = _Emitter()
        try:
            mass = _mass_matrix(E, tree, layout, q)
            bias = _inverse_dynamics(E, tree, layout, q, v, zeros)
            qdd = _cholesky_solve(E, mass, [E.sub(t, b) for t, b in zip(tau_in, bias, strict=True)])
            candidates.append((E.count([(f"qdd[{i}]", x) for i, x in enumerate(qdd)]), E, qdd))
        except ZeroDivisionError:
            pass
    qdd = None
    if candidates:
        _, E, qdd = min(candidates, key=lambda c: c[0])
    if qdd is not None:
        check = "".join(f"    if (!isfinite(qdd[{i}])) return -1;\n" for i in range(n))
        function(f"int {P}_forward_dynamics({R} q, {R} v, {R} tau, {R} p, double *restrict qdd)",
                 E, [(f"qdd[{i}]", x) for i, x in enumerate(qdd)], check + "    return 0;\n")
        straight.append(("forward_dynamics", ("q", "v", "tau"), E, list(enumerate(qdd))))
    else:
        sections.append(_cholesky_forward(P, S, R, n))
    if vector:
        sections.append(_VECTOR)
        for name, inputs, E, outs in straight:
            body = E.body([(f"out[{k}]", t) for k, t in outs], vector=True)
            if name == "mass_matrix":
                body += "\n" + "".join(f"    out[{c * n + r}] = out[{r * n + c}];\n"
                                        for r in range(n) for c in range(r))
            args = ", ".join(f"const lg_v4 *restrict {x}" for x in inputs)
            sections.append(f"static void {P}4_{name}({args}, {R} p, lg_v4 *restrict out)\n"
                            f"{{\n    (void)p;\n{body}\n}}\n")
    return "\n".join(sections)


_VECTOR = r"""
/* Several states at once, each operation on all lanes: four with AVX (a native build, see
   compiled.NATIVE_CFLAGS), else two (one SSE2 instruction; wider vectors without AVX are split
   through memory by the compiler, slower than scalar code). */
#if defined(__AVX__)
#define LG_LANES 4
typedef double lg_v4 __attribute__((vector_size(32)));
#else
#define LG_LANES 2
typedef double lg_v4 __attribute__((vector_size(16)));
#endif
#define LG_V4(x) ((lg_v4){0.0} + (x))
typedef unsigned long long lg_u4 __attribute__((vector_size(sizeof(lg_v4))));

static inline lg_v4 lg_vsqrt(lg_v4 x)
{
    lg_v4 r;
    for (int l = 0; l < LG_LANES; l++) r[l] = sqrt(x[l]);
    return r;
}

static inline void lg_vsincos(lg_v4 x, lg_v4 *sine, lg_v4 *cosine)
{
    int reducible = 1;
    for (int l = 0; l < LG_LANES; l++) reducible &= fabs(x[l]) < 1.0e5;
    if (!reducible) {
        for (int l = 0; l < LG_LANES; l++) {
            double s, c;
            lg_sincos(x[l], &s, &c);
            (*sine)[l] = s;
            (*cosine)[l] = c;
        }
        return;
    }
""" + sincos_kernel("lg_v4") + r"""
    /* the quadrant k = n mod 4 picks (s, c, -s, -c) by bit operations on all lanes at once:
       odd k swaps sine and cosine, bit 2 of k (of k + 1 for the cosine) flips the sign */
    const lg_u4 k = (lg_u4)shifted;
    const lg_u4 odd = -(k & 1), si = (lg_u4)s, ci = (lg_u4)c;
    *sine = (lg_v4)(((odd & ci) | (~odd & si)) ^ ((k & 2) << 62));
    *cosine = (lg_v4)(((odd & si) | (~odd & ci)) ^ (((k + 1) & 2) << 62));
}
"""


def _cholesky_solve(E: _Emitter, mass: dict, rhs: list) -> list:
    """x with M x = rhs by M = L L^T, straight-line (zeros of M, e.g. between two branches of
    the tree, fold away); M given by its lower triangle."""
    n = len(rhs)
    L: dict = {}
    inverse = []
    for j in range(n):
        d = E.sub(mass.get((j, j), 0.0), E.sum(E.mul(L[j, k], L[j, k]) for k in range(j)))
        inverse.append(E.div(1.0, E.call("sqrt", d)))
        for i in range(j + 1, n):
            e = E.sub(mass.get((i, j), 0.0), E.sum(E.mul(L[i, k], L[j, k]) for k in range(j)))
            L[i, j] = E.mul(e, inverse[j])
        L[j, j] = E.div(1.0, inverse[j])
    y = []
    for i in range(n):
        y.append(E.mul(E.sub(rhs[i], E.sum(E.mul(L[i, k], y[k]) for k in range(i))), inverse[i]))
    x = [0.0] * n
    for i in reversed(range(n)):
        x[i] = E.mul(E.sub(y[i], E.sum(E.mul(L[k, i], x[k]) for k in range(i + 1, n))),
                     inverse[i])
    return x


def _cholesky_forward(P: str, S: str, R: str, n: int) -> str:
    """Forward dynamics by Cholesky of M (a tree with mimic joints)."""
    return f"""/* q_ddot = M^-1 (tau - b): Cholesky M = L L^T on the stack; -1 where M is not
   positive definite (a massless branch), else 0. */
{S}int {P}_forward_dynamics({R} q, {R} v, {R} tau, {R} p, double *restrict qdd)
{{
    double L[{n * n}], b[{n}];
    {P}_mass_matrix(q, p, L);
    {P}_bias_forces(q, v, p, b);
    for (int i = 0; i < {n}; i++) qdd[i] = tau[i] - b[i];
    for (int j = 0; j < {n}; j++) {{
        double d = L[j * {n} + j];
        for (int k = 0; k < j; k++) d -= L[j * {n} + k] * L[j * {n} + k];
        if (!(d > 0.0)) return -1;
        d = sqrt(d);
        L[j * {n} + j] = d;
        const double inv = 1.0 / d;
        for (int i = j + 1; i < {n}; i++) {{
            double s = L[i * {n} + j];
            for (int k = 0; k < j; k++) s -= L[i * {n} + k] * L[j * {n} + k];
            L[i * {n} + j] = s * inv;
        }}
    }}
    for (int i = 0; i < {n}; i++) {{
        double s = qdd[i];
        for (int k = 0; k < i; k++) s -= L[i * {n} + k] * qdd[k];
        qdd[i] = s / L[i * {n} + i];
    }}
    for (int i = {n} - 1; i >= 0; i--) {{
        double s = qdd[i];
        for (int k = i + 1; k < {n}; k++) s -= L[k * {n} + i] * qdd[k];
        qdd[i] = s / L[i * {n} + i];
    }}
    return 0;
}}
"""


# -- the compiled module ---------------------------------------------------------------------------

_BINDINGS = r"""
/* ---- batched bindings: each input (..., N) or (N,), outputs shaped like the largest ---- */
enum { RT_MASS, RT_BIAS, RT_GRAVITY, RT_INVERSE, RT_FORWARD, RT_KINETIC, RT_POTENTIAL };
static const char *rt_names[] = {"q", "v", "third"};
#if defined(__unix__) || defined(__APPLE__)
#define RT_PTHREADS 1
#include <pthread.h>
#include <unistd.h>
#else
#define RT_PTHREADS 0
#endif
#define RT_MAX_THREADS 8
#define RT_THREAD_STATES 1024
#ifndef LG_LANES
#define LG_LANES 1
#endif

typedef struct {
    int kind, nin, size;
    npy_intp step[3];
    const double *x0, *x1, *x2, *p;
    double *y;
    npy_intp k0, k1, failed;
} rt_job;

static void *rt_run(void *argument)
{
    rt_job *job = (rt_job *)argument;
    const int kind = job->kind, nin = job->nin, size = job->size;
    const npy_intp *step = job->step;
    const double *x0 = job->x0, *x1 = job->x1, *x2 = job->x2, *p = job->p;
    double *y = job->y;
    npy_intp failed = -1, count = job->k1, k = job->k0;
    (void)nin; (void)size;
#if RT_VECTOR
    /* LG_LANES states at a time through the vector variants, the rest one by one */
    for (; k + LG_LANES <= count && (kind != RT_FORWARD || RT_VECTOR_FORWARD); k += LG_LANES) {
        lg_v4 in[3][LG_N], out4[LG_N * LG_N];
        for (int j = 0; j < nin; j++) {
            const double *x = j == 0 ? x0 : j == 1 ? x1 : x2;
            for (int l = 0; l < LG_LANES; l++)
                for (int i = 0; i < LG_N; i++) in[j][i][l] = x[(k + l) * step[j] + i];
        }
        switch (kind) {
        case RT_MASS: rt4_mass_matrix(in[0], p, out4); break;
        case RT_BIAS: rt4_bias_forces(in[0], in[1], p, out4); break;
        case RT_GRAVITY: rt4_gravity(in[0], p, out4); break;
        case RT_INVERSE: rt4_inverse_dynamics(in[0], in[1], in[2], p, out4); break;
#if RT_VECTOR_FORWARD
        case RT_FORWARD: rt4_forward_dynamics(in[0], in[1], in[2], p, out4); break;
#endif
        case RT_KINETIC: rt4_kinetic_energy(in[0], in[1], p, out4); break;
        case RT_POTENTIAL: rt4_potential_energy(in[0], p, out4); break;
        }
        for (int l = 0; l < LG_LANES; l++)
            for (int i = 0; i < size; i++) {
                const double x = out4[i][l];
                y[(k + l) * size + i] = x;
                if (kind == RT_FORWARD && !isfinite(x) && failed < 0) failed = k + l;
            }
    }
#endif
    for (; k < count; k++) {
        const double *a0 = x0 + k * step[0], *a1 = x1 + k * step[1], *a2 = x2 + k * step[2];
        switch (kind) {
        case RT_MASS: rt_mass_matrix(a0, p, y + k * LG_N * LG_N); break;
        case RT_BIAS: rt_bias_forces(a0, a1, p, y + k * LG_N); break;
        case RT_GRAVITY: rt_gravity(a0, p, y + k * LG_N); break;
        case RT_INVERSE: rt_inverse_dynamics(a0, a1, a2, p, y + k * LG_N); break;
        case RT_FORWARD:
            if (rt_forward_dynamics(a0, a1, a2, p, y + k * LG_N) && failed < 0) failed = k;
            break;
        case RT_KINETIC: y[k] = rt_kinetic_energy(a0, a1, p); break;
        case RT_POTENTIAL: y[k] = rt_potential_energy(a0, p); break;
        }
    }
    job->failed = failed;
    return NULL;
}

/* How many threads a batch of ``count`` states runs on: one per processor (at most
   RT_MAX_THREADS) once each has RT_THREAD_STATES states; LAGRANGIAN_THREADS caps it. */
static int rt_threads(npy_intp count)
{
#if RT_PTHREADS
    static int cap = 0;
    if (cap == 0) {
        long cpus = sysconf(_SC_NPROCESSORS_ONLN);
        const char *env = getenv("LAGRANGIAN_THREADS");
        long asked = env && *env ? strtol(env, NULL, 10) : cpus;
        if (asked < 1) asked = 1;
        if (cpus < 1) cpus = 1;
        cap = (int)(asked < cpus ? asked : cpus);
        if (cap > RT_MAX_THREADS) cap = RT_MAX_THREADS;
    }
    npy_intp parts = count / RT_THREAD_STATES;
    if (parts > cap) parts = cap;
    return parts < 1 ? 1 : (int)parts;
#else
    (void)count;
    return 1;
#endif
}

static PyObject *rt_batch(PyObject *const *args, Py_ssize_t nargs, int nin, int kind)
{
    PyArrayObject *in[3] = {NULL, NULL, NULL}, *P = NULL;
    PyObject *out = NULL;
    npy_intp step[3] = {0, 0, 0};
    if (nargs != nin + 1) {
        PyErr_Format(PyExc_TypeError, "expected %d arguments", nin + 1);
        return NULL;
    }
    int base = 0;
    for (int i = 0; i < nin; i++) {
        in[i] = (PyArrayObject *)PyArray_FROMANY(args[i], NPY_DOUBLE, 0, 0, NPY_ARRAY_CARRAY_RO);
        if (!in[i]) goto done;
        int nd = PyArray_NDIM(in[i]);
        if (nd == 0 || PyArray_DIMS(in[i])[nd - 1] != LG_N) {
            PyErr_Format(PyExc_ValueError, "%s: expected %d values along the last axis",
                         i == 2 ? (kind == RT_FORWARD ? "tau" : "a") : rt_names[i], LG_N);
            goto done;
        }
        if (PyArray_SIZE(in[i]) > PyArray_SIZE(in[base])) base = i;
    }
    npy_intp count = PyArray_SIZE(in[base]) / LG_N;
    int nd = PyArray_NDIM(in[base]);
    for (int i = 0; i < nin; i++) {
        if (PyArray_SIZE(in[i]) == LG_N && PyArray_NDIM(in[i]) == 1) {
            step[i] = count > 1 ? 0 : LG_N;
            continue;
        }
        if (PyArray_NDIM(in[i]) != nd
            || memcmp(PyArray_DIMS(in[i]), PyArray_DIMS(in[base]), nd * sizeof(npy_intp))) {
            PyErr_SetString(PyExc_ValueError, "the batch shapes of the inputs differ");
            goto done;
        }
        step[i] = LG_N;
    }
    P = lg_doubles(args[nin], LG_NP, "parameters");
    if (!P) goto done;
    npy_intp dims[NPY_MAXDIMS];
    memcpy(dims, PyArray_DIMS(in[base]), (nd - 1) * sizeof(npy_intp));
    int od = nd - 1;
    if (kind == RT_MASS) { dims[od++] = LG_N; dims[od++] = LG_N; }
    else if (kind != RT_KINETIC && kind != RT_POTENTIAL) dims[od++] = LG_N;
    out = PyArray_SimpleNew(od, dims, NPY_DOUBLE);
    if (!out) goto done;
    const double *x0 = (const double *)PyArray_DATA(in[0]);
    const double *x1 = nin > 1 ? (const double *)PyArray_DATA(in[1]) : NULL;
    const double *x2 = nin > 2 ? (const double *)PyArray_DATA(in[2]) : NULL;
    const double *p = (const double *)PyArray_DATA(P);
    double *y = (double *)PyArray_DATA((PyArrayObject *)out);
    const int size = kind == RT_MASS ? LG_N * LG_N
                     : (kind == RT_KINETIC || kind == RT_POTENTIAL) ? 1 : LG_N;
    rt_job jobs[RT_MAX_THREADS];
    int parts = rt_threads(count);
    npy_intp share = (count / parts + LG_LANES - 1) / LG_LANES * LG_LANES;
    for (int t = 0; t < parts; t++) {
        rt_job job = {kind, nin, size, {step[0], step[1], step[2]}, x0, x1, x2, p, y,
                      t * share < count ? t * share : count,
                      t == parts - 1 || (t + 1) * share > count ? count : (t + 1) * share, -1};
        jobs[t] = job;
    }
    npy_intp failed = -1;
    NPY_BEGIN_THREADS_DEF;
    if (count > 16) NPY_BEGIN_THREADS;
    /* the batch in parts on threads of their own (the functions keep no state), this thread
       taking the last part; a thread that cannot start leaves its part to this one */
#if RT_PTHREADS
    pthread_t threads[RT_MAX_THREADS];
    int started[RT_MAX_THREADS] = {0};
    for (int t = 0; t < parts - 1; t++)
        started[t] = pthread_create(&threads[t], NULL, rt_run, &jobs[t]) == 0;
    rt_run(&jobs[parts - 1]);
    for (int t = 0; t < parts - 1; t++) {
        if (started[t]) pthread_join(threads[t], NULL);
        else rt_run(&jobs[t]);
    }
#else
    for (int t = 0; t < parts; t++) rt_run(&jobs[t]);
#endif
    for (int t = 0; t < parts; t++)
        if (jobs[t].failed >= 0 && (failed < 0 || jobs[t].failed < failed)) failed = jobs[t].failed;
    if (count > 16) NPY_END_THREADS;
    if (failed >= 0) {
        PyErr_Format(lg_LinAlgError, "the mass matrix is not positive definite (state %zd)",
                     (Py_ssize_t)failed);
        Py_CLEAR(out);
    }
done:
    for (int i = 0; i < 3; i++) Py_XDECREF(in[i]);
    Py_XDECREF(P);
    return out;
}

#define RT_WRAP(name, nin, kind) \
    static PyObject *rt_py_##name(PyObject *self, PyObject *const *args, Py_ssize_t nargs) \
    { (void)self; return rt_batch(args, nargs, nin, kind); }
RT_WRAP(mass_matrix, 1, RT_MASS)
RT_WRAP(bias_forces, 2, RT_BIAS)
RT_WRAP(gravity, 1, RT_GRAVITY)
RT_WRAP(inverse_dynamics, 3, RT_INVERSE)
RT_WRAP(forward_dynamics, 3, RT_FORWARD)
RT_WRAP(kinetic_energy, 2, RT_KINETIC)
RT_WRAP(potential_energy, 1, RT_POTENTIAL)
"""

_DECLARE = "\n".join(
    f"static PyObject *rt_py_{name}(PyObject *, PyObject *const *, Py_ssize_t);"
    for name in ("mass_matrix", "bias_forces", "gravity", "inverse_dynamics", "forward_dynamics",
                 "kinetic_energy", "potential_energy"))

_METHODS = " ".join(
    f'{{"{name}", (PyCFunction)(void (*)(void))rt_py_{name}, METH_FASTCALL, "{doc}"}},'
    for name, doc in (("mass_matrix", "(Q, P) -> M"), ("bias_forces", "(Q, V, P) -> b"),
                      ("gravity", "(Q, P) -> g"), ("inverse_dynamics", "(Q, V, A, P) -> tau"),
                      ("forward_dynamics", "(Q, V, TAU, P) -> q_ddot"),
                      ("kinetic_energy", "(Q, V, P) -> T"), ("potential_energy", "(Q, P) -> V")))


def module_source(tree: KinematicTree, parameters: tuple[str, ...]):
    """The compiled module's C: the recursive functions, lg_parts/lg_energy/lg_residual for
    template.c (simulation, accelerations), and batched bindings for each function."""
    from ..compile.codegen import TEMPLATE, GeneratedSource

    n = len(tree.coordinates)
    # two-state vector variants for batches of arms; a long chain's code is big enough that
    # compiling it twice costs minutes, so there the batch runs the scalar functions
    functions = dynamics_functions(tree, parameters, "rt", vector=n <= VECTOR_LIMIT)
    source = "\n".join([
        f"/* lagrangian: recursive dynamics of a tree of {len(tree.joints)} bodies, {n} "
        "coordinates */",
        f"#define LG_N {n}",
        "#define LG_M 0",
        f"#define LG_NP {len(parameters)}",
        "#define PY_SSIZE_T_CLEAN",
        "#include <Python.h>",
        "#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION",
        "#include <numpy/arrayobject.h>",
        "#include <math.h>",
        "",
        functions,
        """
static void lg_parts(const double *restrict q, const double *restrict v, double t,
                     const double *restrict p, double *restrict M, double *restrict f,
                     double *restrict J, double *restrict g)
{
    (void)t; (void)J; (void)g;
    rt_mass_matrix(q, p, M);
    rt_bias_forces(q, v, p, f);
    for (int i = 0; i < LG_N; i++) f[i] = -f[i];
}

static double lg_energy(const double *restrict q, const double *restrict v, double t,
                        const double *restrict p)
{
    (void)t;
    return rt_kinetic_energy(q, v, p) + rt_potential_energy(q, p);
}

static void lg_residual(const double *restrict q, const double *restrict v, double t,
                        const double *restrict p, double *restrict r)
{
    (void)q; (void)v; (void)t; (void)p; (void)r;
}
""",
        _DECLARE,
        f"#define LG_EXTRA_METHODS {_METHODS}",
        "#define RT_VECTOR_FORWARD " + ("1" if "rt4_forward_dynamics" in functions else "0"),
        "#define RT_VECTOR " + ("1" if "rt4_mass_matrix" in functions else "0"),
        TEMPLATE.read_text(),
        _BINDINGS,
    ])
    return GeneratedSource(source=source, parameters=parameters, n=n, m=0)


@lru_cache(maxsize=1)
def _generator_key() -> str:
    return hashlib.sha256(Path(__file__).read_bytes()).hexdigest()


def tree_key(tree: KinematicTree, parameters: tuple[str, ...]) -> str:
    """What the generated module is a function of: the tree's numbers (exact reprs) and the
    parameters' order, and this generator."""
    return "\n".join(["recursive", _generator_key(), repr(parameters), repr(tree)])


def applicable_tree(model: Model) -> KinematicTree | None:
    """The model's kinematic tree when it describes the model's whole dynamics (a robot read
    from URDF and not edited since: only its rigid bodies, gravity and the actuator forces),
    else None, so that nothing else a model holds is ever left out."""
    tree = model.kinematic_tree
    if tree is None:
        return None
    if (model.particles or model.bodies or model.springs or model.dampers or model.loads
            or model.constraints or model.definitions
            or model.kinetic_energy != 0 or model.potential_energy != 0
            or model.dissipation != 0):
        return None
    if model.rigid_bodies != tree.rigid_bodies:
        return None
    if tuple(c.name for c in model.coordinates) != tree.coordinates:
        return None
    names = {p.name: p.symbol for p in model.parameters}
    if tree.gravity_parameter not in names or any(a not in names for a in tree.actuators):
        return None
    gravity = model.gravity
    if gravity is None or gravity.magnitude != names[tree.gravity_parameter] or \
            tuple(float(d) for d in gravity.direction) != tree.gravity_direction:
        return None
    expected = {c: ((names[a]),) for c, a in zip(tree.coordinates, tree.actuators, strict=True)}
    given: dict[str, tuple] = {}
    for coordinate, force in model.generalized_forces:
        given[coordinate] = given.get(coordinate, ()) + (force,)
    if given != expected:
        return None
    return tree


class RecursiveDynamics:
    """Compiled recursive dynamics of a tree, batched over leading axes (SI units).

    Every input is (..., n) (or (n,), broadcast against the others); outputs keep the batch
    shape. ``functions`` (lazy) is the NumericSystem over the same module (simulation).
    """

    backend = "recursive"

    def __init__(self, model: Model, tree: KinematicTree,
                 parameters: Mapping[str, float] | None = None):
        from ..compile import compiled

        names = tuple(p.name for p in model.parameters)
        values = resolve_parameters(model, parameters)
        self.model = model
        self.tree = tree
        self.coordinates = tree.coordinates
        self.n = len(tree.coordinates)
        self.parameters = {name: float(v) for name, v in zip(names, values.values, strict=True)}
        self.parameter_values = np.array(list(self.parameters.values()), dtype=float)
        self.parameter_values.flags.writeable = False
        self.module = compiled.load_keyed(tree_key(tree, names),
                                          lambda: module_source(tree, names), native=True)
        P = self.parameter_values
        m = self.module
        # The fast path: one C call each, the parameters bound here.
        self._mass, self._bias, self._gravity = m.mass_matrix, m.bias_forces, m.gravity
        self._inverse, self._forward = m.inverse_dynamics, m.forward_dynamics
        self._kinetic, self._potential = m.kinetic_energy, m.potential_energy
        self._P = P

    def regular(self) -> bool:
        """Whether M is positive definite at a few random states (a massless branch is not)."""
        rng = np.random.default_rng(0)
        try:
            np.linalg.cholesky(self.mass_matrix(rng.uniform(-np.pi, np.pi, (3, self.n))))
        except np.linalg.LinAlgError:
            return False
        return True

    def numeric_system(self):
        """The NumericSystem over this module (M, f = -b, energy, accelerations, rhs), as the
        symbolic path gives it; simulation uses it."""
        from ..compile.functions import CKernel, NumericSystem

        return NumericSystem(coordinates=self.coordinates, constraint_names=(),
                             constraint_kinds=(), parameters=dict(self.parameters),
                             _kernel=CKernel(self.module, self.parameter_values))

    def __repr__(self) -> str:
        return f"RecursiveDynamics(coordinates={list(self.coordinates)})"

    def _call(self, function, *arrays):
        try:
            return function(*arrays, self._P)
        except np.linalg.LinAlgError:
            raise
        except ValueError as exc:
            if "batch shapes" in str(exc):  # broadcast in numpy, then one C call
                arrays = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in arrays))
                return function(*(np.ascontiguousarray(x) for x in arrays), self._P)
            field = str(exc).split(":")[0]
            raise ModelError(f"expected {self.n} values ({', '.join(self.coordinates)}) "
                             "along the last axis", field=field) from None

    def mass_matrix(self, q):
        """M(q), shape (..., n, n)."""
        try:
            return self._mass(q, self._P)
        except ValueError:
            return self._call(self._mass, q)

    def bias_forces(self, q, v):
        """C(q, q_dot) q_dot + g(q), shape (..., n)."""
        try:
            return self._bias(q, v, self._P)
        except ValueError:
            return self._call(self._bias, q, v)

    def gravity(self, q):
        """g(q), shape (..., n)."""
        try:
            return self._gravity(q, self._P)
        except ValueError:
            return self._call(self._gravity, q)

    def inverse_dynamics(self, q, v, a):
        """tau = M a + C q_dot + g, shape (..., n)."""
        try:
            return self._inverse(q, v, a, self._P)
        except ValueError:
            return self._call(self._inverse, q, v, a)

    def forward_dynamics(self, q, v, tau):
        """q_ddot = M^-1 (tau - C q_dot - g), shape (..., n)."""
        try:
            return self._forward(q, v, tau, self._P)
        except ValueError:
            return self._call(self._forward, q, v, tau)

    def kinetic_energy(self, q, v):
        """T in J, shape (...)."""
        try:
            return self._kinetic(q, v, self._P)
        except ValueError:
            return self._call(self._kinetic, q, v)

    def potential_energy(self, q):
        """V in J, shape (...)."""
        try:
            return self._potential(q, self._P)
        except ValueError:
            return self._call(self._potential, q)


__all__ = ["RecursiveDynamics", "applicable_tree", "dynamics_functions", "module_source",
           "tree_key"]
