/* The compact tree kernel's forward dynamics, after tree_kernel.c (its records, scratch and
   helpers): the articulated-body algorithm (a ball joint's three columns and a free flyer's
   below the root six among its joints), a floating base's acceleration, and M^-1 (tau - b) by
   Cholesky where mimic joints drive several bodies from one coordinate. Units SI. */

/* loops of a few iterations each (a joint's columns, a small arm's unknowns) left unvectorized:
   GCC's vector loops with their prologues and remainders cost the Panda's forward dynamics a
   tenth of its time (its L D L^T half, by ABA a tenth) */
#if defined(__GNUC__) && !defined(__clang__)
#define TK_SHORT_LOOPS __attribute__((optimize("no-tree-loop-vectorize")))
#else
#define TK_SHORT_LOOPS
#endif

/* The floating base's spatial acceleration a = IA^-1 (tau - pA) (angular, linear; S = 1, its
   articulated inertia IA after every child's share, the ground's upward g in a: what its
   children read), and q_ddot[:6] = (a_v - R^T up, a_w), linear first as v; -1 where IA is not
   positive definite. */
/* L L^T = A (m x m, row-major, stride ``stride``) into L's lower triangle (m x m, stride m);
   the failed mask where A is not positive definite */
static inline TK_MASK TK_FN(factor)(const TK_T *A, int stride, int m, TK_T *L)
{
    TK_MASK bad = TK_FINE;
    for (int j = 0; j < m; j++) {
        TK_T d = A[stride * j + j];
        for (int k = 0; k < j; k++) d -= L[m * j + k] * L[m * j + k];
        bad |= TK_NOT_POSITIVE(d);
        TK_GIVE_UP(bad);
        L[m * j + j] = d = TK_SQRT(d);
        for (int i = j + 1; i < m; i++) {
            TK_T s = A[stride * i + j];
            for (int k = 0; k < j; k++) s -= L[m * i + k] * L[m * j + k];
            L[m * i + j] = s / d;
        }
    }
    return bad;
}

/* x = (L L^T)^-1 x in place (L: TK_FN(factor)'s, m x m) */
static inline void TK_FN(solve)(const TK_T *L, int m, TK_T *x)
{
    for (int i = 0; i < m; i++) {
        for (int k = 0; k < i; k++) x[i] -= L[m * i + k] * x[k];
        x[i] /= L[m * i + i];
    }
    for (int i = m - 1; i >= 0; i--) {
        for (int k = i + 1; k < m; k++) x[i] -= L[m * k + i] * x[k];
        x[i] /= L[m * i + i];
    }
}

static TK_MASK TK_FN(free_acceleration)(const tk_tree *t, const TK_T *IA, const TK_T *pA,
                                         const TK_T *R, const TK_T *tau, TK_T *a, TK_T *qdd)
{
    TK_T L[36], gb[3];
    const double up[3] = {-t->g[0], -t->g[1], -t->g[2]};
    for (int r = 0; r < 3; r++) {  /* tau is (force, moment), a's rows (moment, force) */
        a[r] = tau[3 + r] - pA[r];
        a[3 + r] = tau[r] - pA[3 + r];
    }
    TK_MASK bad = TK_FN(factor)(IA, 6, 6, L);
    TK_GIVE_UP(bad);
    TK_FN(solve)(L, 6, a);
    SP_APPLY_T(R, up, gb);
    for (int r = 0; r < 3; r++) { qdd[r] = a[3 + r] - gb[r]; qdd[3 + r] = a[r]; }
    return bad;
}

/* The parent's share of body i: its articulated inertia Ia and bias pv (angular, linear, in
   the body's axes) moved into the parent's axes and added to the parent's IA, pA. */
