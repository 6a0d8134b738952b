/* d tau/dq, d tau/dq_dot of recursive Newton-Euler and d q_ddot/dq, d q_ddot/dq_dot, M^-1 of
 * forward dynamics, over a tree given at run time (dk_tree below: any number of bodies, a
 * state's work in one block per thread, off its stack past a small tree's). Analytic, O(n^2)
 * per state but for forward dynamics' dense M^-1 products, O(n^3).
 *
 * Spatial vectors at the world's origin in world axes, linear part first: a motion [v; w], a
 * force [f; n]. A body's joint column S (theta_dot = k q_dot[c]); v_i = v_p + S theta_dot,
 * a_i = a_p + S theta_ddot + (v_p x S) theta_dot (a of the ground: -g), f_i = I a + v x* I v.
 * Turning joint j by d theta moves its subtree rigidly about S_j while its parent's v_p, a_p
 * stay: with dv_j = v_p x S_j and psi_j = a_p x S_j + v_p x dv_j, a body i below j gets
 *   d f_i / d theta_j     = S_j x* f_i + I_i psi_j + B_i dv_j,
 *   d f_i / d theta_dot_j = I_i (2 dv_j) + B_i S_j,   B_i x = v x* I x - I (v x x) + x x* I v,
 * so that, with composite (subtree) sums Ic, Bc, F (the rigid turn S_j x* cancels on the rows
 * of the subtree):
 *   row k below j (k in j's subtree):  d tau_k/d theta_j = S_k . (Ic_k psi_j + Bc_k dv_j)
 *   row k above j (k a strict ancestor): S_k . (S_j x* F_j + Ic_j psi_j + Bc_j dv_j),
 * likewise for theta_dot, and M_kj = S_k . Ic_k S_j. B = [[0, -2[l]x], [0, A]] with l the
 * linear momentum and A = [w]x J_O - J_O [w]x - [v]x[c]x - [c]x[v]x - [n]x (n the angular
 * momentum about the origin, c = m x_G): 12 numbers, additive over a subtree.
 * A ball joint is three such columns, a free flyer below the root six (derivatives_c.py's
 * description: one record each, the body on the last), its body's twists in its own axes (a
 * ball's turns about its x, y, z; a flyer's slides along them, then those turns): each moves
 * the joint's subtree rigidly from the joint's parent's v_p, a_p (dv, psi as above with
 * those), and between two columns of one joint both entries take the row-below form (each
 * column moves with the others, fixed in the body); d a/d theta_dot's own part is
 * dv + v_b x S (v_b the joint's body's), 2 dv for a joint of one column. */

#define DK_STR_(x) #x
#define DK_STR(x) DK_STR_(x)
#define DK_PASTE_(a, b) a##b
#define DK_PASTE(a, b) DK_PASTE_(a, b)

#include "spatial.h"
#include "joint.h"

/* The tree, read at run time: its description D (tree/description.py, the tree kernel's; each
 * joint in canonical axes, placed by joint.h) and one table of its pattern (derivatives_c.py),
 * copied here once per tree by the bindings: nb bodies, nj joint coordinates, ff 1 on a
 * floating base (body 0 a free flyer, its 7 q and 6 v first: qo, vo), nv = nj + 6 ff velocity
 * coordinates, nq = nj + 7 ff + a ball's one more; np ancestor pairs (k, j), j on k's path to the ground, k first;
 * per coordinate j the rows that d tau/d(q, q_dot)_j can have nonzero (rows[row0[j] ..
 * row0[j + 1]]), and its parent coordinate (lambda, for the factor along the tree). Per body,
 * read out of D once: its parent body, coordinate and multiplier. ``space``: the DK_T numbers
 * of one state's work (a lane group's on the lanes: carve). */
typedef struct {
    int nb, nj, ff, np, nv, nq, qo, vo, ltdl, once, sparse;
    int bodies;  /* the records that are a body's (end[i] == i): the regressor's ten columns */
    tk_tree t;
    const int *parent, *coord, (*pair)[2], *row0, *rows, *lambda;
    /* per record: whose motion its column's dv and psi are taken from (the parent's, a ball
       column's the ball's parent's), the record of its body (a ball column's: the last), and
       its ball (the first column's record; -1 for a record that is no ball's column) */
    const int *motion, *end, *group;
    const double *mult;
    size_t space;
} dk_tree;

