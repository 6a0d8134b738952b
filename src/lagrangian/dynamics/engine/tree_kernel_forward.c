/* The compact tree kernel's forward dynamics, after tree_kernel.c (its records, scratch and
   helpers): the articulated-body algorithm, a floating base's acceleration, and M^-1 (tau - b)
   by Cholesky where mimic joints drive several bodies from one coordinate or a ball joint
   turns a body, and a ball joint's three columns of M, a free flyer's below the root six.
   Units SI. */

/* The floating base's spatial acceleration a = IA^-1 (tau - pA) (angular, linear; S = 1, its
   articulated inertia IA after every child's share, the ground's upward g in a: what its
   children read), and q_ddot[:6] = (a_v - R^T up, a_w), linear first as v; -1 where IA is not
   positive definite. */
static TK_MASK TK_FN(free_acceleration)(const tk_tree *t, const TK_T *IA, const TK_T *pA,
                                         const TK_T *R, const TK_T *tau, TK_T *a, TK_T *qdd)
{
    TK_T L[36], gb[3];
    const double up[3] = {-t->g[0], -t->g[1], -t->g[2]};
    TK_MASK bad = TK_FINE;
    for (int r = 0; r < 3; r++) {  /* tau is (force, moment), a's rows (moment, force) */
        a[r] = tau[3 + r] - pA[r];
        a[3 + r] = tau[r] - pA[3 + r];
    }
    for (int j = 0; j < 6; j++) {
        TK_T d = IA[6 * j + j];
        for (int k = 0; k < j; k++) d -= L[6 * j + k] * L[6 * j + k];
        bad |= TK_NOT_POSITIVE(d);
        TK_GIVE_UP(bad);
        L[6 * j + j] = d = TK_SQRT(d);
        for (int i = j + 1; i < 6; i++) {
            TK_T s = IA[6 * i + j];
            for (int k = 0; k < j; k++) s -= L[6 * i + k] * L[6 * j + k];
            L[6 * i + j] = s / d;
        }
    }
    for (int i = 0; i < 6; i++) {
        for (int k = 0; k < i; k++) a[i] -= L[6 * i + k] * a[k];
        a[i] /= L[6 * i + i];
    }
    for (int i = 5; i >= 0; i--) {
        for (int k = i + 1; k < 6; k++) a[i] -= L[6 * k + i] * a[k];
        a[i] /= L[6 * i + i];
    }
    SP_APPLY_T(R, up, gb);
    for (int r = 0; r < 3; r++) { qdd[r] = a[3 + r] - gb[r]; qdd[3 + r] = a[r]; }
    return bad;
}

/* The articulated-body algorithm (no mimic joints: each coordinate drives one body); -1 where
   a joint's articulated inertia is not positive (a massless branch). Spatial vectors are
   (angular, linear) at the body's origin in its axes. */
static TK_MASK TK_FN(forward_aba)(const tk_tree *t, const TK_T *restrict q,
                                  const TK_T *restrict v, const TK_T *restrict tau,
                                  TK_T *restrict W, TK_T *restrict qdd)
{
    TK_MASK bad = TK_FINE;
    TK_FN(place)(t, q, W);
    /* scratch per body after R, p: V 6, C 6, A 6, IA 36, PA 6, U 6, D, u */
    enum { V = TW_A, C = V + 6, A = C + 6, IA = A + 6, PA = IA + 36, U = PA + 6, D = U + 6,
           UU = D + 1 };
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        TK_T *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P;
        double sw, sv;
        TK_T x[3];
        const int parent = (int)b[TK_PARENT];
        tk_subspace(b, &sw, &sv);  /* zero for the free flyer: its motion is v[:6] itself */
        const TK_T rate = TK_FREE(b) ? TK_C(0.0) : v[t->bv + (int)b[TK_COORD]];
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
        const TK_T *R = w + TW_R, *p = w + TW_P;
        TK_T *PI = W + parent * TW_STRIDE + IA, *Pp = W + parent * TW_STRIDE + PA;
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
static TK_MASK TK_FN(forward_cholesky)(const tk_tree *t, const TK_T *restrict q,
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
    for (int j = 0; j < n; j++) {
        TK_T d = L[j * n + j];
        for (int k = 0; k < j; k++) d -= L[j * n + k] * L[j * n + k];
        bad |= TK_NOT_POSITIVE(d);
        TK_GIVE_UP(bad);
        d = TK_SQRT(d);
        L[j * n + j] = d;
        const TK_T inv = 1.0 / d;
        for (int i = j + 1; i < n; i++) {
            TK_T s = L[i * n + j];
            for (int k = 0; k < j; k++) s -= L[i * n + k] * L[j * n + k];
            L[i * n + j] = s * inv;
        }
    }
    for (int i = 0; i < n; i++) {
        TK_T s = qdd[i];
        for (int k = 0; k < i; k++) s -= L[i * n + k] * qdd[k];
        qdd[i] = s / L[i * n + i];
    }
    for (int i = n - 1; i >= 0; i--) {
        TK_T s = qdd[i];
        for (int k = i + 1; k < n; k++) s -= L[k * n + i] * qdd[k];
        qdd[i] = s / L[i * n + i];
    }
    for (int i = 0; i < n; i++)
        bad |= TK_NOT_FINITE(qdd[i]);
    return bad;
}
