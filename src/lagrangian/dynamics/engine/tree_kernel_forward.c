/* The compact tree kernel's forward dynamics, after tree_kernel.c (its records, scratch and
   helpers): the articulated-body algorithm, a floating base's acceleration, and M^-1 (tau - b)
   by Cholesky where mimic joints drive several bodies from one coordinate. Units SI. */

/* The floating base's spatial acceleration a = IA^-1 (tau - pA) (angular, linear; S = 1, its
   articulated inertia IA after every child's share, the ground's upward g in a: what its
   children read), and q_ddot[:6] = (a_v - R^T up, a_w), linear first as v; -1 where IA is not
   positive definite. */
static int tk_free_acceleration(const tk_tree *t, const double *IA, const double *pA,
                                const double *R, const double *tau, double *a, double *qdd)
{
    double L[36], up[3] = {-t->g[0], -t->g[1], -t->g[2]}, gb[3];
    for (int r = 0; r < 3; r++) {  /* tau is (force, moment), a's rows (moment, force) */
        a[r] = tau[3 + r] - pA[r];
        a[3 + r] = tau[r] - pA[3 + r];
    }
    for (int j = 0; j < 6; j++) {
        double d = IA[6 * j + j];
        for (int k = 0; k < j; k++) d -= L[6 * j + k] * L[6 * j + k];
        if (!(d > 0.0)) return -1;
        L[6 * j + j] = d = sqrt(d);
        for (int i = j + 1; i < 6; i++) {
            double s = IA[6 * i + j];
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
    tk_apply_t(R, up, gb);
    for (int r = 0; r < 3; r++) { qdd[r] = a[3 + r] - gb[r]; qdd[3 + r] = a[r]; }
    return 0;
}

/* The articulated-body algorithm (no mimic joints: each coordinate drives one body); -1 where
   a joint's articulated inertia is not positive (a massless branch). Spatial vectors are
   (angular, linear) at the body's origin in its axes. */
static int tk_forward_aba(const tk_tree *t, const double *q, const double *v,
                          const double *tau, double *W, double *qdd)
{
    tk_place(t, q, W);
    /* scratch per body after R, p: V 6, C 6, A 6, IA 36, PA 6, U 6, D, u */
    enum { V = TW_A, C = V + 6, A = C + 6, IA = A + 6, PA = IA + 36, U = PA + 6, D = U + 6,
           UU = D + 1 };
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        double *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P;
        double sw[3], sv[3], x[3];
        const int parent = (int)b[TK_PARENT];
        tk_subspace(b, sw, sv);  /* zero for the free flyer: its motion is v[:6] itself */
        const double rate = TK_FREE(b) ? 0.0 : v[t->bv + (int)b[TK_COORD]];
        double *vw = w + V, *vv = w + V + 3;
        if (TK_FREE(b)) {
            for (int r = 0; r < 3; r++) { vw[r] = v[3 + r]; vv[r] = v[r]; }
        } else if (parent < 0) {
            for (int r = 0; r < 3; r++) vw[r] = vv[r] = 0.0;
        } else {
            const double *pv = W + parent * TW_STRIDE + V;
            tk_cross(pv, p, x);
            for (int r = 0; r < 3; r++) x[r] += pv[3 + r];
            tk_apply_t(R, pv, vw);
            tk_apply_t(R, x, vv);
        }
        /* c = v x (S rate), with the parent's part: (w x s_w, w x s_v + v_l x s_w) rate */
        double *cw = w + C, *cv = w + C + 3, y[3];
        tk_cross(vw, sw, cw);
        tk_cross(vw, sv, x);
        tk_cross(vv, sw, y);
        for (int r = 0; r < 3; r++) {
            cw[r] *= rate;
            cv[r] = (x[r] + y[r]) * rate;
            vw[r] += rate * sw[r];
            vv[r] += rate * sv[r];
        }
        /* IA = I, pA = v x* I v: I v = (J w + h x v, m v + w x h) */
        const double m = b[TK_MASS], *h = b + TK_H, *J = b + TK_J;
        double *In = w + IA, *pa = w + PA, Iw[3], Iv[3], z[3];
        for (int r = 0; r < 3; r++)
            for (int col = 0; col < 3; col++) {
                In[6 * r + col] = J[3 * r + col];
                In[6 * (r + 3) + col + 3] = r == col ? m : 0.0;
            }
        /* [[J, [h]x], [[h]x^T, m 1]] */
        const double H[9] = {0.0, -h[2], h[1], h[2], 0.0, -h[0], -h[1], h[0], 0.0};
        for (int r = 0; r < 3; r++)
            for (int col = 0; col < 3; col++) {
                In[6 * r + col + 3] = H[3 * r + col];
                In[6 * (r + 3) + col] = H[3 * col + r];
            }
        tk_apply(J, vw, Iw);
        tk_cross(h, vv, x);
        for (int r = 0; r < 3; r++) Iw[r] += x[r];
        tk_cross(vw, h, x);
        for (int r = 0; r < 3; r++) Iv[r] = m * vv[r] + x[r];
        /* v x* (n, f) = (w x n + v x f, w x f) */
        tk_cross(vw, Iw, x);
        tk_cross(vv, Iv, z);
        tk_cross(vw, Iv, y);
        for (int r = 0; r < 3; r++) { pa[r] = x[r] + z[r]; pa[3 + r] = y[r]; }
    }
    for (int i = t->nb - 1; i >= 0; i--) {
        const double *b = t->body + i * TK_STRIDE;
        double *w = W + i * TW_STRIDE, *In = w + IA, *pa = w + PA, *U_ = w + U;
        double S[6];
        if (TK_FREE(b)) continue;  /* the root: solved outright below */
        tk_subspace(b, S, S + 3);
        for (int r = 0; r < 6; r++) {
            double s = 0.0;
            for (int k = 0; k < 6; k++) s += In[6 * r + k] * S[k];
            U_[r] = s;
        }
        double d = 0.0, su = 0.0;
        for (int r = 0; r < 6; r++) { d += S[r] * U_[r]; su += S[r] * pa[r]; }
        const int c = (int)b[TK_COORD];
        const double u = tau[t->bv + c] + t->tau0[c] - su;
        if (!(d > 0.0)) return -1;
        w[D] = d;
        w[UU] = u;
        const int parent = (int)b[TK_PARENT];
        if (parent < 0) continue;
        /* Ia = IA - U U^T / D, pa' = pA + Ia c + U u / D, then X^T into the parent */
        double Ia[36], pv[6];
        const double inv = 1.0 / d;
        for (int r = 0; r < 6; r++)
            for (int k = 0; k < 6; k++) Ia[6 * r + k] = In[6 * r + k] - U_[r] * U_[k] * inv;
        const double *cc = w + C;
        for (int r = 0; r < 6; r++) {
            double s = pa[r] + U_[r] * u * inv;
            for (int k = 0; k < 6; k++) s += Ia[6 * r + k] * cc[k];
            pv[r] = s;
        }
        const double *R = w + TW_R, *p = w + TW_P;
        double *PI = W + parent * TW_STRIDE + IA, *Pp = W + parent * TW_STRIDE + PA;
        /* blocks A, B, C' of Ia rotated into parent axes, then shifted by p (P = [p]x):
           A + P B^T - B P - P C P, B + P C, C */
        double Ab[9], Bb[9], Cb[9], Ar[9], Br[9], Cr[9];
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 3; k++) {
                Ab[3 * r + k] = Ia[6 * r + k];
                Bb[3 * r + k] = Ia[6 * r + k + 3];
                Cb[3 * r + k] = Ia[6 * (r + 3) + k + 3];
            }
        tk_sandwich(R, Ab, Ar);
        tk_sandwich(R, Bb, Br);
        tk_sandwich(R, Cb, Cr);
        double PC[9], BP[9], PCP[9], PBt[9];
        for (int k = 0; k < 3; k++) {  /* column k of P X is p x (column k of X) */
            double col[3], out[3];
            for (int r = 0; r < 3; r++) col[r] = Cr[3 * r + k];
            tk_cross(p, col, out);
            for (int r = 0; r < 3; r++) PC[3 * r + k] = out[r];
            for (int r = 0; r < 3; r++) col[r] = Br[3 * k + r];  /* column k of B^T */
            tk_cross(p, col, out);
            for (int r = 0; r < 3; r++) PBt[3 * r + k] = out[r];
        }
        for (int r = 0; r < 3; r++) {  /* row r of X P is -(p x row r of X) ... = row x p */
            double row[3], out[3];
            for (int k = 0; k < 3; k++) row[k] = Br[3 * r + k];
            tk_cross(row, p, out);
            for (int k = 0; k < 3; k++) BP[3 * r + k] = out[k];
            for (int k = 0; k < 3; k++) row[k] = PC[3 * r + k];
            tk_cross(row, p, out);
            for (int k = 0; k < 3; k++) PCP[3 * r + k] = out[k];
        }
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 3; k++) {
                const double a = Ar[3 * r + k] + PBt[3 * r + k] - BP[3 * r + k] - PCP[3 * r + k];
                const double bb = Br[3 * r + k] + PC[3 * r + k];
                PI[6 * r + k] += a;
                PI[6 * r + k + 3] += bb;
                PI[6 * (k + 3) + r] += bb;
                PI[6 * (r + 3) + k + 3] += Cr[3 * r + k];
            }
        double F[3], N[3], x[3];
        tk_apply(R, pv + 3, F);
        tk_apply(R, pv, N);
        tk_cross(p, F, x);
        for (int r = 0; r < 3; r++) { Pp[r] += N[r] + x[r]; Pp[3 + r] += F[r]; }
    }
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        double *w = W + i * TW_STRIDE, *R = w + TW_R, *p = w + TW_P, *ac = w + A;
        const int parent = (int)b[TK_PARENT];
        double x[3], S[6];
        if (TK_FREE(b)) {
            if (tk_free_acceleration(t, w + IA, w + PA, R, tau, ac, qdd)) return -1;
            continue;
        }
        if (parent < 0) {  /* the ground accelerates up by g: (0, -g) */
            const double up[3] = {-t->g[0], -t->g[1], -t->g[2]};
            for (int r = 0; r < 3; r++) ac[r] = 0.0;
            tk_apply_t(R, up, ac + 3);
        } else {
            const double *pa = W + parent * TW_STRIDE + A;
            tk_cross(pa, p, x);
            for (int r = 0; r < 3; r++) x[r] += pa[3 + r];
            tk_apply_t(R, pa, ac);
            tk_apply_t(R, x, ac + 3);
        }
        for (int r = 0; r < 6; r++) ac[r] += w[C + r];
        tk_subspace(b, S, S + 3);
        double s = 0.0;
        for (int r = 0; r < 6; r++) s += w[U + r] * ac[r];
        const double x_dd = (w[UU] - s) / w[D];
        qdd[t->bv + (int)b[TK_COORD]] = x_dd;
        for (int r = 0; r < 6; r++) ac[r] += S[r] * x_dd;
    }
    for (int i = 0; i < t->nv; i++)
        if (!isfinite(qdd[i])) return -1;
    return 0;
}