static void TK_FN(into_parent)(const tk_tree *t, TK_T *restrict W, int i, const TK_T *Ia,
                               const TK_T *pv)
{
    const int parent = (int)t->body[i * TK_STRIDE + TK_PARENT];
    const TK_T *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P;
    TK_T *PI = W + parent * TW_STRIDE + TA_IA, *Pp = W + parent * TW_STRIDE + TA_PA;
    /* blocks A, B, C' of Ia rotated into parent axes, then shifted by p (P = [p]x):
       A + P B^T - B P - P C P, B + P C, C */
    TK_T Ab[9], Bb[9], Cb[9], Ar[9], Br[9], Cr[9];
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++) {
            Ab[3 * r + k] = Ia[6 * r + k];
            Bb[3 * r + k] = Ia[6 * r + k + 3];
            Cb[3 * r + k] = Ia[6 * (r + 3) + k + 3];
        }
    TK_FN(sandwich)(R, Ab, Ar);
    TK_FN(sandwich)(R, Bb, Br);
    TK_FN(sandwich)(R, Cb, Cr);
    TK_T PC[9], BP[9], PCP[9], PBt[9];
    for (int k = 0; k < 3; k++) {  /* column k of P X is p x (column k of X) */
        TK_T col[3], out[3];
        for (int r = 0; r < 3; r++) col[r] = Cr[3 * r + k];
        SP_CROSS(p, col, out);
        for (int r = 0; r < 3; r++) PC[3 * r + k] = out[r];
        for (int r = 0; r < 3; r++) col[r] = Br[3 * k + r];  /* column k of B^T */
        SP_CROSS(p, col, out);
        for (int r = 0; r < 3; r++) PBt[3 * r + k] = out[r];
    }
    for (int r = 0; r < 3; r++) {  /* row r of X P is -(p x row r of X) ... = row x p */
        TK_T row[3], out[3];
        for (int k = 0; k < 3; k++) row[k] = Br[3 * r + k];
        SP_CROSS(row, p, out);
        for (int k = 0; k < 3; k++) BP[3 * r + k] = out[k];
        for (int k = 0; k < 3; k++) row[k] = PC[3 * r + k];
        SP_CROSS(row, p, out);
        for (int k = 0; k < 3; k++) PCP[3 * r + k] = out[k];
    }
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++) {
            const TK_T a = Ar[3 * r + k] + PBt[3 * r + k] - BP[3 * r + k] - PCP[3 * r + k];
            const TK_T bb = Br[3 * r + k] + PC[3 * r + k];
            PI[6 * r + k] += a;
            PI[6 * r + k + 3] += bb;
            PI[6 * (k + 3) + r] += bb;
            PI[6 * (r + 3) + k + 3] += Cr[3 * r + k];
        }
    TK_T F[3], N[3], x[3];
    SP_APPLY(R, pv + 3, F);
    SP_APPLY(R, pv, N);
    SP_CROSS(p, F, x);
    for (int r = 0; r < 3; r++) { Pp[r] += N[r] + x[r]; Pp[3 + r] += F[r]; }
}

/* A ball's (S = [1; 0]: its three turns) or a free flyer's below the root (S: its twist,
   linear then angular, in (angular, linear) rows) backward step: U = IA S, D = S^T U,
   u = tau - S^T pA; the parent gets Ia = IA - U D^-1 U^T, pA + Ia c + U D^-1 u. A flyer's
   Ia is 0 and its pv its own applied wrench: a free body hands its parent nothing else. */
