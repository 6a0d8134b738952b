/* The compact tree kernel: the recursions of tree_algorithms.py as loops over a tree given at
   run time as one array of doubles (its layout in compact_kernel.py), compiled once for every
   tree. Units SI. Each body i hangs from parent(i) < i (or the ground, -1) by one joint:
   R = R0 Rot(u, theta) (revolute, helical) or R0 (prismatic), p = t0 (+ R0 u lead theta: lead
   1 prismatic, the pitch helical), with theta = k q[c] + offset; R turns body axes into parent axes, p is the origin in the parent.
   A floating base (header flag) is body 0 on a free flyer (kind 2, free_flyer.py): q holds
   nq = 7 + n numbers (its position, quaternion x y z w, then the joints: q[7 + c]), v, a and
   tau nv = 6 + n (its twist in its own axes, linear then angular, then v[6 + c]). A ball joint
   (kind 4, spherical.py) turns its body by the unit quaternion q[QCOORD:QCOORD + 4] (w x y z,
   MuJoCo's), R = R0 R(q), p = t0, at the angular velocity v[COORD:COORD + 3] in the body's axes:
   a coordinate's place in q (QCOORD) and in v (COORD) then differ, and n counts v's. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
/* TK_SINCOS */

#define TK_HEADER 8     /* nb, n, gravity vector g*dir (3, world axes), mimic flag, floating
                           flag, quaternion tolerance */
#define TK_STRIDE 64    /* numbers per body record */
/* a body record's fields */
#define TK_PARENT 0
#define TK_KIND 1       /* 0 revolute, 1 prismatic, 2 free flyer (body 0 only), 3 helical,
                           4 ball */
#define TK_COORD 2      /* its (first) number in v, after the base's */
#define TK_MULT 3
#define TK_OFFSET 4
#define TK_R0 5         /* 9, row-major */
#define TK_T0 14        /* 3 */
#define TK_AXIS 17      /* 3 */
#define TK_MASS 20
#define TK_H 21         /* 3: first moment m c about the body origin */
#define TK_J 24         /* 9: inertia about the body origin */
#define TK_PERM 33      /* 3: where R0 is a signed permutation, each row's nonzero column */
#define TK_SIGN 36      /* 3: that entry, +-1 */
#define TK_PERMUTED 39  /* 1 where R0 is a signed permutation (description.py) */
#define TK_QCOORD 40    /* its (first) number in q, after the base's */
#define TK_LEAD 61      /* the slide along u per unit theta: 1 prismatic, pitch (m/rad) helical */
#define TK_TURNS(b) ((b)[TK_KIND] == 0.0 || (b)[TK_KIND] == 3.0)
#define TK_SLIDES(b) ((b)[TK_KIND] == 1.0 || (b)[TK_KIND] == 3.0)
/* a body's scratch */
#define TW_STRIDE 96
#define TW_R 0
#define TW_P 9
#define TW_A 12         /* 6-vectors and 6x6 matrices of the algorithms from here */
#define TW_CS 92        /* cos and sin of theta (1, 0 for a joint that does not turn) */
#define TW_SN 93

typedef struct {
    int nb, n, mimic, fb, bq, bv, nq, nv;  /* bq, bv: the base's numbers before the joints' */
    int balls;  /* ball joints: each one more number in q than in v */
    double qtol;
    const double *g, *tau0, *body;
} tk_tree;

#define TK_FREE(b) ((b)[TK_KIND] == 2.0)
#define TK_BALL(b) ((b)[TK_KIND] == 4.0)