#define DK_BODY_OF(tree, i) ((tree)->t.body + (size_t)(i) * TK_STRIDE)  /* body i's record */

/* joint.h's and spatial.h's number type and names: the core's (DK_T, DK_FN) */
#define SP_T DK_T
#define JT_T DK_T
#define JT_FN(name) DK_FN(jt_##name)
#define JT_C(x) DK_C(x)
#define JT_SINCOS DK_SINCOS

/* The core below is emitted twice by derivatives_c.py: on one state (dk_*, DK_T double) and on
 * LG_LANES states at once (dk4_*, DK_T lg_v4, GCC/Clang vector extensions). DK_FN(name) names a
 * function, DK_C(x) a constant as a DK_T, DK_SINCOS and DK_SQRT the functions of a DK_T, and
 * DK_FAILED(d) the lanes where !(d > 0) as a DK_MASK, DK_BITS(mask) those lanes as bits. */
/* DK_CORE_BEGIN */
/* JT_CORE: joint.h's core, here */

/* motion x motion: [w x yv + v x yw; w x yw] */
static inline void DK_FN(mcross)(const DK_T *x, const DK_T *y, DK_T *out)
{
    DK_T a[3], b[3], c[3];
    SP_CROSS(x + 3, y, a);
    SP_CROSS(x, y + 3, b);
    SP_CROSS(x + 3, y + 3, c);
    for (int j = 0; j < 3; j++) { out[j] = a[j] + b[j]; out[3 + j] = c[j]; }
}

/* motion x* force: [w x f; v x f + w x n] */
static inline void DK_FN(fcross)(const DK_T *x, const DK_T *f, DK_T *out)
{
    DK_T a[3], b[3], c[3];
    SP_CROSS(x + 3, f, a);
    SP_CROSS(x, f, b);
    SP_CROSS(x + 3, f + 3, c);
    for (int j = 0; j < 3; j++) { out[j] = a[j]; out[3 + j] = b[j] + c[j]; }
}

static inline DK_T DK_FN(dot6)(const DK_T *a, const DK_T *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5];
}

/* A spatial inertia at the world's origin: mass m, c = m x_G (3), J_O (3 x 3, symmetric). */
typedef struct { DK_T m, c[3], J[9]; } DK_FN(inertia);

/* Y x: [m v + w x c; c x v + J w] */
static inline void DK_FN(iapply)(const DK_FN(inertia) *Y, const DK_T *x, DK_T *out)
{
    DK_T a[3], b[3], Jw[3];
    SP_CROSS(x + 3, Y->c, a);
    SP_CROSS(Y->c, x, b);
    SP_APPLY(Y->J, x + 3, Jw);
    for (int j = 0; j < 3; j++) { out[j] = Y->m * x[j] + a[j]; out[3 + j] = b[j] + Jw[j]; }
}

/* A state's work (lane's): per body (tree->nb rows) in the thread's heap block (carve), a
 * floating base's six columns here. */
typedef struct {
    DK_T (*S)[6], (*dv)[6], (*psi)[6];
    DK_T (*dvv)[6];               /* d a/d theta_dot's own part: 2 dv (a ball column's below) */
    DK_T (*F)[6];                 /* f_i, then the subtree's sum */
    DK_FN(inertia) *Y;            /* the body's, then the subtree's */
    DK_T (*L)[3], (*A)[9];        /* B's 12 numbers, the body's then the subtree's */
    DK_T (*r1)[6], (*r2)[3];      /* Ic_k S_k and the angular part of Bc_k^T S_k */
    DK_T (*Phi)[6], (*Psi)[6];
    /* each body's placement (R: body -> world, origin o), velocity and acceleration at the
       world's origin (a of the ground: -g) */
    DK_T (*R)[9], (*o)[3], (*V)[6], (*Acc)[6];
    /* forward dynamics' own: the bodies' f and inertia before the sums, da, tau by body;
       per coordinate b, zeros and the factor's diagonal; and four nv x nv matrices */
    DK_T (*F0)[6], (*da)[6], *taub, *b, *zero, *diagonal, *M, *dq, *dv_, *X;
    DK_FN(inertia) *Y0;
    /* a floating base's six columns (body 0): S, psi = -g x S, dv = v x S (its parent the
       ground), Ic S, Bc^T S's angular part, and S . F */
    DK_T ffS[6][6], ffpsi[6][6], ffdv[6][6], ffr1[6][6], ffr2[6][3], fftau[6];
} DK_FN(work);