static TK_MASK TK_FN(many_backward)(const tk_tree *t, TK_T *restrict W, int i,
                                    const TK_T *restrict tau)
{
    const double *b = t->body + i * TK_STRIDE;
    TK_T *w = W + i * TW_STRIDE, *In = w + TA_IA, *pa = w + TA_PA;
    const int c = (int)b[TK_COORD], parent = (int)b[TK_PARENT];
    TK_MASK bad = TK_FINE;
    if (TK_FLYER(b)) {  /* IA x = S (tau + tau0) - pA: the body's acceleration, solved later */
        TK_T rhs[6], L[36];
        for (int r = 0; r < 3; r++) {
            rhs[r] = tau[t->bv + c + 3 + r] + t->tau0[c + 3 + r] - pa[r];
            rhs[3 + r] = tau[t->bv + c + r] + t->tau0[c + r] - pa[3 + r];
        }
        bad |= TK_FN(factor)(In, 6, 6, L);
        TK_GIVE_UP(bad);
        if (parent >= 0) {
            TK_T zero[36], pv[6];
            for (int k = 0; k < 36; k++) zero[k] = TK_C(0.0);
            for (int r = 0; r < 6; r++) pv[r] = rhs[r] + pa[r];
            TK_FN(into_parent)(t, W, i, zero, pv);
        }
        for (int k = 0; k < 36; k++) In[k] = L[k];  /* its factor, then its right side */
        for (int r = 0; r < 6; r++) w[TA_U + r] = rhs[r];
        return bad;
    }
    TK_T U[18], L[9], Dinv[9], u[3];  /* U (6 x 3): IA's first three columns */
    for (int r = 0; r < 6; r++)
        for (int k = 0; k < 3; k++) U[3 * r + k] = In[6 * r + k];
    bad |= TK_FN(factor)(In, 6, 3, L);
    TK_GIVE_UP(bad);
    for (int k = 0; k < 3; k++) {  /* D^-1 column by column */
        TK_T e[3] = {TK_C(0.0), TK_C(0.0), TK_C(0.0)};
        e[k] = TK_C(1.0);
        TK_FN(solve)(L, 3, e);
        for (int r = 0; r < 3; r++) Dinv[3 * r + k] = e[r];
    }
    for (int k = 0; k < 3; k++) u[k] = tau[t->bv + c + k] + t->tau0[c + k] - pa[k];
    if (parent >= 0) {
        TK_T UD[18], Ia[36], pv[6], Du[3];  /* U D^-1, then IA - U D^-1 U^T */
        for (int r = 0; r < 6; r++)
            for (int k = 0; k < 3; k++)
                UD[3 * r + k] = U[3 * r] * Dinv[k] + U[3 * r + 1] * Dinv[3 + k]
                                + U[3 * r + 2] * Dinv[6 + k];
        for (int r = 0; r < 6; r++)
            for (int k = 0; k < 6; k++)
                Ia[6 * r + k] = In[6 * r + k] - (UD[3 * r] * U[3 * k] + UD[3 * r + 1] * U[3 * k + 1]
                                                 + UD[3 * r + 2] * U[3 * k + 2]);
        SP_APPLY(Dinv, u, Du);
        const TK_T *cc = w + TA_C;
        for (int r = 0; r < 6; r++) {
            TK_T s = pa[r] + U[3 * r] * Du[0] + U[3 * r + 1] * Du[1] + U[3 * r + 2] * Du[2];
            for (int k = 0; k < 6; k++) s += Ia[6 * r + k] * cc[k];
            pv[r] = s;
        }
        TK_FN(into_parent)(t, W, i, Ia, pv);
    }
    for (int k = 0; k < 9; k++) In[k] = Dinv[k];  /* D^-1, u, U where IA was */
    for (int k = 0; k < 3; k++) In[9 + k] = u[k];
    for (int k = 0; k < 18; k++) In[12 + k] = U[k];
    return bad;
}

/* A ball's or a flyer's below the root accelerations from its body's a = X a_p + c (in
   W's A): a ball's q_ddot = D^-1 (u - U^T a), a += S q_ddot; a flyer's body acceleration x
   solves IA x = S tau - pA outright, q_ddot = S^T (x - a), a = x. */