static int tk_open(const double *d, Py_ssize_t size, tk_tree *t)
{
    if (size < TK_HEADER) return -1;
    t->nb = (int)d[0];
    t->n = (int)d[1];
    t->mimic = d[5] != 0.0;
    t->fb = d[6] != 0.0;
    t->qtol = d[7];
    t->bq = t->fb ? 7 : 0;
    t->bv = t->fb ? 6 : 0;
    t->g = d + 2;
    t->tau0 = d + TK_HEADER;
    t->body = d + TK_HEADER + t->n;
    if (t->nb < 1 || t->n < (t->fb ? 0 : 1)
        || size != TK_HEADER + t->n + (Py_ssize_t)t->nb * TK_STRIDE)
        return -1;
    t->balls = 0;
    for (int i = 0; i < t->nb; i++)
        if (TK_BALL(t->body + i * TK_STRIDE)) t->balls++;
    t->nq = t->bq + t->n + t->balls;
    t->nv = t->bv + t->n;
    if (t->balls) t->mimic = 1;  /* forward dynamics by Cholesky of M */
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        if (!(b[TK_PARENT] >= -1 && b[TK_PARENT] < i))
            return -1;
        if (t->fb && i == 0) {  /* the free flyer, and only it, on the ground */
            if (!TK_FREE(b) || b[TK_PARENT] != -1) return -1;
        } else if (TK_BALL(b)) {
            if (!(b[TK_COORD] >= 0 && b[TK_COORD] + 3 <= t->n && b[TK_QCOORD] >= 0
                  && b[TK_QCOORD] + 4 <= t->n + t->balls))
                return -1;
        } else if (!(b[TK_COORD] >= 0 && b[TK_COORD] < t->n)
                   || !(b[TK_QCOORD] >= 0 && b[TK_QCOORD] < t->n + t->balls)
                   || !(TK_TURNS(b) || TK_SLIDES(b))) {
            return -1;
        }
    }
    return 0;
}

/* Small 3-vector helpers as macros, so that each takes a tree's doubles or a state's numbers
   (a TK_T: one double, or LG_LANES of them) in any place; the core below is compiled twice. */
#define TK_CROSS(a, b, c) do {                                       \
        TK_T c0_ = (a)[1] * (b)[2] - (a)[2] * (b)[1];                \
        TK_T c1_ = (a)[2] * (b)[0] - (a)[0] * (b)[2];                \
        TK_T c2_ = (a)[0] * (b)[1] - (a)[1] * (b)[0];                \
        (c)[0] = c0_; (c)[1] = c1_; (c)[2] = c2_;                    \
    } while (0)
#define TK_APPLY(R, x, y) do {  /* y = R x */                                        \
        for (int r_ = 0; r_ < 3; r_++)                                               \
            (y)[r_] = (R)[3 * r_] * (x)[0] + (R)[3 * r_ + 1] * (x)[1] + (R)[3 * r_ + 2] * (x)[2]; \
    } while (0)
#define TK_APPLY_T(R, x, y) do {  /* y = R^T x */                                    \
        for (int r_ = 0; r_ < 3; r_++)                                               \
            (y)[r_] = (R)[r_] * (x)[0] + (R)[3 + r_] * (x)[1] + (R)[6 + r_] * (x)[2]; \
    } while (0)
#define TK_DOT(a, b) ((a)[0] * (b)[0] + (a)[1] * (b)[1] + (a)[2] * (b)[2])

/* S = ((0, 0, s_w), (0, 0, s_v)) per unit rate of q (the multiplier k included), about the
   joint's z: the tree's numbers alone. */
static inline void tk_subspace(const double *b, double *sw, double *sv)
{
    *sw = TK_TURNS(b) ? b[TK_MULT] : 0.0;
    *sv = TK_SLIDES(b) ? b[TK_MULT] * b[TK_LEAD] : 0.0;
}

/* the mass matrix's scratch per body: its rotation and origin in the world, its composite
   inertia about the world's origin (m, h, J_O's six), its joint's s_w and s_v there */
enum { TW_RW = TW_A, TW_OW = TW_RW + 9, TW_IC = TW_OW + 3, TW_SW = TW_IC + 10,
       TW_SV = TW_SW + 3 };

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

/* R = R0 E(x, y, z, s): E the rotation of the quaternion (x, y, z, s = its scalar part), made
   unit here (a free flyer's, a ball joint's) */
