/* The compact tree kernel: the recursions of tree_algorithms.py as loops over a tree given at
   run time as one array of doubles (its layout: tree/description.py and joint.h, which places
   each joint kind for this module, the reach and the derivatives modules), compiled once for
   every tree. Units SI. Each body i hangs from parent(i) < i (or the ground, -1) by one joint:
   R = R0 Rot(u, theta) (revolute, helical) or R0 (prismatic), p = t0 (+ R0 u lead theta: lead
   1 prismatic, the pitch helical), with theta = k q[c] + offset; R turns body axes into parent axes, p is the origin in the parent.
   A floating base (header flag) is body 0 on a free flyer (kind 2, free_flyer.py): q holds
   nq = 7 + n numbers (its position, quaternion x y z w, then the joints: q[7 + c]), v, a and
   tau nv = 6 + n (its twist in its own axes, linear then angular, then v[6 + c]). A ball joint
   (kind 4, spherical.py) turns its body by the unit quaternion q[QCOORD:QCOORD + 4] (w x y z,
   MuJoCo's), R = R0 R(q), p = t0, at the angular velocity v[COORD:COORD + 3] in the body's axes:
   a coordinate's place in q (QCOORD) and in v (COORD) then differ, and n counts v's. A free
   flyer below the root (kind 5) moves its body by q[QCOORD:QCOORD + 7] (x y z, quaternion x y
   z w) at the twist v[COORD:COORD + 6] (linear, angular) relative to its parent, in its axes. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
/* TK_SINCOS */

#include "spatial.h"
#include "joint.h"
/* a body's scratch */
#define TW_STRIDE 96
#define TW_R 0
#define TW_P 9
#define TW_A 12         /* 6-vectors and 6x6 matrices of the algorithms from here */
#define TW_CS 92        /* cos and sin of theta (1, 0 for a joint that does not turn) */
#define TW_SN 93

/* joint.h's and spatial.h's number type and names: the core's (TK_T, TK_FN) */
#define SP_T TK_T
#define JT_T TK_T
#define JT_FN(name) TK_FN(jt_##name)
#define JT_C(x) TK_C(x)
#define JT_SINCOS TK_SINCOS

/* the mass matrix's scratch per body: its rotation and origin in the world, its composite
   inertia about the world's origin (m, h, J_O's six), its joint's columns (s_v, s_w) there: up
   to six, to 70 (before TW_CS) */
enum { TW_RW = TW_A, TW_OW = TW_RW + 9, TW_IC = TW_OW + 3, TW_COLS = TW_IC + 10 };

/* the articulated-body algorithm's scratch per body after R, p: V 6, C 6, A 6, IA 36, PA 6, U 6,
   D, u; a ball's or a flyer's below the root D^-1 (its factor), u and U in its IA's place once
   its parent has its share (the backward pass reads a body's IA no more) */
enum { TA_V = TW_A, TA_C = TA_V + 6, TA_A = TA_C + 6, TA_IA = TA_A + 6, TA_PA = TA_IA + 36,
       TA_U = TA_PA + 6, TA_D = TA_U + 6, TA_UU = TA_D + 1 };

/* TK_CORE_BEGIN */
/* The recursions, emitted twice by compact_kernel.py: on one state (tk_*, TK_T double) and
   on LG_LANES states at once (tk4_*, TK_T lg_v4). TK_FN(name) names a function, TK_C(x) a
   number as a TK_T. Every branch depends on the tree alone, never on a state, so the lanes
   take one path and each lane's numbers are its state's single call's, bit for bit (the module
   is built without fused multiply-adds); a failed state (a matrix not positive definite) is
   marked in the functions' returned TK_BAD, its numbers left for the caller to blank. */