static void TK_FN(many_forward)(const tk_tree *t, TK_T *restrict W, int i, TK_T *restrict qdd)
{
    const double *b = t->body + i * TK_STRIDE;
    TK_T *w = W + i * TW_STRIDE, *ac = w + TA_A, *stored = w + TA_IA;
    const int c = t->bv + (int)b[TK_COORD];
    if (TK_FLYER(b)) {
        TK_T x[6];
        for (int r = 0; r < 6; r++) x[r] = w[TA_U + r];
        TK_FN(solve)(stored, 6, x);
        for (int r = 0; r < 3; r++) {  /* v's order: linear, then angular */
            qdd[c + r] = x[3 + r] - ac[3 + r];
            qdd[c + 3 + r] = x[r] - ac[r];
        }
        for (int r = 0; r < 6; r++) ac[r] = x[r];
        return;
    }
    const TK_T *Dinv = stored, *u = stored + 9, *U = stored + 12;
    TK_T e[3], x[3];
    for (int k = 0; k < 3; k++) {
        TK_T s = u[k];
        for (int r = 0; r < 6; r++) s -= U[3 * r + k] * ac[r];
        e[k] = s;
    }
    SP_APPLY(Dinv, e, x);
    for (int k = 0; k < 3; k++) {
        qdd[c + k] = x[k];
        ac[k] += x[k];
    }
}

/* The articulated-body algorithm (no mimic joints: each coordinate drives one body); -1 where
   a joint's articulated inertia is not positive (a massless branch). Spatial vectors are
   (angular, linear) at the body's origin in its axes. */