/* w's rows in the block at ``at`` (sizeof(DK_T) aligned); the first DK_T past them. The block
 * is sized once per tree (dk_tree's space, checked against this at the tree's making). */
static DK_T *DK_FN(carve)(const dk_tree *tree, DK_T *at, DK_FN(work) *w)
{
    const size_t nb = tree->nb, nv = tree->nv;
#define DK_TAKE(field, count) (w->field = (void *)at, at += (count))
    DK_TAKE(S, 6 * nb); DK_TAKE(dv, 6 * nb); DK_TAKE(psi, 6 * nb); DK_TAKE(F, 6 * nb);
    DK_TAKE(dvv, 6 * nb);
    DK_TAKE(Y, 13 * nb); DK_TAKE(L, 3 * nb); DK_TAKE(A, 9 * nb); DK_TAKE(r1, 6 * nb);
    DK_TAKE(r2, 3 * nb); DK_TAKE(Phi, 6 * nb); DK_TAKE(Psi, 6 * nb); DK_TAKE(R, 9 * nb);
    DK_TAKE(o, 3 * nb); DK_TAKE(V, 6 * nb); DK_TAKE(Acc, 6 * nb); DK_TAKE(F0, 6 * nb);
    DK_TAKE(da, 6 * nb); DK_TAKE(taub, nb); DK_TAKE(Y0, 13 * nb);
    DK_TAKE(b, nv); DK_TAKE(zero, nv); DK_TAKE(diagonal, nv);
    DK_TAKE(M, nv * nv); DK_TAKE(dq, nv * nv); DK_TAKE(dv_, nv * nv); DK_TAKE(X, nv * nv);
#undef DK_TAKE
    return at;
}

/* A floating base (body 0): q[0:3] its origin, q[3:7] its quaternion x y z w (joint.h places
 * it: R = R0 R(quaternion), o = t0 + R0 q[0:3]); its velocity and acceleration in its own axes, so
 * its columns are the world's images of the unit twists: [R e_c; 0] and [o x R e_c; R e_c]. */
static void DK_FN(base)(const dk_tree *tree, const DK_T *q, const DK_T *qd, const DK_T *qdd,
                        const double *g, DK_FN(work) *w)
{
    DK_T *R = w->R[0], *o = w->o[0], *V = w->V[0], *Acc = w->Acc[0];
    DK_FN(jt_placed)(&tree->t, DK_BODY_OF(tree, 0), q, NULL, NULL, R, o);
    DK_FN(jt_columns)(DK_BODY_OF(tree, 0), R, o, w->ffS);  /* its six columns (joint.h) */
    for (int j = 0; j < 6; j++) {
        V[j] = DK_C(0.0);
        Acc[j] = DK_C(j < 3 ? -g[j] : 0.0);
        w->S[0][j] = w->dv[0][j] = w->psi[0][j] = DK_C(0.0);
    }
    for (int c = 0; c < 6; c++)
        for (int j = 0; j < 6; j++) { V[j] += w->ffS[c][j] * qd[c]; Acc[j] += w->ffS[c][j] * qdd[c]; }
    const DK_T ground[6] = {DK_C(-g[0]), DK_C(-g[1]), DK_C(-g[2]), DK_C(0.0), DK_C(0.0), DK_C(0.0)};
    for (int c = 0; c < 6; c++) {
        DK_FN(mcross)(ground, w->ffS[c], w->ffpsi[c]);
        DK_FN(mcross)(V, w->ffS[c], w->ffdv[c]);
    }
}

