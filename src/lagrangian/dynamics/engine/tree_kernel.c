/* The compact tree kernel: the recursions of tree_algorithms.py as loops over a tree given at
   run time as one array of doubles (its layout in compact_kernel.py), compiled once for every
   tree. Units SI. Each body i hangs from parent(i) < i (or the ground, -1) by one joint:
   R = R0 Rot(u, theta) (revolute) or R0 (prismatic), p = t0 (+ R0 u theta), with
   theta = k q[c] + offset; R turns body axes into parent axes, p is the origin in the parent.
   A floating base (header flag) is body 0 on a free flyer (kind 2, free_flyer.py): q holds
   nq = 7 + n numbers (its position, quaternion x y z w, then the joints: q[7 + c]), v, a and
   tau nv = 6 + n (its twist in its own axes, linear then angular, then v[6 + c]). */
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
#define TK_KIND 1       /* 0 revolute, 1 prismatic, 2 free flyer (body 0 only) */
#define TK_COORD 2
#define TK_MULT 3
#define TK_OFFSET 4
#define TK_R0 5         /* 9, row-major */
#define TK_T0 14        /* 3 */
#define TK_AXIS 17      /* 3 */
#define TK_MASS 20
#define TK_H 21         /* 3: first moment m c about the body origin */
#define TK_J 24         /* 9: inertia about the body origin */
#define TK_TURN 33      /* 27: R0 u u^T, R0 (1 - u u^T), R0 [u]x (row-major): a revolute joint's
                           R = R0 Rot(u, theta) = P + cos(theta) C + sin(theta) S */
/* a body's scratch */
#define TW_STRIDE 96
#define TW_R 0
#define TW_P 9
#define TW_A 12         /* 6-vectors and 6x6 matrices of the algorithms from here */

typedef struct {
    int nb, n, mimic, fb, bq, bv, nq, nv;  /* bq, bv: the base's numbers before the joints' */
    double qtol;
    const double *g, *tau0, *body;
} tk_tree;

#define TK_FREE(b) ((b)[TK_KIND] == 2.0)

static inline void tk_cross(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static inline void tk_apply(const double *R, const double *x, double *y)  /* y = R x */
{
    for (int i = 0; i < 3; i++) y[i] = R[3 * i] * x[0] + R[3 * i + 1] * x[1] + R[3 * i + 2] * x[2];
}

static inline void tk_apply_t(const double *R, const double *x, double *y)  /* y = R^T x */
{
    for (int i = 0; i < 3; i++) y[i] = R[i] * x[0] + R[3 + i] * x[1] + R[6 + i] * x[2];
}

static inline double tk_dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void tk_sandwich(const double *R, const double *A, double *out)  /* R A R^T */
{
    double T[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            T[3 * i + j] = R[3 * i] * A[j] + R[3 * i + 1] * A[3 + j] + R[3 * i + 2] * A[6 + j];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[3 * i + j] = T[3 * i] * R[3 * j] + T[3 * i + 1] * R[3 * j + 1]
                             + T[3 * i + 2] * R[3 * j + 2];
}

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
    t->nq = t->bq + t->n;
    t->nv = t->bv + t->n;
    t->g = d + 2;
    t->tau0 = d + TK_HEADER;
    t->body = d + TK_HEADER + t->n;
    if (t->nb < 1 || t->n < (t->fb ? 0 : 1)
        || size != TK_HEADER + t->n + (Py_ssize_t)t->nb * TK_STRIDE)
        return -1;
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        if (!(b[TK_PARENT] >= -1 && b[TK_PARENT] < i))
            return -1;
        if (t->fb && i == 0) {  /* the free flyer, and only it, on the ground */
            if (!TK_FREE(b) || b[TK_PARENT] != -1) return -1;
        } else if (!(b[TK_COORD] >= 0 && b[TK_COORD] < t->n)
                   || !(b[TK_KIND] == 0 || b[TK_KIND] == 1)) {
            return -1;
        }
    }
    return 0;
}