TK_SHORT_LOOPS static TK_MASK TK_FN(forward_aba)(const tk_tree *t, const TK_T *restrict q,
                                  const TK_T *restrict v, const TK_T *restrict tau,
                                  TK_T *restrict W, TK_T *restrict qdd)
{
    TK_MASK bad = TK_FINE;
    TK_FN(place)(t, q, W);
    enum { V = TA_V, C = TA_C, A = TA_A, IA = TA_IA, PA = TA_PA, U = TA_U, D = TA_D, UU = TA_UU };
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        TK_T *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P;
        double sw, sv;
        TK_T x[3];
        const int parent = (int)b[TK_PARENT];
        tk_subspace(b, &sw, &sv);  /* zero for the free flyer: its motion is v[:6] itself */
        const int many = TK_BALL(b) || TK_FLYER(b);  /* several columns: the rates below */
        const TK_T rate = TK_FREE(b) || many ? TK_C(0.0) : v[t->bv + (int)b[TK_COORD]];
        TK_T *vw = w + V, *vv = w + V + 3;
        if (TK_FREE(b)) {
            for (int r = 0; r < 3; r++) { vw[r] = v[3 + r]; vv[r] = v[r]; }
        } else if (parent < 0) {
            for (int r = 0; r < 3; r++) vw[r] = vv[r] = TK_C(0.0);
        } else {
            const TK_T *pv = W + parent * TW_STRIDE + V;
            SP_CROSS(pv, p, x);
            for (int r = 0; r < 3; r++) x[r] += pv[3 + r];
            SP_APPLY_T(R, pv, vw);
            SP_APPLY_T(R, x, vv);
        }
        /* c = v x (S rate), with the parent's part: (w x s_w, w x s_v + v_l x s_w) rate, S
           about z */
        TK_T *cw = w + C, *cv = w + C + 3, y[3];
        cw[0] = vw[1] * sw * rate;
        cw[1] = -(vw[0] * sw) * rate;
        cw[2] = TK_C(0.0);
        cv[0] = (vw[1] * sv + vv[1] * sw) * rate;
        cv[1] = -(vw[0] * sv + vv[0] * sw) * rate;
        cv[2] = TK_C(0.0);
        vw[2] += rate * sw;
        vv[2] += rate * sv;
        if (many) {  /* the twist (w_r, v_r) in its axes: c = v_p x it, then v += it */
            const TK_T *vr = v + t->bv + (int)b[TK_COORD], *wr = TK_BALL(b) ? vr : vr + 3;
            TK_T z[3];
            SP_CROSS(vw, wr, cw);
            SP_CROSS(vv, wr, cv);
            if (TK_FLYER(b)) {
                SP_CROSS(vw, vr, z);
                for (int r = 0; r < 3; r++) { cv[r] += z[r]; vv[r] += vr[r]; }
            }
            for (int r = 0; r < 3; r++) vw[r] += wr[r];
        }
        /* IA = I, pA = v x* I v: I v = (J w + h x v, m v + w x h) */
        const double m = b[TK_MASS], *h = b + TK_H, *J = b + TK_J;
        TK_T *In = w + IA, *pa = w + PA, Iw[3], Iv[3], z[3];
        for (int r = 0; r < 3; r++)
            for (int col = 0; col < 3; col++) {
                In[6 * r + col] = TK_C(J[3 * r + col]);
                In[6 * (r + 3) + col + 3] = TK_C(r == col ? m : 0.0);
            }
        /* [[J, [h]x], [[h]x^T, m 1]] */
        const double H[9] = {0.0, -h[2], h[1], h[2], 0.0, -h[0], -h[1], h[0], 0.0};
        for (int r = 0; r < 3; r++)
            for (int col = 0; col < 3; col++) {
                In[6 * r + col + 3] = TK_C(H[3 * r + col]);
                In[6 * (r + 3) + col] = TK_C(H[3 * col + r]);
            }
        SP_APPLY(J, vw, Iw);
        SP_CROSS(h, vv, x);
        for (int r = 0; r < 3; r++) Iw[r] += x[r];
        SP_CROSS(vw, h, x);
        for (int r = 0; r < 3; r++) Iv[r] = m * vv[r] + x[r];
        /* v x* (n, f) = (w x n + v x f, w x f) */
        SP_CROSS(vw, Iw, x);
        SP_CROSS(vv, Iv, z);
        SP_CROSS(vw, Iv, y);
        for (int r = 0; r < 3; r++) { pa[r] = x[r] + z[r]; pa[3 + r] = y[r]; }
    }
    for (int i = t->nb - 1; i >= 0; i--) {
        const double *b = t->body + i * TK_STRIDE;
        TK_T *w = W + i * TW_STRIDE, *In = w + IA, *pa = w + PA, *U_ = w + U;
        double sw, sv;
        if (TK_FREE(b)) continue;  /* the root: solved outright below */
        if (TK_BALL(b) || TK_FLYER(b)) {
            bad |= TK_FN(many_backward)(t, W, i, tau);
            TK_GIVE_UP(bad);
            continue;
        }
        tk_subspace(b, &sw, &sv);  /* S = (0, 0, sw, 0, 0, sv) */
        for (int r = 0; r < 6; r++) U_[r] = In[6 * r + 2] * sw + In[6 * r + 5] * sv;
        const TK_T d = sw * U_[2] + sv * U_[5], su = sw * pa[2] + sv * pa[5];
        const int c = (int)b[TK_COORD];
        const TK_T u = tau[t->bv + c] + t->tau0[c] - su;
        bad |= TK_NOT_POSITIVE(d);
        TK_GIVE_UP(bad);
        w[D] = d;
        w[UU] = u;
        const int parent = (int)b[TK_PARENT];
        if (parent < 0) continue;
        /* Ia = IA - U U^T / D, pa' = pA + Ia c + U u / D, then X^T into the parent */
        TK_T Ia[36], pv[6];
        const TK_T inv = 1.0 / d;
        for (int r = 0; r < 6; r++)
            for (int k = 0; k < 6; k++) Ia[6 * r + k] = In[6 * r + k] - U_[r] * U_[k] * inv;
        const TK_T *cc = w + C;
        for (int r = 0; r < 6; r++) {
            TK_T s = pa[r] + U_[r] * u * inv;
            for (int k = 0; k < 6; k++) s += Ia[6 * r + k] * cc[k];
            pv[r] = s;
        }
        TK_FN(into_parent)(t, W, i, Ia, pv);
    }
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        TK_T *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P, *ac = w + A;
        const int parent = (int)b[TK_PARENT];
        TK_T x[3];
        double sw, sv;
        if (TK_FREE(b)) {
            bad |= TK_FN(free_acceleration)(t, w + IA, w + PA, R, tau, ac, qdd);
            TK_GIVE_UP(bad);
            continue;
        }
        if (parent < 0) {  /* the ground accelerates up by g: (0, -g) */
            const double up[3] = {-t->g[0], -t->g[1], -t->g[2]};
            for (int r = 0; r < 3; r++) ac[r] = TK_C(0.0);
            SP_APPLY_T(R, up, ac + 3);
        } else {
            const TK_T *pa = W + parent * TW_STRIDE + A;
            SP_CROSS(pa, p, x);
            for (int r = 0; r < 3; r++) x[r] += pa[3 + r];
            SP_APPLY_T(R, pa, ac);
            SP_APPLY_T(R, x, ac + 3);
        }
        for (int r = 0; r < 6; r++) ac[r] += w[C + r];
        if (TK_BALL(b) || TK_FLYER(b)) {
            TK_FN(many_forward)(t, W, i, qdd);
            continue;
        }
        tk_subspace(b, &sw, &sv);
        TK_T s = TK_C(0.0);
        for (int r = 0; r < 6; r++) s += w[U + r] * ac[r];
        const TK_T x_dd = (w[UU] - s) / w[D];
        qdd[t->bv + (int)b[TK_COORD]] = x_dd;
        ac[2] += sw * x_dd;
        ac[5] += sv * x_dd;
    }
    for (int i = 0; i < t->nv; i++)
        bad |= TK_NOT_FINITE(qdd[i]);
    return bad;
}