static inline void TK_FN(turned)(const double *R0, TK_T x, TK_T y, TK_T z, TK_T s, TK_T *R)
{
    const TK_T k = 2.0 / (x * x + y * y + z * z + s * s);
    const TK_T E[9] = {1.0 - k * (y * y + z * z), k * (x * y - z * s), k * (x * z + y * s),
                       k * (x * y + z * s), 1.0 - k * (x * x + z * z), k * (y * z - x * s),
                       k * (x * z - y * s), k * (y * z + x * s), 1.0 - k * (x * x + y * y)};
    for (int r = 0; r < 3; r++)
        for (int col = 0; col < 3; col++)
            R[3 * r + col] = R0[3 * r] * E[col] + R0[3 * r + 1] * E[3 + col]
                             + R0[3 * r + 2] * E[6 + col];
}

/* Each body's R and p for the configuration q (into the scratch W), and theta's cos, sin. */
static void TK_FN(place)(const tk_tree *t, const TK_T *restrict q, TK_T *restrict W)
{
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        TK_T *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P;
        const double *R0 = b + TK_R0;
        if (TK_FREE(b)) {  /* R0 R(quaternion x y z w, normalized), t0 + R0 x */
            TK_FN(turned)(R0, q[3], q[4], q[5], q[6], R);
            TK_APPLY(R0, q, p);
            for (int r = 0; r < 3; r++) p[r] += b[TK_T0 + r];
            w[TW_CS] = TK_C(1.0);
            w[TW_SN] = TK_C(0.0);
            continue;
        }
        if (TK_BALL(b)) {  /* R0 R(quaternion w x y z, normalized), p = t0 */
            const TK_T *e = q + t->bq + (int)b[TK_QCOORD];
            TK_FN(turned)(R0, e[1], e[2], e[3], e[0], R);
            for (int r = 0; r < 3; r++) p[r] = TK_C(b[TK_T0 + r]);
            w[TW_CS] = TK_C(1.0);
            w[TW_SN] = TK_C(0.0);
            continue;
        }
        const TK_T theta = b[TK_MULT] * q[t->bq + (int)b[TK_QCOORD]] + b[TK_OFFSET];
        if (TK_TURNS(b)) {
            /* sine and cosine written out here: a libm call cost as much as the rest of an
               arm's mass matrix */
            TK_T sn, cs;
            TK_SINCOS(theta, &sn, &cs);
            w[TW_CS] = cs;
            w[TW_SN] = sn;
            if (b[TK_PERMUTED] != 0.0) {  /* row r of R0 Rot(z) is +-row PERM[r] of Rot(z) */
                for (int r = 0; r < 3; r++) {
                    const int k = (int)b[TK_PERM + r];
                    const double e = b[TK_SIGN + r];
                    TK_T *row = R + 3 * r;
                    if (k == 0) { row[0] = e * cs; row[1] = -e * sn; row[2] = TK_C(0.0); }
                    else if (k == 1) { row[0] = e * sn; row[1] = e * cs; row[2] = TK_C(0.0); }
                    else { row[0] = TK_C(0.0); row[1] = TK_C(0.0); row[2] = TK_C(e); }
                }
            } else {  /* columns: cos R0 e_x + sin R0 e_y, cos R0 e_y - sin R0 e_x, R0 e_z */
                for (int r = 0; r < 3; r++) {
                    R[3 * r] = cs * R0[3 * r] + sn * R0[3 * r + 1];
                    R[3 * r + 1] = cs * R0[3 * r + 1] - sn * R0[3 * r];
                    R[3 * r + 2] = TK_C(R0[3 * r + 2]);
                }
            }
        } else {
            w[TW_CS] = TK_C(1.0);
            w[TW_SN] = TK_C(0.0);
            for (int r = 0; r < 9; r++) R[r] = TK_C(R0[r]);
        }
        for (int r = 0; r < 3; r++) p[r] = TK_C(b[TK_T0 + r]);
        if (TK_SLIDES(b)) {  /* along R0 e_z by lead theta (a prismatic joint's lead 1) */
            const TK_T slide = b[TK_KIND] == 1.0 ? theta : b[TK_LEAD] * theta;
            for (int r = 0; r < 3; r++) p[r] += R0[3 * r + 2] * slide;
        }
    }
}