/* Each body's R and p for the configuration q (into the scratch W). */
static void tk_place(const tk_tree *t, const double *q, double *W)
{
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        double *R = W + i * TW_STRIDE + TW_R, *p = W + i * TW_STRIDE + TW_P;
        const double *R0 = b + TK_R0, *u = b + TK_AXIS;
        if (TK_FREE(b)) {  /* R0 R(quaternion x y z w, normalized), t0 + R0 x */
            const double x = q[3], y = q[4], z = q[5], s = q[6];
            const double k = 2.0 / (x * x + y * y + z * z + s * s);
            const double E[9] = {1 - k * (y * y + z * z), k * (x * y - z * s), k * (x * z + y * s),
                                 k * (x * y + z * s), 1 - k * (x * x + z * z), k * (y * z - x * s),
                                 k * (x * z - y * s), k * (y * z + x * s), 1 - k * (x * x + y * y)};
            for (int r = 0; r < 3; r++)
                for (int col = 0; col < 3; col++)
                    R[3 * r + col] = R0[3 * r] * E[col] + R0[3 * r + 1] * E[3 + col]
                                     + R0[3 * r + 2] * E[6 + col];
            tk_apply(R0, q, p);
            for (int r = 0; r < 3; r++) p[r] += b[TK_T0 + r];
            continue;
        }
        const double theta = b[TK_MULT] * q[t->bq + (int)b[TK_COORD]] + b[TK_OFFSET];
        if (b[TK_KIND] == 0) {
            /* sine and cosine written out here: a libm call cost as much as the rest of an
               arm's mass matrix */
            double sn, cs;
            lg_sincos_inline(theta, &sn, &cs);
            const double *P = b + TK_TURN, *C = P + 9, *S = P + 18;
            for (int r = 0; r < 9; r++) R[r] = P[r] + cs * C[r] + sn * S[r];
            memcpy(p, b + TK_T0, 3 * sizeof(double));
        } else {
            double Ru[3];
            memcpy(R, R0, 9 * sizeof(double));
            tk_apply(R0, u, Ru);
            for (int r = 0; r < 3; r++) p[r] = b[TK_T0 + r] + Ru[r] * theta;
        }
    }
}

/* S = (s_w, s_v) per unit rate of q (the multiplier k included). */
static inline void tk_subspace(const double *b, double *sw, double *sv)
{
    const double k = b[TK_MULT];
    for (int r = 0; r < 3; r++) {
        sw[r] = b[TK_KIND] == 0 ? k * b[TK_AXIS + r] : 0.0;
        sv[r] = b[TK_KIND] == 1 ? k * b[TK_AXIS + r] : 0.0;
    }
}

/* Recursive Newton-Euler: tau = M a + C v + g - tau0 (v, a NULL: zero). */
static void tk_inverse(const tk_tree *t, const double *q, const double *v, const double *a,
                       double *W, double *tau)
{
    tk_place(t, q, W);
    for (int i = 0; i < t->bv; i++) tau[i] = 0.0;
    for (int i = 0; i < t->n; i++) tau[t->bv + i] = -t->tau0[i];
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        double *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P;
        double *om = w + TW_A, *dom = om + 3, *acc = om + 6, *f = om + 9, *nn = om + 12;
        const int parent = (int)b[TK_PARENT], c = (int)b[TK_COORD];
        double sw[3], sv[3], x[3], y[3];
        tk_subspace(b, sw, sv);
        if (parent < 0) {
            const double up[3] = {-t->g[0], -t->g[1], -t->g[2]};  /* the ground accelerates up */
            for (int r = 0; r < 3; r++) om[r] = dom[r] = 0.0;
            tk_apply_t(R, up, acc);
            if (TK_FREE(b)) {  /* the origin's acceleration a_v + w x v_v, body axes */
                if (v) {
                    tk_cross(v + 3, v, x);
                    for (int r = 0; r < 3; r++) { om[r] = v[3 + r]; acc[r] += x[r]; }
                }
                if (a)
                    for (int r = 0; r < 3; r++) { dom[r] = a[3 + r]; acc[r] += a[r]; }
            }
        } else {
            const double *pw = W + parent * TW_STRIDE + TW_A, *pdw = pw + 3, *pa = pw + 6;
            double z[3];
            tk_apply_t(R, pw, om);
            tk_apply_t(R, pdw, dom);
            /* a_parent + dw x p + w x (w x p) */
            tk_cross(pdw, p, x);
            tk_cross(pw, p, y);
            tk_cross(pw, y, z);
            for (int r = 0; r < 3; r++) x[r] += pa[r] + z[r];
            tk_apply_t(R, x, acc);
        }
        const double rate = v && !TK_FREE(b) ? v[t->bv + c] : 0.0;
        const double accel = a && !TK_FREE(b) ? a[t->bv + c] : 0.0;
        if (rate != 0.0) {
            double ws[3] = {rate * sw[0], rate * sw[1], rate * sw[2]};
            tk_cross(om, ws, x);
            for (int r = 0; r < 3; r++) { om[r] += ws[r]; dom[r] += x[r]; }
            double vs[3] = {rate * sv[0], rate * sv[1], rate * sv[2]};
            tk_cross(om, vs, x);
            for (int r = 0; r < 3; r++) acc[r] += 2.0 * x[r];
        }
        for (int r = 0; r < 3; r++) { dom[r] += accel * sw[r]; acc[r] += accel * sv[r]; }
        /* f = m a + dw x h + w x (w x h), n = J dw + w x J w + h x a (about the origin) */
        const double m = b[TK_MASS], *h = b + TK_H, *J = b + TK_J;
        double wh[3], z[3];
        tk_cross(dom, h, x);
        tk_cross(om, h, wh);
        tk_cross(om, wh, z);
        for (int r = 0; r < 3; r++) f[r] = m * acc[r] + x[r] + z[r];
        tk_apply(J, dom, nn);
        tk_apply(J, om, y);
        tk_cross(om, y, x);
        tk_cross(h, acc, z);
        for (int r = 0; r < 3; r++) nn[r] += x[r] + z[r];
    }
    for (int i = t->nb - 1; i >= 0; i--) {
        const double *b = t->body + i * TK_STRIDE;
        double *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P;
        double *f = w + TW_A + 9, *nn = w + TW_A + 12, sw[3], sv[3];
        if (TK_FREE(b)) {  /* the base's wrench in its axes, force then moment */
            for (int r = 0; r < 3; r++) { tau[r] += f[r]; tau[3 + r] += nn[r]; }
            continue;
        }
        tk_subspace(b, sw, sv);
        tau[t->bv + (int)b[TK_COORD]] += tk_dot(sw, nn) + tk_dot(sv, f);
        const int parent = (int)b[TK_PARENT];
        if (parent >= 0) {
            double *pf = W + parent * TW_STRIDE + TW_A + 9, *pn = pf + 3, F[3], N[3], x[3];
            tk_apply(R, f, F);
            tk_apply(R, nn, N);
            tk_cross(p, F, x);
            for (int r = 0; r < 3; r++) { pf[r] += F[r]; pn[r] += N[r] + x[r]; }
        }
    }
}