/* The forward pass's kinematics: placements, S, v, a, dv and psi of every body. */
static void DK_FN(kinematics)(const dk_tree *tree, const DK_T *q, const DK_T *qd,
                              const DK_T *qdd, const double *g, DK_FN(work) *w)
{
    DK_T (*R)[9] = w->R, (*o)[3] = w->o, (*V)[6] = w->V, (*Acc)[6] = w->Acc;
    for (int i = 0; i < tree->nb; i++) {
        if (tree->ff && i == 0) {
            DK_FN(base)(tree, q, qd, qdd, g, w);
            continue;
        }
        const double *b = DK_BODY_OF(tree, i);
        const int p = tree->parent[i], mp = tree->motion[i];
        const int column = tree->group[i] >= 0 ? (int)b[TK_COLUMN] : 0;
        if (column > 1) {  /* a ball's or a flyer's later column: at the joint's pose */
            for (int j = 0; j < 9; j++) R[i][j] = R[p][j];
            for (int j = 0; j < 3; j++) o[i][j] = o[p][j];
        } else {
            DK_FN(jt_placed)(&tree->t, b, q, p < 0 ? NULL : R[p], p < 0 ? NULL : o[p], R[i],
                             o[i]);
        }
        if (column > 0) {  /* the joint's column of its twist in its body's axes (joint.h) */
            DK_T all[6][6];
            DK_FN(jt_columns)(b, R[i], o[i], all);
            for (int j = 0; j < 6; j++) w->S[i][j] = all[column - 1][j];
        } else {
            DK_FN(jt_columns)(b, R[i], o[i], (DK_T (*)[6])w->S[i]);  /* S (joint.h) */
        }
        const DK_T *S = w->S[i];
        /* the parent's motion, which the column adds to; and that its dv and psi are taken
           from (a ball column's: the ball's parent's, the ball's columns one joint) */
        DK_T vp[6], ap[6], vm[6], am[6];
        for (int j = 0; j < 6; j++) {
            vp[j] = p >= 0 ? V[p][j] : DK_C(0.0);
            ap[j] = p >= 0 ? Acc[p][j] : DK_C(j < 3 ? -g[j] : 0.0);
            vm[j] = mp >= 0 ? V[mp][j] : DK_C(0.0);
            am[j] = mp >= 0 ? Acc[mp][j] : DK_C(j < 3 ? -g[j] : 0.0);
        }
        DK_T rate = tree->mult[i] * qd[tree->vo + tree->coord[i]];
        DK_T accel = tree->mult[i] * qdd[tree->vo + tree->coord[i]];
        DK_T t[6];
        DK_FN(mcross)(vm, S, w->dv[i]);
        DK_FN(mcross)(am, S, w->psi[i]);
        DK_FN(mcross)(vm, w->dv[i], t);
        for (int j = 0; j < 6; j++) {
            w->psi[i][j] += t[j];
            V[i][j] = vp[j] + S[j] * rate;
            Acc[i][j] = ap[j] + S[j] * accel + w->dv[i][j] * rate;
        }
    }
    /* d a/d theta_dot below the joint, its own part: 2 dv for a joint of one column; for a
       ball's column dv + v_b x S (v_b the ball's body's velocity: the ball's other columns
       turn with it) */
    for (int i = 0; i < tree->nb; i++) {
        if (tree->group[i] < 0) {
            for (int j = 0; j < 6; j++) w->dvv[i][j] = 2.0 * w->dv[i][j];
            continue;
        }
        DK_T t[6];
        DK_FN(mcross)(V[tree->end[i]], w->S[i], t);
        for (int j = 0; j < 6; j++) w->dvv[i][j] = w->dv[i][j] + t[j];
    }
}