/* q_ddot = M^-1 (tau - b) by Cholesky (a tree with mimic joints); -1 where M is not positive
   definite. L needs n * n numbers. */
static int tk_forward_cholesky(const tk_tree *t, const double *q, const double *v,
                               const double *tau, double *W, double *L, double *qdd)
{
    const int n = t->nv;
    tk_mass(t, q, W, L);
    tk_inverse(t, q, v, NULL, W, qdd);
    for (int i = 0; i < n; i++) qdd[i] = tau[i] - qdd[i];
    for (int j = 0; j < n; j++) {
        double d = L[j * n + j];
        for (int k = 0; k < j; k++) d -= L[j * n + k] * L[j * n + k];
        if (!(d > 0.0)) return -1;
        d = sqrt(d);
        L[j * n + j] = d;
        const double inv = 1.0 / d;
        for (int i = j + 1; i < n; i++) {
            double s = L[i * n + j];
            for (int k = 0; k < j; k++) s -= L[i * n + k] * L[j * n + k];
            L[i * n + j] = s * inv;
        }
    }
    for (int i = 0; i < n; i++) {
        double s = qdd[i];
        for (int k = 0; k < i; k++) s -= L[i * n + k] * qdd[k];
        qdd[i] = s / L[i * n + i];
    }
    for (int i = n - 1; i >= 0; i--) {
        double s = qdd[i];
        for (int k = i + 1; k < n; k++) s -= L[k * n + i] * qdd[k];
        qdd[i] = s / L[i * n + i];
    }
    for (int i = 0; i < n; i++)
        if (!isfinite(qdd[i])) return -1;
    return 0;
}