/* Recursive Newton-Euler: tau = M a + C v + g - tau0 (v, a NULL: zero). */
static void TK_FN(inverse)(const tk_tree *t, const TK_T *restrict q, const TK_T *restrict v,
                           const TK_T *restrict a, TK_T *restrict W, TK_T *restrict tau)
{
    TK_FN(place)(t, q, W);
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
            TK_APPLY_T(R, up, acc);
            if (TK_FREE(b)) {  /* the origin's acceleration a_v + w x v_v, body axes */
                if (v) {
                    TK_CROSS(v + 3, v, x);
                    for (int r = 0; r < 3; r++) { om[r] = v[3 + r]; acc[r] += x[r]; }
                }
                if (a)
                    for (int r = 0; r < 3; r++) { dom[r] = a[3 + r]; acc[r] += a[r]; }
            }
        } else {
            const TK_T *pw = W + parent * TW_STRIDE + TW_A, *pdw = pw + 3, *pa = pw + 6;
            TK_T z[3];
            TK_APPLY_T(R, pw, om);
            TK_APPLY_T(R, pdw, dom);
            /* a_parent + dw x p + w x (w x p) */
            TK_CROSS(pdw, p, x);
            TK_CROSS(pw, p, y);
            TK_CROSS(pw, y, z);
            for (int r = 0; r < 3; r++) x[r] += pa[r] + z[r];
            TK_APPLY_T(R, x, acc);
        }
        if (TK_BALL(b)) {  /* w += w_rel, dw += w x w_rel + dw_rel (body axes) */
            if (v) {
                const TK_T *wr = v + t->bv + c;
                TK_CROSS(om, wr, x);
                for (int r = 0; r < 3; r++) { dom[r] += x[r]; om[r] += wr[r]; }
            }
            if (a)
                for (int r = 0; r < 3; r++) dom[r] += a[t->bv + c + r];
        } else if (v && !TK_FREE(b)) {  /* the joint's rate about z: w += S w, the Coriolis terms */
            const TK_T rate = v[t->bv + c], wz = rate * sw, vz = rate * sv;
            dom[0] += om[1] * wz;  /* w x (0, 0, wz) */
            dom[1] -= om[0] * wz;
            om[2] += wz;
            acc[0] += 2.0 * (om[1] * vz);
            acc[1] -= 2.0 * (om[0] * vz);
        }
        if (a && !TK_FREE(b) && !TK_BALL(b)) {
            const TK_T accel = a[t->bv + c];
            dom[2] += accel * sw;
            acc[2] += accel * sv;
        }
        /* f = m a + dw x h + w x (w x h), n = J dw + w x J w + h x a (about the origin) */
        const double m = b[TK_MASS], *h = b + TK_H, *J = b + TK_J;
        TK_T wh[3], z[3];
        TK_CROSS(dom, h, x);
        TK_CROSS(om, h, wh);
        TK_CROSS(om, wh, z);
        for (int r = 0; r < 3; r++) f[r] = m * acc[r] + x[r] + z[r];
        TK_APPLY(J, dom, nn);
        TK_APPLY(J, om, y);
        TK_CROSS(om, y, x);
        TK_CROSS(h, acc, z);
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
        } else {
            tk_subspace(b, &sw, &sv);
            tau[t->bv + (int)b[TK_COORD]] += sw * nn[2] + sv * f[2];
        }
        const int parent = (int)b[TK_PARENT];
        if (parent >= 0) {
            TK_T *pf = W + parent * TW_STRIDE + TW_A + 9, *pn = pf + 3, F[3], N[3], x[3];
            TK_APPLY(R, f, F);
            TK_APPLY(R, nn, N);
            TK_CROSS(p, F, x);
            for (int r = 0; r < 3; r++) { pf[r] += F[r]; pn[r] += N[r] + x[r]; }
        }
    }
}