/* The forward pass: the kinematics, then each body's f and B. */
static void DK_FN(forward)(const dk_tree *tree, const DK_T *q, const DK_T *qd, const DK_T *qdd,
                           const double *g, DK_FN(work) *w)
{
    DK_FN(kinematics)(tree, q, qd, qdd, g, w);
    DK_T (*R)[9] = w->R, (*o)[3] = w->o, (*V)[6] = w->V, (*Acc)[6] = w->Acc;
    for (int i = 0; i < tree->nb; i++) {
        /* the inertia at the world's origin: c = R h + m o, J_O = R J R^T shifted by o */
        DK_FN(inertia) *Y = &w->Y[i];
        DK_T hr[3], RJ[9];
        /* the body's inertial, given at run time: P = [g, tau_<joint>, (m, h, J_O) per body] */
        const double *inertial = g + 3 + tree->nj + 13 * i, m = inertial[0];
        const DK_T *po = o[i];
        for (int j = 0; j < 3; j++)
            hr[j] = R[i][3 * j] * inertial[1] + R[i][3 * j + 1] * inertial[2]
                    + R[i][3 * j + 2] * inertial[3];
        SP_MATMUL(R[i], inertial + 4, RJ);
        DK_T pp = SP_DOT(po, po), ph = SP_DOT(po, hr);
        for (int a = 0; a < 3; a++)
            for (int b = a; b < 3; b++) {
                DK_T T = RJ[3 * a] * R[i][3 * b] + RJ[3 * a + 1] * R[i][3 * b + 1]
                         + RJ[3 * a + 2] * R[i][3 * b + 2]
                         - m * po[a] * po[b] - po[a] * hr[b] - hr[a] * po[b];
                if (a == b) T += m * pp + 2.0 * ph;
                Y->J[3 * a + b] = Y->J[3 * b + a] = T;
            }
        Y->m = DK_C(m);
        for (int j = 0; j < 3; j++) Y->c[j] = hr[j] + m * po[j];
        /* momentum h = Y v, force f = Y a + v x* h */
        DK_T h[6], Ya[6], vh[6];
        DK_FN(iapply)(Y, V[i], h);
        DK_FN(iapply)(Y, Acc[i], Ya);
        DK_FN(fcross)(V[i], h, vh);
        for (int j = 0; j < 6; j++) w->F[i][j] = Ya[j] + vh[j];
        /* B: L = l, A = X + X^T - (c v^T + v c^T) + 2 (v.c) 1 - [n]x, X = [w]x J_O */
        const DK_T *vl = V[i], *vw = V[i] + 3, *c = Y->c;
        DK_T X[9], cv = SP_DOT(vl, c);
        for (int b = 0; b < 3; b++) {
            DK_T col[3] = {Y->J[b], Y->J[3 + b], Y->J[6 + b]}, r[3];
            SP_CROSS(vw, col, r);
            X[b] = r[0]; X[3 + b] = r[1]; X[6 + b] = r[2];
        }
        DK_T *A = w->A[i];
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                A[3 * a + b] = X[3 * a + b] + X[3 * b + a] - c[a] * vl[b] - vl[a] * c[b];
        for (int a = 0; a < 3; a++) A[4 * a] += 2.0 * cv;
        const DK_T *n = h + 3;
        A[1] += n[2]; A[2] -= n[1]; A[3] -= n[2]; A[5] += n[0]; A[6] += n[1]; A[7] -= n[0];
        for (int j = 0; j < 3; j++) w->L[i][j] = h[j];
    }
}

/* Bc x for the subtree's B: [-2 L x x_w; A x_w] */
static inline void DK_FN(bapply)(const DK_T *L, const DK_T *A, const DK_T *x, DK_T *out)
{
    DK_T t[3];
    SP_CROSS(L, x + 3, t);
    SP_APPLY(A, x + 3, out + 3);
    for (int j = 0; j < 3; j++) out[j] = -2.0 * t[j];
}

/* The backward pass: subtree sums and each body's row (r1, r2) and column (Phi, Psi) vectors
 * (the columns, and the sums of B, only with ``columns``), tau by body into tau (nb) when
 * asked; with ``summed`` the inertias are the subtrees' already and r1 is kept (a second pass
 * at the same q). */
static void DK_FN(backward)(const dk_tree *tree, DK_FN(work) *w, DK_T *tau, int columns,
                            int summed)
{
    for (int i = tree->nb - 1; i >= 0; i--) {
        const DK_FN(inertia) *Y = &w->Y[i];
        const DK_T *S = w->S[i];
        if (!summed) DK_FN(iapply)(Y, S, w->r1[i]);
        if (tau) tau[i] = DK_FN(dot6)(S, w->F[i]);
        if (columns) {
            DK_T t[6], u[6], x[6];
            /* Bc^T S (angular part): 2 L x s_v + A^T s_w */
            DK_T *r2 = w->r2[i];
            SP_CROSS(w->L[i], S, r2);
            for (int j = 0; j < 3; j++)
                r2[j] = 2.0 * r2[j] + w->A[i][j] * S[3] + w->A[i][3 + j] * S[4]
                        + w->A[i][6 + j] * S[5];
            DK_FN(fcross)(S, w->F[i], t);
            DK_FN(iapply)(Y, w->psi[i], u);
            DK_FN(bapply)(w->L[i], w->A[i], w->dv[i], x);
            for (int j = 0; j < 6; j++) w->Phi[i][j] = t[j] + u[j] + x[j];
            DK_FN(iapply)(Y, w->dvv[i], u);
            DK_FN(bapply)(w->L[i], w->A[i], S, x);
            for (int j = 0; j < 6; j++) w->Psi[i][j] = u[j] + x[j];
        }
        if (tree->ff && i == 0)  /* the base's columns, its subtree the whole tree */
            for (int c = 0; c < 6; c++) {
                const DK_T *T = w->ffS[c];
                if (!summed) DK_FN(iapply)(Y, T, w->ffr1[c]);
                w->fftau[c] = DK_FN(dot6)(T, w->F[0]);
                if (!columns) continue;
                DK_T *r2 = w->ffr2[c];
                SP_CROSS(w->L[0], T, r2);
                for (int j = 0; j < 3; j++)
                    r2[j] = 2.0 * r2[j] + w->A[0][j] * T[3] + w->A[0][3 + j] * T[4]
                            + w->A[0][6 + j] * T[5];
            }
        int p = tree->parent[i];
        if (p >= 0) {
            if (!summed) {
                DK_FN(inertia) *P = &w->Y[p];
                P->m += Y->m;
                for (int j = 0; j < 3; j++) P->c[j] += Y->c[j];
                for (int j = 0; j < 9; j++) P->J[j] += Y->J[j];
            }
            if (columns) {
                for (int j = 0; j < 3; j++) w->L[p][j] += w->L[i][j];
                for (int j = 0; j < 9; j++) w->A[p][j] += w->A[i][j];
            }
            for (int j = 0; j < 6; j++) w->F[p][j] += w->F[i][j];
        }
    }
}