static inline void TK_FN(sandwich)(const TK_T *R, const TK_T *A, TK_T *out)  /* R A R^T */
{
    TK_T T[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            T[3 * i + j] = R[3 * i] * A[j] + R[3 * i + 1] * A[3 + j] + R[3 * i + 2] * A[6 + j];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[3 * i + j] = T[3 * i] * R[3 * j] + T[3 * i + 1] * R[3 * j + 1]
                             + T[3 * i + 2] * R[3 * j + 2];
}

/* JT_CORE: joint.h's core, here */

/* Each body's R and p for the configuration q (into the scratch W), and theta's cos, sin. */
static void TK_FN(place)(const tk_tree *t, const TK_T *restrict q, TK_T *restrict W)
{
#if TK_SCALAR
    /* on one state: every turning joint's theta first, then their sines and cosines LG_LANES
       at a time on the vector unit (the lanes' own function: the same numbers bit for bit) */
    const int nb = t->nb, chunks = (nb + LG_LANES - 1) / LG_LANES;
    lg_v4 theta[chunks], sine, cosine;
    for (int k = 0; k < chunks; k++) theta[k] = LG_V4(0.0);
    for (int i = 0; i < nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        if (TK_TURNS(b)) theta[i / LG_LANES][i % LG_LANES] = JT_FN(angle)(t, b, q);
    }
    for (int k = 0; k < chunks; k++) {
        lg_vsincos_inline(theta[k], &sine, &cosine);
        for (int l = 0; l < LG_LANES && k * LG_LANES + l < nb; l++) {
            TK_T *w = W + (k * LG_LANES + l) * TW_STRIDE;
            w[TW_CS] = cosine[l];
            w[TW_SN] = sine[l];
        }
    }
    for (int i = 0; i < nb; i++) {
        TK_T *w = W + i * TW_STRIDE;
        JT_FN(place_sines)(t, t->body + i * TK_STRIDE, q, w + TW_R, w + TW_P, w + TW_CS,
                           w + TW_SN, 1);
    }
#else
    for (int i = 0; i < t->nb; i++) {
        TK_T *w = W + i * TW_STRIDE;
        JT_FN(place)(t, t->body + i * TK_STRIDE, q, w + TW_R, w + TW_P, w + TW_CS, w + TW_SN);
    }
#endif
}

/* Recursive Newton-Euler: tau = M a + C v + g - tau0 (v, a NULL: zero), the bodies placed
   in W (TK_FN(place)) */
static void TK_FN(inverse_placed)(const tk_tree *t, const TK_T *restrict v,
                                  const TK_T *restrict a, TK_T *restrict W, TK_T *restrict tau)
{
    for (int i = 0; i < t->bv; i++) tau[i] = TK_C(0.0);
    for (int i = 0; i < t->n; i++) tau[t->bv + i] = TK_C(-t->tau0[i]);
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        TK_T *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P;
        TK_T *om = w + TW_A, *dom = om + 3, *acc = om + 6, *f = om + 9, *nn = om + 12;
        const int parent = (int)b[TK_PARENT], c = (int)b[TK_COORD];
        double sw, sv;
        TK_T x[3], y[3];
        tk_subspace(b, &sw, &sv);
        if (parent < 0) {
            const double up[3] = {-t->g[0], -t->g[1], -t->g[2]};  /* the ground accelerates up */
            for (int r = 0; r < 3; r++) om[r] = dom[r] = TK_C(0.0);
            SP_APPLY_T(R, up, acc);
            if (TK_FREE(b)) {  /* the origin's acceleration a_v + w x v_v, body axes */
                if (v) {
                    SP_CROSS(v + 3, v, x);
                    for (int r = 0; r < 3; r++) { om[r] = v[3 + r]; acc[r] += x[r]; }
                }
                if (a)
                    for (int r = 0; r < 3; r++) { dom[r] = a[3 + r]; acc[r] += a[r]; }
            }
        } else {
            const TK_T *pw = W + parent * TW_STRIDE + TW_A, *pdw = pw + 3, *pa = pw + 6;
            TK_T z[3];
            SP_APPLY_T(R, pw, om);
            SP_APPLY_T(R, pdw, dom);
            /* a_parent + dw x p + w x (w x p) */
            SP_CROSS(pdw, p, x);
            SP_CROSS(pw, p, y);
            SP_CROSS(pw, y, z);
            for (int r = 0; r < 3; r++) x[r] += pa[r] + z[r];
            SP_APPLY_T(R, x, acc);
        }
        if (TK_BALL(b)) {  /* w += w_rel, dw += w x w_rel + dw_rel (body axes) */
            if (v) {
                const TK_T *wr = v + t->bv + c;
                SP_CROSS(om, wr, x);
                for (int r = 0; r < 3; r++) { dom[r] += x[r]; om[r] += wr[r]; }
            }
            if (a)
                for (int r = 0; r < 3; r++) dom[r] += a[t->bv + c + r];
        } else if (TK_FLYER(b)) {  /* its twist (v_r, w_r) added, body axes */
            if (v) {  /* a += 2 w x v_r + w_r x v_r, dw += w x w_r, w += w_r */
                const TK_T *vr = v + t->bv + c, *wr = vr + 3;
                TK_T z[3];
                SP_CROSS(om, vr, x);
                SP_CROSS(wr, vr, y);
                SP_CROSS(om, wr, z);
                for (int r = 0; r < 3; r++) {
                    acc[r] += 2.0 * x[r] + y[r];
                    dom[r] += z[r];
                    om[r] += wr[r];
                }
            }
            if (a)
                for (int r = 0; r < 3; r++) {
                    acc[r] += a[t->bv + c + r];
                    dom[r] += a[t->bv + c + 3 + r];
                }
        } else if (v && !TK_FREE(b)) {  /* the joint's rate about z: w += S w, the Coriolis terms */
            const TK_T rate = v[t->bv + c], wz = rate * sw, vz = rate * sv;
            dom[0] += om[1] * wz;  /* w x (0, 0, wz) */
            dom[1] -= om[0] * wz;
            om[2] += wz;
            acc[0] += 2.0 * (om[1] * vz);
            acc[1] -= 2.0 * (om[0] * vz);
        }
        if (a && !TK_FREE(b) && !TK_BALL(b) && !TK_FLYER(b)) {
            const TK_T accel = a[t->bv + c];
            dom[2] += accel * sw;
            acc[2] += accel * sv;
        }
        /* f = m a + dw x h + w x (w x h), n = J dw + w x J w + h x a (about the origin) */
        const double m = b[TK_MASS], *h = b + TK_H, *J = b + TK_J;
        TK_T wh[3], z[3];
        SP_CROSS(dom, h, x);
        SP_CROSS(om, h, wh);
        SP_CROSS(om, wh, z);
        for (int r = 0; r < 3; r++) f[r] = m * acc[r] + x[r] + z[r];
        SP_APPLY(J, dom, nn);
        SP_APPLY(J, om, y);
        SP_CROSS(om, y, x);
        SP_CROSS(h, acc, z);
        for (int r = 0; r < 3; r++) nn[r] += x[r] + z[r];
    }
    for (int i = t->nb - 1; i >= 0; i--) {
        const double *b = t->body + i * TK_STRIDE;
        TK_T *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P;
        TK_T *f = w + TW_A + 9, *nn = w + TW_A + 12;
        double sw, sv;
        if (TK_FREE(b)) {  /* the base's wrench in its axes, force then moment */
            for (int r = 0; r < 3; r++) { tau[r] += f[r]; tau[3 + r] += nn[r]; }
            continue;
        }
        if (TK_BALL(b)) {  /* the moment on the body about its joint, its axes */
            for (int r = 0; r < 3; r++) tau[t->bv + (int)b[TK_COORD] + r] += nn[r];
        } else if (TK_FLYER(b)) {  /* the wrench on the body, force then moment, its axes */
            for (int r = 0; r < 3; r++) {
                tau[t->bv + (int)b[TK_COORD] + r] += f[r];
                tau[t->bv + (int)b[TK_COORD] + 3 + r] += nn[r];
            }
        } else {
            tk_subspace(b, &sw, &sv);
            tau[t->bv + (int)b[TK_COORD]] += sw * nn[2] + sv * f[2];
        }
        const int parent = (int)b[TK_PARENT];
        if (parent >= 0) {
            TK_T *pf = W + parent * TW_STRIDE + TW_A + 9, *pn = pf + 3, F[3], N[3], x[3];
            SP_APPLY(R, f, F);
            SP_APPLY(R, nn, N);
            SP_CROSS(p, F, x);
            for (int r = 0; r < 3; r++) { pf[r] += F[r]; pn[r] += N[r] + x[r]; }
        }
    }
}