/* a ball joint's columns of M and S_c . f (tree_kernel_forward.c) */
static inline TK_T TK_FN(ball_dot)(const TK_T *w, int c, const TK_T *f);
static void TK_FN(ball_columns)(const tk_tree *t, const TK_T *W, int i, TK_T *M);

/* M by the composite-rigid-body algorithm in world axes about the world's origin (row-major
   n x n): each body's inertia (mass m, first moment h, rotational inertia J_O) moved there once,
   composites summed child into parent with no turning, then M[i][j] = S_j . (I_c(i) S_i) for
   each joint j from body i to the root: one 6-vector dot a pair, where the bodies' own axes
   turned the composite's wrench at every step of that walk. */
static void TK_FN(mass)(const tk_tree *t, const TK_T *restrict q, TK_T *restrict W,
                        TK_T *restrict M)
{
    const int n = t->nv;
    TK_FN(place)(t, q, W);
    for (int k = 0; k < n * n; k++) M[k] = TK_C(0.0);
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        TK_T *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P;
        TK_T *Rw = w + TW_RW, *o = w + TW_OW, *Ic = w + TW_IC;
        const int parent = (int)b[TK_PARENT];
        if (parent < 0) {  /* the ground's axes are the world's (a free flyer's pose too) */
            for (int r = 0; r < 9; r++) Rw[r] = R[r];
            for (int r = 0; r < 3; r++) o[r] = p[r];
        } else if (b[TK_PERMUTED] != 0.0) {  /* Rw = (Rp R0) Rot(z): columns moved, then turned */
            const TK_T *Rp = W + parent * TW_STRIDE + TW_RW, *op = W + parent * TW_STRIDE + TW_OW;
            TK_T Q[9], d[3];
            for (int r = 0; r < 3; r++) {  /* column PERM[r] of Rp R0 is SIGN[r] Rp e_r */
                const int k = (int)b[TK_PERM + r];
                const double e = b[TK_SIGN + r];
                for (int x = 0; x < 3; x++) Q[3 * x + k] = e * Rp[3 * x + r];
            }
            const TK_T cs = w[TW_CS], sn = w[TW_SN];
            for (int x = 0; x < 3; x++) {
                if (TK_TURNS(b)) {
                    Rw[3 * x] = cs * Q[3 * x] + sn * Q[3 * x + 1];
                    Rw[3 * x + 1] = cs * Q[3 * x + 1] - sn * Q[3 * x];
                } else {
                    Rw[3 * x] = Q[3 * x];
                    Rw[3 * x + 1] = Q[3 * x + 1];
                }
                Rw[3 * x + 2] = Q[3 * x + 2];
            }
            TK_APPLY(Rp, p, d);
            for (int r = 0; r < 3; r++) o[r] = op[r] + d[r];
        } else {
            const TK_T *Rp = W + parent * TW_STRIDE + TW_RW, *op = W + parent * TW_STRIDE + TW_OW;
            TK_T d[3];
            for (int r = 0; r < 3; r++)
                for (int col = 0; col < 3; col++)
                    Rw[3 * r + col] = Rp[3 * r] * R[col] + Rp[3 * r + 1] * R[3 + col]
                                      + Rp[3 * r + 2] * R[6 + col];
            TK_APPLY(Rp, p, d);
            for (int r = 0; r < 3; r++) o[r] = op[r] + d[r];
        }
        /* Ic = (m, h_O = R h + m o, J_O = R J R^T + m (|o|^2 1 - o o^T) + 2 (o.Rh) 1 - o (Rh)^T
           - (Rh) o^T), J_O as xx yy zz xy xz yz */
        const double m = b[TK_MASS];
        TK_T hr[3], RJ[9];
        TK_APPLY(Rw, b + TK_H, hr);
        for (int r = 0; r < 3; r++)
            for (int col = 0; col < 3; col++)
                RJ[3 * r + col] = Rw[3 * r] * b[TK_J + col] + Rw[3 * r + 1] * b[TK_J + 3 + col]
                                  + Rw[3 * r + 2] * b[TK_J + 6 + col];
        const TK_T oo = TK_DOT(o, o), oh = TK_DOT(o, hr);
        static const int ra[6] = {0, 1, 2, 0, 0, 1}, rc[6] = {0, 1, 2, 1, 2, 2};
        Ic[0] = TK_C(m);
        for (int r = 0; r < 3; r++) Ic[1 + r] = hr[r] + m * o[r];
        for (int e = 0; e < 6; e++) {
            const int x = ra[e], y = rc[e];
            TK_T v = RJ[3 * x] * Rw[3 * y] + RJ[3 * x + 1] * Rw[3 * y + 1]
                     + RJ[3 * x + 2] * Rw[3 * y + 2];
            if (e < 3) v += m * oo + 2.0 * oh;
            Ic[4 + e] = v - m * o[x] * o[y] - o[x] * hr[y] - hr[x] * o[y];
        }
        /* the joint's motion per unit rate at the world's origin: s_w = Rw e_z sw,
           s_v = Rw e_z sv + o x s_w */
        if (!TK_FREE(b) && !TK_BALL(b)) {
            double sw, sv;
            TK_T *Sw = w + TW_SW, *Sv = w + TW_SV, x[3];
            tk_subspace(b, &sw, &sv);
            for (int r = 0; r < 3; r++) { Sw[r] = sw * Rw[3 * r + 2]; Sv[r] = sv * Rw[3 * r + 2]; }
            TK_CROSS(o, Sw, x);
            for (int r = 0; r < 3; r++) Sv[r] += x[r];
        }
    }
    for (int i = t->nb - 1; i > 0; i--) {  /* composites: children before their parents */
        const int parent = (int)t->body[i * TK_STRIDE + TK_PARENT];
        if (parent < 0) continue;
        const TK_T *Ic = W + i * TW_STRIDE + TW_IC;
        TK_T *Icp = W + parent * TW_STRIDE + TW_IC;
        for (int k = 0; k < 10; k++) Icp[k] += Ic[k];
    }
    for (int i = t->nb - 1; i >= 0; i--) {
        const double *b = t->body + i * TK_STRIDE;
        const TK_T *w = W + i * TW_STRIDE, *Ic = w + TW_IC, *h = Ic + 1, *J = Ic + 4;
        if (TK_FREE(b)) {  /* the base's six columns [R e_c; 0] and [o x R e_c; R e_c] */
            const TK_T *Rw = w + TW_RW, *o = w + TW_OW;
            TK_T S[6][6], F[6][6];
            for (int c = 0; c < 3; c++) {
                TK_T e[3] = {Rw[c], Rw[3 + c], Rw[6 + c]}, x[3];
                TK_CROSS(o, e, x);
                for (int r = 0; r < 3; r++) {
                    S[c][r] = e[r]; S[c][3 + r] = TK_C(0.0);
                    S[3 + c][r] = x[r]; S[3 + c][3 + r] = e[r];
                }
            }
            for (int c = 0; c < 6; c++) {  /* F = Ic S: [m s_v + s_w x h; h x s_v + J_O s_w] */
                const TK_T *sv = S[c], *sw = S[c] + 3;
                TK_T x[3];
                TK_CROSS(sw, h, x);
                for (int r = 0; r < 3; r++) F[c][r] = Ic[0] * sv[r] + x[r];
                TK_CROSS(h, sv, x);
                F[c][3] = x[0] + J[0] * sw[0] + J[3] * sw[1] + J[4] * sw[2];
                F[c][4] = x[1] + J[3] * sw[0] + J[1] * sw[1] + J[5] * sw[2];
                F[c][5] = x[2] + J[4] * sw[0] + J[5] * sw[1] + J[2] * sw[2];
            }
            for (int c = 0; c < 6; c++)
                for (int r = 0; r < 6; r++) {
                    TK_T e = TK_C(0.0);
                    for (int k = 0; k < 6; k++) e += S[r][k] * F[c][k];
                    M[r * n + c] += e;
                }
            continue;
        }
        if (TK_BALL(b)) {
            TK_FN(ball_columns)(t, W, i, M);
            continue;
        }
        const TK_T *Sw = w + TW_SW, *Sv = w + TW_SV;
        TK_T f[6], x[3];
        TK_CROSS(Sw, h, x);  /* I_c(i) S_i */
        for (int r = 0; r < 3; r++) f[r] = Ic[0] * Sv[r] + x[r];
        TK_CROSS(h, Sv, x);
        f[3] = x[0] + J[0] * Sw[0] + J[3] * Sw[1] + J[4] * Sw[2];
        f[4] = x[1] + J[3] * Sw[0] + J[1] * Sw[1] + J[5] * Sw[2];
        f[5] = x[2] + J[4] * Sw[0] + J[5] * Sw[1] + J[2] * Sw[2];
        const int ci = t->bv + (int)b[TK_COORD];
        M[ci * n + ci] += TK_DOT(Sv, f) + TK_DOT(Sw, f + 3);
        for (int k = (int)b[TK_PARENT]; k >= 0; k = (int)t->body[k * TK_STRIDE + TK_PARENT]) {
            const double *bk = t->body + k * TK_STRIDE;
            const TK_T *wk = W + k * TW_STRIDE;
            if (TK_FREE(bk)) {  /* the base's six columns: S_base^T f */
                const TK_T *Rw = wk + TW_RW, *o = wk + TW_OW;
                for (int c = 0; c < 3; c++) {
                    TK_T e[3] = {Rw[c], Rw[3 + c], Rw[6 + c]}, y[3];
                    TK_CROSS(o, e, y);
                    const TK_T lin = TK_DOT(e, f), ang = TK_DOT(y, f) + TK_DOT(e, f + 3);
                    M[ci * n + c] += lin;  /* += : mimic joints share a column */
                    M[c * n + ci] += lin;
                    M[ci * n + 3 + c] += ang;
                    M[(3 + c) * n + ci] += ang;
                }
                break;
            }
            if (TK_BALL(bk)) {  /* the ball's three columns: S_ball^T f */
                const int ck = t->bv + (int)bk[TK_COORD];
                for (int c = 0; c < 3; c++) {
                    const TK_T e = TK_FN(ball_dot)(wk, c, f);
                    M[ci * n + ck + c] += e;
                    M[(ck + c) * n + ci] += e;
                }
                continue;
            }
            const TK_T e = TK_DOT(wk + TW_SV, f) + TK_DOT(wk + TW_SW, f + 3);
            const int ck = t->bv + (int)bk[TK_COORD];
            M[ci * n + ck] += e;
            M[ck * n + ci] += e;
        }
    }
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
            TK_CROSS(pw, p, x);
            for (int r = 0; r < 3; r++) x[r] += pw[3 + r];
            TK_APPLY_T(R, pw, om);
            TK_APPLY_T(R, x, vel);
        }
        if (TK_BALL(b)) {
            for (int r = 0; r < 3; r++) om[r] += v[t->bv + (int)b[TK_COORD] + r];
        } else if (!TK_FREE(b)) {
            const TK_T rate = v[t->bv + (int)b[TK_COORD]];
            om[2] += rate * sw;
            vel[2] += rate * sv;
        }
        TK_T Jw[3], wh[3];
        TK_APPLY(b + TK_J, om, Jw);
        TK_CROSS(om, b + TK_H, wh);
        total += b[TK_MASS] * TK_DOT(vel, vel) + 2.0 * TK_DOT(vel, wh) + TK_DOT(om, Jw);
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
            gb[3] = TK_DOT(t->g, p);  /* g . r of this origin */
            TK_APPLY_T(R, t->g, gb);
        } else {
            const TK_T *gl = W + parent * TW_STRIDE + TW_A;
            gb[3] = gl[3] + TK_DOT(gl, p);
            TK_APPLY_T(R, gl, gb);
        }
        total -= b[TK_MASS] * gb[3] + TK_DOT(gb, b + TK_H);
    }
    return total;
}