/* x += value, or x = value where ``fresh`` (pairs) */
#define DK_ADD(x, value) ((fresh) ? (void)((x) = (value)) : (void)((x) += (value)))

/* The entries of a floating base's columns c: with body k (at or below the base: row k by
 * Ic_k, Bc_k; column k by its Phi, Psi) or, k = 0, with its own columns. A translation column
 * (c < 3) is [R e_c; 0], its psi 0 and its dv = [w x R e_c; 0]: their angular halves are not
 * summed, nor d tau/dq's entries by it (0; the caller's zeros stay). Body k's entries are
 * summed into its coordinate's like every pair's: a mimic coordinate drives two bodies. */
static inline __attribute__((always_inline)) void DK_FN(base_pairs)(
    const dk_tree *tree, const DK_FN(work) *w, int k, DK_T *M, DK_T *dq, DK_T *dv, int fresh)
{
    const int n = tree->nv;
    _Pragma("GCC unroll 6")
    for (int c = 0; c < 6; c++) {
        const DK_T *S = w->ffS[c];
        const int moves = c >= 3;  /* a turn of the base, not a translation */
        if (k == 0) {
            for (int r = 0; r < 6; r++) {
                const DK_T *r1 = w->ffr1[r], *r2 = w->ffr2[r];
                if (M) M[r * n + c] = moves ? DK_FN(dot6)(r1, S) : SP_DOT(r1, S);
                if (!dq) continue;
                if (moves) {
                    dq[r * n + c] = DK_FN(dot6)(r1, w->ffpsi[c]);
                    dv[r * n + c] = DK_FN(dot6)(r1, w->ffdv[c]) + SP_DOT(r2, S + 3);
                } else {
                    dv[r * n + c] = SP_DOT(r1, w->ffdv[c]);
                }
            }
            continue;
        }
        const int ck = tree->vo + tree->coord[k];
        const double m = tree->mult[k];
        const DK_T *r1 = w->r1[k], *r2 = w->r2[k];
        if (M) {
            const DK_T mkc = m * (moves ? DK_FN(dot6)(r1, S) : SP_DOT(r1, S));
            DK_ADD(M[ck * n + c], mkc);
            DK_ADD(M[c * n + ck], mkc);
        }
        if (!dq) continue;
        if (moves) {
            DK_ADD(dq[ck * n + c], m * DK_FN(dot6)(r1, w->ffpsi[c]));
            DK_ADD(dv[ck * n + c], m * (DK_FN(dot6)(r1, w->ffdv[c]) + SP_DOT(r2, S + 3)));
            DK_ADD(dq[c * n + ck], m * DK_FN(dot6)(S, w->Phi[k]));
            DK_ADD(dv[c * n + ck], m * DK_FN(dot6)(S, w->Psi[k]));
        } else {
            DK_ADD(dv[ck * n + c], m * SP_DOT(r1, w->ffdv[c]));
            DK_ADD(dq[c * n + ck], m * SP_DOT(S, w->Phi[k]));
            DK_ADD(dv[c * n + ck], m * SP_DOT(S, w->Psi[k]));
        }
    }
}

