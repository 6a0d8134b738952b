/* Inverse dynamics with wrenches at frames in one Newton-Euler pass, after reach_kernel.c (its
 * tables and helpers): velocities and accelerations at the world's origin in world axes going
 * out, each body's force less the wrenches on it coming back, tau = S^T f. The ground
 * accelerates up (up = -g, world axes, m/s^2): every body feels gravity. */

/* I X for body i's spatial inertia about its own origin, world axes (X = [a; alpha] there):
 * [m a - h x alpha; h x a + R J R^T alpha], h = R h_i its first moment (kg m) */
static inline void RK_FN(inertia_at)(const rk_model *md, int i, const RK_T *R, const RK_T *h,
                                     const RK_T *X, RK_T *out)
{
    RK_T t[3], u[3], hxa[3], ahx[3];
    SP_APPLY_T(R, X + 3, t);
    SP_APPLY(md->J + 9 * i, t, u);
    SP_APPLY(R, u, t);
    SP_CROSS(X + 3, h, ahx);  /* -h x alpha */
    SP_CROSS(h, X, hxa);
    for (int j = 0; j < 3; j++) {
        out[j] = md->m[i] * X[j] + ahx[j];
        out[3 + j] = hxa[j] + t[j];
    }
}

/* tau (nv) = M(q) qdd + C(q, qd) qd + g(q) - sum J_f^T w_f over the nw wrenches w_f =
 * [force; moment] at frames[f]'s origin, world axes (a floating base's six first: the force
 * and moment on the base about its origin, base axes) */
static void RK_FN(inverse)(const rk_model *md, RK_FN(work) *work, const RK_T *restrict q,
                           const RK_T *restrict qd, const RK_T *restrict qdd, const double *up,
                           int nw, const int *frames, const RK_T (*w)[6], RK_T *restrict tau)
{
    const int nb = md->nb;
    RK_T (*R)[9] = work->R, (*o)[3] = work->o, (*V)[6] = (RK_T (*)[6])work->x, (*A)[6] = V + nb,
         (*F)[6] = V + 2 * nb, (*S)[6] = V + 3 * nb;
    RK_T base[6][6];
    RK_FN(bodies)(md, q, R, o);
    for (int j = 0; j < md->nv; j++) tau[j] = RK_C(0.0);
    for (int i = 0; i < md->nb; i++) {
        const int p = md->parent[i];
        if (RK_FREE(i)) {  /* V = S v_base, A = up + S a_base (V x S v_base = V x V = 0) */
            RK_FREE_COLUMNS(md, R[0], o[0], base);
            for (int j = 0; j < 6; j++) {
                V[0][j] = RK_C(0.0);
                A[0][j] = RK_C(j < 3 ? up[j] : 0.0);
                for (int c = 0; c < 6; c++) {
                    V[0][j] += base[c][j] * qd[c];
                    A[0][j] += base[c][j] * qdd[c];
                }
            }
        } else {  /* its columns (one; a ball's three, a flyer's six), each fixed in the body */
            RK_T (*columns_)[6] = (RK_T (*)[6])S[i], many[6][6], c[6];
            int first;
            double mult;
            if (RK_MANY(md, i)) columns_ = many;  /* more than S[i]'s one: recomputed below */
            const int columns = RK_FN(columns)(md, i, R, o, columns_, &first, &mult);
            for (int j = 0; j < 6; j++) {
                V[i][j] = p < 0 ? RK_C(0.0) : V[p][j];
                A[i][j] = p < 0 ? RK_C(j < 3 ? up[j] : 0.0) : A[p][j];
            }
            for (int col = 0; col < columns; col++)
                for (int j = 0; j < 6; j++) {
                    V[i][j] += columns_[col][j] * (mult * qd[first + col]);
                    A[i][j] += columns_[col][j] * (mult * qdd[first + col]);
                }
            for (int col = 0; col < columns; col++) {  /* d/dt S = V x S: S moves with its body */
                RK_FN(motion_cross)(V[i], columns_[col], c);
                for (int j = 0; j < 6; j++) A[i][j] += c[j] * (mult * qd[first + col]);
            }
        }
        /* f = I A + V x* (I V) about the body's own origin o (its inertia without lever
         * arms: motions there [v + w x o; w]), V x* [f; n] = [w x f; w x n + v x f], then
         * carried to the world's origin: [f; n + o x f] */
        RK_T h[3], Vo[6], Ao[6], IV[6], f[6], t1[3], t2[3];
        SP_APPLY(R[i], md->h + 3 * i, h);
        SP_CROSS(V[i] + 3, o[i], t1);
        SP_CROSS(A[i] + 3, o[i], t2);
        for (int j = 0; j < 3; j++) {
            Vo[j] = V[i][j] + t1[j], Vo[3 + j] = V[i][3 + j];
            Ao[j] = A[i][j] + t2[j], Ao[3 + j] = A[i][3 + j];
        }
        RK_FN(inertia_at)(md, i, R[i], h, Ao, f);
        RK_FN(inertia_at)(md, i, R[i], h, Vo, IV);
        SP_CROSS(Vo + 3, IV, t1);
        for (int j = 0; j < 3; j++) f[j] += t1[j];
        SP_CROSS(Vo + 3, IV + 3, t1);
        SP_CROSS(Vo, IV, t2);
        for (int j = 0; j < 3; j++) f[3 + j] += t1[j] + t2[j];
        SP_CROSS(o[i], f, t1);
        for (int j = 0; j < 3; j++) F[i][j] = f[j], F[i][3 + j] = f[3 + j] + t1[j];
    }
    for (int k = 0; k < nw; k++) {  /* the wrench carried to the world's origin: [f; m + p x f] */
        const int b = md->fbody[frames[k]];
        if (b < 0) continue;  /* on the ground: no joint feels it */
        RK_T x[3], m[3];
        RK_FN(frame_origin)(md, frames[k], R, o, x);
        SP_CROSS(x, w[k], m);
        for (int j = 0; j < 3; j++) {
            F[b][j] -= w[k][j];
            F[b][3 + j] -= w[k][3 + j] + m[j];
        }
    }
    for (int i = md->nb - 1; i >= 0; i--) {
        if (RK_FREE(i)) {
            for (int c = 0; c < 6; c++) {
                RK_T t = RK_C(0.0);
                for (int j = 0; j < 6; j++) t += base[c][j] * F[0][j];
                tau[c] = t;
            }
        } else {
            RK_T (*columns_)[6] = (RK_T (*)[6])S[i], many[6][6];
            int first, columns = 1;
            double mult = md->mult[i];
            first = md->bv + md->coord[i];
            if (RK_MANY(md, i)) {
                columns_ = many;
                columns = RK_FN(columns)(md, i, R, o, columns_, &first, &mult);
            }
            for (int col = 0; col < columns; col++) {
                RK_T t = RK_C(0.0);
                for (int j = 0; j < 6; j++) t += columns_[col][j] * F[i][j];
                tau[first + col] += mult * t;
            }
        }
        const int p = md->parent[i];
        if (p >= 0)
            for (int j = 0; j < 6; j++) F[p][j] += F[i][j];
    }
}