static void TK_FN(inverse)(const tk_tree *t, const TK_T *restrict q, const TK_T *restrict v,
                           const TK_T *restrict a, TK_T *restrict W, TK_T *restrict tau)
{
    TK_FN(place)(t, q, W);
    TK_FN(inverse_placed)(t, v, a, W, tau);
}

/* M by the composite-rigid-body algorithm in world axes about the world's origin (row-major
   n x n): each body's inertia (mass m, first moment h, rotational inertia J_O) moved there once,
   composites summed child into parent with no turning, and each joint's motion columns S there
   (joint.h: one, a ball's three, a free flyer's six, the multiplier k in a mimic's); then
   M[i][j] = S_j . (I_c(i) S_i) for each column j of body i's joint and of every joint from it
   to the root: one 6-vector dot a pair, no joint kind asked again. The bodies placed in W
   (TK_FN(place)); the numbers there that RNEA reads (R, p, cos, sin) left as they are. */
static void TK_FN(mass_placed)(const tk_tree *t, TK_T *restrict W, TK_T *restrict M)
{
    const int n = t->nv, nb = t->nb;
    /* the tree's links as integers, read once: the walks below are chains of these loads */
    int parent_of[nb], column_of[nb], count_of[nb];
    for (int k = 0; k < n * n; k++) M[k] = TK_C(0.0);
    for (int i = 0; i < nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        TK_T *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P;
        TK_T *Rw = w + TW_RW, *o = w + TW_OW, *Ic = w + TW_IC;
        const int parent = (int)b[TK_PARENT];
        parent_of[i] = parent;
        column_of[i] = TK_FREE(b) ? 0 : t->bv + (int)b[TK_COORD];
        if (parent < 0) {  /* the ground's axes are the world's (a free flyer's pose too) */
            for (int r = 0; r < 9; r++) Rw[r] = R[r];
            for (int r = 0; r < 3; r++) o[r] = p[r];
        } else {  /* Rw = Rp R, o = op + Rp p (joint.h) */
            const TK_T *Rp = W + parent * TW_STRIDE + TW_RW, *op = W + parent * TW_STRIDE + TW_OW;
            JT_FN(world)(b, Rp, op, R, p, w[TW_CS], w[TW_SN], Rw, o);
        }
        /* Ic = (m, h_O, J_O about the world's origin), J_O as xx yy zz xy xz yz */
        const double m = b[TK_MASS];
        TK_T hr[3], RJ[9];
        SP_APPLY(Rw, b + TK_H, hr);
        for (int r = 0; r < 3; r++)
            for (int col = 0; col < 3; col++)
                RJ[3 * r + col] = Rw[3 * r] * b[TK_J + col] + Rw[3 * r + 1] * b[TK_J + 3 + col]
                                  + Rw[3 * r + 2] * b[TK_J + 6 + col];
        static const int ra[6] = {0, 1, 2, 0, 0, 1}, rc[6] = {0, 1, 2, 1, 2, 2};
        TK_T *hO = Ic + 1;  /* h_O = R h + m o, then m (|o|^2 1 - o o^T) + 2 (o.Rh) 1 - o (Rh)^T
                               - (Rh) o^T = (o.h_O + o.Rh) 1 - o h_O^T - (Rh) o^T */
        Ic[0] = TK_C(m);
        for (int r = 0; r < 3; r++) hO[r] = hr[r] + m * o[r];
        const TK_T diagonal = SP_DOT(o, hO) + SP_DOT(o, hr);
        for (int e = 0; e < 6; e++) {
            const int x = ra[e], y = rc[e];
            TK_T v = RJ[3 * x] * Rw[3 * y] + RJ[3 * x + 1] * Rw[3 * y + 1]
                     + RJ[3 * x + 2] * Rw[3 * y + 2];
            if (e < 3) v += diagonal;
            Ic[4 + e] = v - o[x] * hO[y] - hr[x] * o[y];
        }
        /* the joint's motion columns at the world's origin (s_v, s_w), per unit rate */
        TK_T *S = w + TW_COLS;
        const int count = JT_FN(columns)(b, Rw, o, (TK_T (*)[6])S);
        count_of[i] = count;
        if (count == 1 && b[TK_MULT] != 1.0)  /* a mimic: q_i = k q_master + offset */
            for (int r = 0; r < 6; r++) S[r] *= b[TK_MULT];
    }
    for (int i = nb - 1; i >= 0; i--) {  /* children before their parents */
        TK_T *w = W + i * TW_STRIDE, *Ic = w + TW_IC, *h = Ic + 1, *J = Ic + 4;
        const TK_T *S = w + TW_COLS;
        const int ci = column_of[i], count = count_of[i], parent = parent_of[i];
        if (parent >= 0) {  /* its composite is whole: into its parent's */
            TK_T *Icp = W + parent * TW_STRIDE + TW_IC;
            for (int k = 0; k < 10; k++) Icp[k] += Ic[k];
        }
        for (int c = 0; c < count; c++) {
            const TK_T *sv = S + 6 * c, *sw = sv + 3;
            TK_T f[6], x[3];
            SP_CROSS(sw, h, x);  /* F = Ic S: [m s_v + s_w x h; h x s_v + J_O s_w] */
            for (int r = 0; r < 3; r++) f[r] = Ic[0] * sv[r] + x[r];
            SP_CROSS(h, sv, x);
            f[3] = x[0] + J[0] * sw[0] + J[3] * sw[1] + J[4] * sw[2];
            f[4] = x[1] + J[3] * sw[0] + J[1] * sw[1] + J[5] * sw[2];
            f[5] = x[2] + J[4] * sw[0] + J[5] * sw[1] + J[2] * sw[2];
            for (int r = c; r < count; r++) {  /* the joint's own block, mirrored: */
                const TK_T e = SP_DOT(S + 6 * r, f) + SP_DOT(S + 6 * r + 3, f + 3);
                M[(ci + r) * n + ci + c] += e;  /* M symmetric bit for bit */
                if (r != c) M[(ci + c) * n + ci + r] += e;
            }
            TK_T *row = M + (ci + c) * n, *column = M + ci + c;
            for (int k = parent; k >= 0; k = parent_of[k]) {  /* += : mimics share */
                const TK_T *Sk = W + k * TW_STRIDE + TW_COLS;
                const int ck = column_of[k];
                if (count_of[k] == 1) {
                    const TK_T e = SP_DOT(Sk, f) + SP_DOT(Sk + 3, f + 3);
                    row[ck] += e;
                    column[ck * n] += e;
                    continue;
                }
                for (int r = 0; r < count_of[k]; r++) {
                    const TK_T e = SP_DOT(Sk + 6 * r, f) + SP_DOT(Sk + 6 * r + 3, f + 3);
                    row[ck + r] += e;
                    column[(ck + r) * n] += e;
                }
            }
        }
    }
}