/* M (nv x nv) when asked, or d tau/dq and d tau/dq_dot, from the pairs (k below or at j),
 * each entry scattered to the coordinates with the joints' multipliers: summed into zeros, or,
 * ``fresh`` (tree->once: each coordinate one body's, so each entry comes from one pair), set
 * once and the entries no pair writes left as they are, for a caller that reads none of them
 * (the lanes' products over the pattern, the factor along the tree): a state's zeroing and its
 * additions' loads spared. Inlined where called: M or dq, and fresh, then constants (no
 * test of them per pair). */
static inline __attribute__((always_inline)) void DK_FN(pairs)(const dk_tree *tree,
                                                              const DK_FN(work) *w, DK_T *M,
                                                              DK_T *dq, DK_T *dv, int fresh)
{
    const int n = tree->nv;
    if (M && !fresh)
        for (int j = 0; j < n * n; j++) M[j] = DK_C(0.0);
    if (dq && !fresh)
        for (int j = 0; j < n * n; j++) { dq[j] = DK_C(0.0); dv[j] = DK_C(0.0); }
    for (int e = 0; e < tree->np; e++) {
        const int k = tree->pair[e][0], j = tree->pair[e][1];
        if (tree->ff && j == 0) {
            DK_FN(base_pairs)(tree, w, k, M, dq, dv, fresh);
            continue;
        }
        const int ck = tree->vo + tree->coord[k], cj = tree->vo + tree->coord[j];
        const double kk = tree->mult[k] * tree->mult[j];
        const DK_T *r1 = w->r1[k];
        if (M) {
            const DK_T mkj = kk * DK_FN(dot6)(r1, w->S[j]);
            DK_ADD(M[ck * n + cj], mkj);
            if (k != j) DK_ADD(M[cj * n + ck], mkj);
        }
        if (!dq) continue;
        const DK_T *r2 = w->r2[k];
        DK_ADD(dq[ck * n + cj],
               kk * (DK_FN(dot6)(r1, w->psi[j]) + SP_DOT(r2, w->dv[j] + 3)));
        DK_ADD(dv[ck * n + cj],
               kk * (DK_FN(dot6)(r1, w->dvv[j]) + SP_DOT(r2, w->S[j] + 3)));
        if (k != j && tree->group[k] >= 0 && tree->group[k] == tree->group[j]) {
            /* two columns of one ball: j's turns with k's (the body's axes), as a row below */
            DK_ADD(dq[cj * n + ck], kk * (DK_FN(dot6)(w->r1[j], w->psi[k])
                                          + SP_DOT(w->r2[j], w->dv[k] + 3)));
            DK_ADD(dv[cj * n + ck], kk * DK_FN(dot6)(w->S[j], w->Psi[k]));
        } else if (k != j) {
            DK_ADD(dq[cj * n + ck], kk * DK_FN(dot6)(w->S[j], w->Phi[k]));
            DK_ADD(dv[cj * n + ck], kk * DK_FN(dot6)(w->S[j], w->Psi[k]));
        }
    }
}

/* (d tau/dq, d tau/dq_dot) at one state (lane); g (3) the gravity vector (m/s^2); ``space``
 * the thread's work block. */
static void DK_FN(inverse)(const dk_tree *tree, DK_T *space, const DK_T *q, const DK_T *qd,
                           const DK_T *qdd, const double *g, DK_T *dq, DK_T *dv)
{
    DK_FN(work) w;
    DK_FN(carve)(tree, space, &w);
    DK_FN(forward)(tree, q, qd, qdd, g, &w);
    DK_FN(backward)(tree, &w, NULL, 1, 0);
    DK_FN(pairs)(tree, &w, NULL, dq, dv, 0);
}

/* DK_FACTOR: derivatives_factor.c, here (M's factor, its solve, M^-1, the products) */

/* (d q_ddot/dq, d q_ddot/dq_dot, M^-1) at one state (lane); P = [g (3), tau_<joint> (nj), ...];
 * the lanes (bits) where M is not positive definite */