/* M by the composite-rigid-body algorithm (row-major n x n). */
static void tk_mass(const tk_tree *t, const double *q, double *W, double *M)
{
    const int n = t->nv;
    tk_place(t, q, W);
    memset(M, 0, (size_t)n * n * sizeof(double));
    for (int i = 0; i < t->nb; i++) {  /* composite inertias start as the bodies' own */
        double *c = W + i * TW_STRIDE + TW_A;
        const double *b = t->body + i * TK_STRIDE;
        memcpy(c, b + TK_MASS, 13 * sizeof(double));
    }
    for (int i = t->nb - 1; i >= 0; i--) {
        const double *b = t->body + i * TK_STRIDE;
        double *w = W + i * TW_STRIDE, *c = w + TW_A;
        const double m = c[0], *h = c + 1, *J = c + 4;
        if (TK_FREE(b)) {  /* the whole robot's inertia: [[m 1, -[h]x], [[h]x, J]] */
            const double H[9] = {0.0, -h[2], h[1], h[2], 0.0, -h[0], -h[1], h[0], 0.0};
            for (int r = 0; r < 3; r++)
                for (int col = 0; col < 3; col++) {
                    M[r * n + col] = r == col ? m : 0.0;
                    M[r * n + 3 + col] = -H[3 * r + col];
                    M[(3 + r) * n + col] = H[3 * r + col];
                    M[(3 + r) * n + 3 + col] = J[3 * r + col];
                }
            continue;
        }
        const int ci = t->bv + (int)b[TK_COORD];
        double sw[3], sv[3], force[3], moment[3], x[3];
        tk_subspace(b, sw, sv);
        /* the composite's wrench for a unit rate: f = m s_v + s_w x h, n = J s_w + h x s_v */
        tk_cross(sw, h, x);
        for (int r = 0; r < 3; r++) force[r] = m * sv[r] + x[r];
        tk_apply(J, sw, moment);
        tk_cross(h, sv, x);
        for (int r = 0; r < 3; r++) moment[r] += x[r];
        M[ci * n + ci] += tk_dot(sw, moment) + tk_dot(sv, force);
        for (int k = i; (int)t->body[k * TK_STRIDE + TK_PARENT] >= 0;) {
            const double *wk = W + k * TW_STRIDE;
            double F[3], N[3];
            tk_apply(wk + TW_R, force, F);
            tk_apply(wk + TW_R, moment, N);
            tk_cross(wk + TW_P, F, x);
            for (int r = 0; r < 3; r++) { force[r] = F[r]; moment[r] = N[r] + x[r]; }
            k = (int)t->body[k * TK_STRIDE + TK_PARENT];
            const double *bk = t->body + k * TK_STRIDE;
            if (TK_FREE(bk)) {  /* the base's six columns: the wrench itself */
                for (int r = 0; r < 3; r++) {
                    M[ci * n + r] += force[r];  /* += : mimic joints share a column */
                    M[r * n + ci] += force[r];
                    M[ci * n + 3 + r] += moment[r];
                    M[(3 + r) * n + ci] += moment[r];
                }
                break;
            }
            double kw[3], kv[3];
            tk_subspace(bk, kw, kv);
            const double e = tk_dot(kw, moment) + tk_dot(kv, force);
            const int ck = t->bv + (int)bk[TK_COORD];
            M[ci * n + ck] += e;
            M[ck * n + ci] += e;
        }
        const int parent = (int)b[TK_PARENT];
        if (parent >= 0) {  /* the composite moved into the parent's axes */
            const double *R = w + TW_R, *p = w + TW_P;
            double *pc = W + parent * TW_STRIDE + TW_A, hr[3], S[9];
            tk_apply(R, h, hr);
            tk_sandwich(R, J, S);
            const double ph = tk_dot(p, hr), pp = tk_dot(p, p);
            /* J' = R J R^T + m (|p|^2 1 - p p^T) + 2 (p.h) 1 - p h^T - h p^T */
            for (int r = 0; r < 3; r++)
                for (int col = 0; col < 3; col++)
                    pc[4 + 3 * r + col] += S[3 * r + col]
                        + (r == col ? m * pp + 2.0 * ph : 0.0)
                        - m * p[r] * p[col] - p[r] * hr[col] - hr[r] * p[col];
            for (int r = 0; r < 3; r++) pc[1 + r] += hr[r] + m * p[r];
            pc[0] += m;
        }
    }
}