static void TK_FN(mass)(const tk_tree *t, const TK_T *restrict q, TK_T *restrict W,
                        TK_T *restrict M)
{
    TK_FN(place)(t, q, W);
    TK_FN(mass_placed)(t, W, M);
}

/* T = 1/2 sum (m v.v + 2 v.(w x h) + w.J w) */
static TK_T TK_FN(kinetic)(const tk_tree *t, const TK_T *restrict q, const TK_T *restrict v,
                           TK_T *restrict W)
{
    TK_FN(place)(t, q, W);
    TK_T total = TK_C(0.0);
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        TK_T *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P;
        TK_T *om = w + TW_A, *vel = om + 3, x[3];
        double sw, sv;
        const int parent = (int)b[TK_PARENT];
        tk_subspace(b, &sw, &sv);
        if (TK_FREE(b)) {
            for (int r = 0; r < 3; r++) { om[r] = v[3 + r]; vel[r] = v[r]; }
        } else if (parent < 0) {
            for (int r = 0; r < 3; r++) om[r] = vel[r] = TK_C(0.0);
        } else {
            const TK_T *pw = W + parent * TW_STRIDE + TW_A;
            SP_CROSS(pw, p, x);
            for (int r = 0; r < 3; r++) x[r] += pw[3 + r];
            SP_APPLY_T(R, pw, om);
            SP_APPLY_T(R, x, vel);
        }
        if (TK_BALL(b)) {
            for (int r = 0; r < 3; r++) om[r] += v[t->bv + (int)b[TK_COORD] + r];
        } else if (TK_FLYER(b)) {  /* its twist, linear then angular, in its axes */
            const TK_T *vr = v + t->bv + (int)b[TK_COORD];
            for (int r = 0; r < 3; r++) { vel[r] += vr[r]; om[r] += vr[3 + r]; }
        } else if (!TK_FREE(b)) {
            const TK_T rate = v[t->bv + (int)b[TK_COORD]];
            om[2] += rate * sw;
            vel[2] += rate * sv;
        }
        TK_T Jw[3], wh[3];
        SP_APPLY(b + TK_J, om, Jw);
        SP_CROSS(om, b + TK_H, wh);
        total += b[TK_MASS] * SP_DOT(vel, vel) + 2.0 * SP_DOT(vel, wh) + SP_DOT(om, Jw);
    }
    return 0.5 * total;
}

/* V = -sum (m g.r + g.h), g the gravity vector in each body's axes, r its origin */
static TK_T TK_FN(potential)(const tk_tree *t, const TK_T *restrict q, TK_T *restrict W)
{
    TK_FN(place)(t, q, W);
    TK_T total = TK_C(0.0);
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        TK_T *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P, *gb = w + TW_A;
        const int parent = (int)b[TK_PARENT];
        if (parent < 0) {
            gb[3] = SP_DOT(t->g, p);  /* g . r of this origin */
            SP_APPLY_T(R, t->g, gb);
        } else {
            const TK_T *gl = W + parent * TW_STRIDE + TW_A;
            gb[3] = gl[3] + SP_DOT(gl, p);
            SP_APPLY_T(R, gl, gb);
        }
        total -= b[TK_MASS] * gb[3] + SP_DOT(gb, b + TK_H);
    }
    return total;
}