static int DK_FN(forward_derivatives)(const dk_tree *tree, DK_T *space, const DK_T *q,
                                      const DK_T *qd, const DK_T *tau, const double *P,
                                      DK_T *aq, DK_T *av, DK_T *Minv)
{
    DK_FN(work) w;
    DK_FN(carve)(tree, space, &w);
    const int nb = tree->nb, nv = tree->nv, vo = tree->vo, ff = tree->ff;
    DK_T *M = w.M, *dq = w.dq, *dv = w.dv_, *taub = w.taub, *b = w.b, *zero = w.zero;
    DK_T *diagonal = w.diagonal, (*da)[6] = w.da;
    for (int j = 0; j < nv; j++) zero[j] = DK_C(0.0);
    /* q_ddot = M^-1 (tau + tau_p - b), b from Newton-Euler at q_ddot = 0 */
    DK_FN(forward)(tree, q, qd, zero, P, &w);
    /* the bodies' own f and inertia: the first backward pass sums them in place (not B) */
    memcpy(w.F0, w.F, (size_t)nb * sizeof w.F[0]);
    memcpy(w.Y0, w.Y, (size_t)nb * sizeof w.Y[0]);
    DK_FN(backward)(tree, &w, taub, 0, 0);
    if (tree->ltdl) DK_FN(pairs)(tree, &w, M, NULL, NULL, 1);
    else DK_FN(pairs)(tree, &w, M, NULL, NULL, 0);
    for (int j = 0; j < nv; j++) b[j] = tau[j];
    for (int j = 0; j < tree->nj; j++) b[vo + j] += P[3 + j];
    for (int i = ff; i < nb; i++) b[vo + tree->coord[i]] -= tree->mult[i] * taub[i];
    for (int c = 0; c < 6 * ff; c++) b[c] -= w.fftau[c];
    int failed;
    if (tree->ltdl) {
        failed = DK_FN(ltdl_factor)(tree, M, diagonal);
        DK_FN(ltdl_solve)(tree, M, diagonal, b);
    } else {
        failed = DK_FN(factor)(nv, M, diagonal);
        DK_FN(solve)(nv, M, diagonal, b);
    }
    /* at q_ddot = b: each body's acceleration grows by da = da_p + S theta_ddot, so psi by
       da_p x S and f by Y da (the rest of the forward pass does not see q_ddot) */
    for (int i = 0; i < nb; i++) {
        const int p = tree->parent[i];
        const DK_T accel = ff && i == 0 ? DK_C(0.0) : tree->mult[i] * b[vo + tree->coord[i]];
        DK_T t[6], u[6];
        if (p >= 0) {  /* psi from its motion's (a ball column's: the ball's parent's) */
            const int mp = tree->motion[i];
            if (mp >= 0) {
                DK_FN(mcross)(da[mp], w.S[i], t);
                for (int j = 0; j < 6; j++) w.psi[i][j] += t[j];
            }
            for (int j = 0; j < 6; j++) da[i][j] = da[p][j];
        } else {
            for (int j = 0; j < 6; j++) da[i][j] = DK_C(0.0);
        }
        for (int j = 0; j < 6; j++) da[i][j] += w.S[i][j] * accel;
        if (ff && i == 0)
            for (int c = 0; c < 6; c++)
                for (int j = 0; j < 6; j++) da[0][j] += w.ffS[c][j] * b[c];
        DK_FN(iapply)(&w.Y0[i], da[i], u);
        for (int j = 0; j < 6; j++) w.F[i][j] = w.F0[i][j] + u[j];
    }
    /* the second pass: the subtrees' inertias and r1 as they are (the same q) */
    DK_FN(backward)(tree, &w, NULL, 1, 1);
    const int sparse = tree->sparse && DK_ON_LANES;
    if (sparse && tree->once) DK_FN(pairs)(tree, &w, NULL, dq, dv, 1);
    else DK_FN(pairs)(tree, &w, NULL, dq, dv, 0);
    if (tree->ltdl)
        DK_FN(ltdl_inverse)(tree, M, diagonal, w.X, Minv);
    else
        DK_FN(inverse_from_factor)(nv, M, diagonal, w.X, Minv);
    /* a floating base's translation leaves tau as it is: d tau/dq's first three columns 0 */
    DK_FN(minus_product)(tree, sparse, Minv, dq, aq, 3 * ff);
    DK_FN(minus_product)(tree, sparse, Minv, dv, av, 0);
    return failed;
}
/* DK_CORE_END */