/* q_ddot = M^-1 (tau - b) by Cholesky (a tree with mimic joints); -1 where M is not positive
   definite. L needs n * n numbers (TK_Ts). */
TK_SHORT_LOOPS static TK_MASK TK_FN(forward_cholesky)(const tk_tree *t, const TK_T *restrict q,
                                       const TK_T *restrict v, const TK_T *restrict tau,
                                       TK_T *restrict W, TK_T *restrict L,
                                       TK_T *restrict qdd)
{
    TK_MASK bad = TK_FINE;
    const int n = t->nv;
    TK_FN(place)(t, q, W);  /* once: the mass matrix leaves RNEA's placements as they are */
    TK_FN(mass_placed)(t, W, L);
    TK_FN(inverse_placed)(t, v, NULL, W, qdd);
    for (int i = 0; i < n; i++) qdd[i] = tau[i] - qdd[i];
    /* M = L D L^T, L unit lower, column by column, each one's update of the rest at once and
       of L y = x with it: one reciprocal a column and no square root (the roots and divisions
       on the factor's chain were a fifteenth of the Panda's forward dynamics) */
    TK_T inverse[n], column[n];
    for (int j = 0; j < n; j++) {
        const TK_T d = L[j * n + j];
        bad |= TK_NOT_POSITIVE(d);
        TK_GIVE_UP(bad);
        inverse[j] = 1.0 / d;
        for (int i = j + 1; i < n; i++) {
            column[i] = L[i * n + j];  /* l_ij d_j */
            const TK_T l = column[i] * inverse[j];
            L[i * n + j] = l;
            qdd[i] -= l * qdd[j];  /* y_j is whole: every column before it is done */
        }
        for (int i = j + 1; i < n; i++) {
            const TK_T l = L[i * n + j];
            for (int k = j + 1; k <= i; k++) L[i * n + k] -= l * column[k];
        }
    }
    for (int i = 0; i < n; i++) qdd[i] *= inverse[i];
    for (int i = n - 1; i >= 0; i--)  /* L^T x = D^-1 y */
        for (int k = 0; k < i; k++) qdd[k] -= L[i * n + k] * qdd[i];
    for (int i = 0; i < n; i++)
        bad |= TK_NOT_FINITE(qdd[i]);
    return bad;
}