/* T = 1/2 sum (m v.v + 2 v.(w x h) + w.J w) */
static double tk_kinetic(const tk_tree *t, const double *q, const double *v, double *W)
{
    tk_place(t, q, W);
    double total = 0.0;
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        double *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P;
        double *om = w + TW_A, *vel = om + 3, sw[3], sv[3], x[3];
        const int parent = (int)b[TK_PARENT];
        tk_subspace(b, sw, sv);
        if (TK_FREE(b)) {
            for (int r = 0; r < 3; r++) { om[r] = v[3 + r]; vel[r] = v[r]; }
        } else if (parent < 0) {
            for (int r = 0; r < 3; r++) om[r] = vel[r] = 0.0;
        } else {
            const double *pw = W + parent * TW_STRIDE + TW_A;
            tk_cross(pw, p, x);
            for (int r = 0; r < 3; r++) x[r] += pw[3 + r];
            tk_apply_t(R, pw, om);
            tk_apply_t(R, x, vel);
        }
        const double rate = TK_FREE(b) ? 0.0 : v[t->bv + (int)b[TK_COORD]];
        for (int r = 0; r < 3; r++) { om[r] += rate * sw[r]; vel[r] += rate * sv[r]; }
        double Jw[3], wh[3];
        tk_apply(b + TK_J, om, Jw);
        tk_cross(om, b + TK_H, wh);
        total += b[TK_MASS] * tk_dot(vel, vel) + 2.0 * tk_dot(vel, wh) + tk_dot(om, Jw);
    }
    return 0.5 * total;
}

/* V = -sum (m g.r + g.h), g the gravity vector in each body's axes, r its origin */
static double tk_potential(const tk_tree *t, const double *q, double *W)
{
    tk_place(t, q, W);
    double total = 0.0;
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        double *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P, *gb = w + TW_A;
        const int parent = (int)b[TK_PARENT];
        const double *gl = parent < 0 ? t->g : W + parent * TW_STRIDE + TW_A;
        const double height = parent < 0 ? 0.0 : W[parent * TW_STRIDE + TW_A + 3];
        gb[3] = height + tk_dot(gl, p);  /* g . r of this origin */
        tk_apply_t(R, gl, gb);
        total -= b[TK_MASS] * gb[3] + tk_dot(gb, b + TK_H);
    }
    return total;
}

