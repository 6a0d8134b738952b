/* The joint-torque regressor Y (tau = Y pi), part of the derivatives kernel's core (compiled on
 * one state and on LG_LANES states, after derivatives_kernel.c: its work, carve, kinematics,
 * cross and dot3; its tree and work block the caller's). */

/* One column S (world, at the world's origin; times mult) of a joint at or above body i,
 * paired with body i's wrench per parameter: S at body i's origin in its axes,
 * [R^T (s_v + s_w x o); R^T s_w], dotted with f (al, Fh) and n (Nh, Nj). */
static inline void DK_FN(regressor_column)(const DK_T *S, double mult, const DK_T *R,
                                           const DK_T *o, const DK_T *al, DK_T Fh[3][3],
                                           DK_T Nh[3][3], DK_T Nj[6][3], DK_T *row)
{
    DK_T sv[3], sl[3], sw[3], t[3];
    SP_CROSS(S + 3, o, t);
    for (int j = 0; j < 3; j++) sv[j] = S[j] + t[j];
    for (int j = 0; j < 3; j++) {
        sl[j] = R[j] * sv[0] + R[3 + j] * sv[1] + R[6 + j] * sv[2];
        sw[j] = R[j] * S[3] + R[3 + j] * S[4] + R[6 + j] * S[5];
    }
    row[0] += mult * SP_DOT(sl, al);
    for (int c = 0; c < 3; c++)
        row[1 + c] += mult * (SP_DOT(sl, Fh[c]) + SP_DOT(sw, Nh[c]));
    for (int p = 0; p < 6; p++) row[4 + p] += mult * SP_DOT(sw, Nj[p]);
}

/* Y (nv x 10 bodies, row-major) with tau = Y pi, pi = [m, m c, I_xx, I_xy, I_yy, I_xz, I_yz,
 * I_zz] per body about its origin in its link's own axes (Pinocchio's order; a ball's or a
 * flyer's records before its last are massless and frameless, no body's: none): body i's wrench
 * at its origin per parameter, from its angular velocity w, angular acceleration dw and its
 * origin's acceleration ac (gravity in), in its axes: m [ac; 0], h [(dw x + w x w x) h; h x ac],
 * J [0; J dw + w x J w]; each paired with S_k of every joint k at or above it, in its axes. */
static void DK_FN(regressor)(const dk_tree *tree, DK_T *space, const DK_T *q, const DK_T *qd,
                             const DK_T *qdd, const double *g, DK_T *Y)
{
    DK_FN(work) w;
    DK_FN(carve)(tree, space, &w);
    DK_FN(kinematics)(tree, q, qd, qdd, g, &w);
    const int nb = tree->nb, width = 10 * tree->bodies;
    for (int j = 0; j < tree->nv * width; j++) Y[j] = DK_C(0.0);
    for (int i = 0, body = -1; i < nb; i++) {
        if (tree->end[i] != i) continue;  /* a split joint's column before its last */
        body++;
        const DK_T *o = w.o[i], *V = w.V[i], *Acc = w.Acc[i];
        /* the link's own axes, whose inertial pi is: R = R_c A^T, R_c the body's canonical
           axes (D's) and A (D's TK_AXES) the canonical axes in the link's */
        const double *A = DK_BODY_OF(tree, i) + TK_AXES;
        DK_T R[9];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                R[3 * r + c] = w.R[i][3 * r] * A[3 * c] + w.R[i][3 * r + 1] * A[3 * c + 1]
                               + w.R[i][3 * r + 2] * A[3 * c + 2];
        DK_T vo[3], ac[3], t[3], wl[3], dwl[3], al[3], ww[3];
        /* the origin's velocity v + w x o and classical acceleration a + dw x o + w x vo */
        SP_CROSS(V + 3, o, t);
        for (int j = 0; j < 3; j++) vo[j] = V[j] + t[j];
        SP_CROSS(Acc + 3, o, t);
        for (int j = 0; j < 3; j++) ac[j] = Acc[j] + t[j];
        SP_CROSS(V + 3, vo, t);
        for (int j = 0; j < 3; j++) ac[j] += t[j];
        for (int j = 0; j < 3; j++) {  /* into the body's axes: R^T x */
            wl[j] = R[j] * V[3] + R[3 + j] * V[4] + R[6 + j] * V[5];
            dwl[j] = R[j] * Acc[3] + R[3 + j] * Acc[4] + R[6 + j] * Acc[5];
            al[j] = R[j] * ac[0] + R[3 + j] * ac[1] + R[6 + j] * ac[2];
        }
        /* the columns: f (3) and n (3) per parameter */
        DK_T Fh[3][3], Nh[3][3], Nj[6][3];
        for (int c = 0; c < 3; c++) {  /* h = e_c: (dw x + w x w x) e_c, e_c x ac */
            DK_T e[3] = {DK_C(0.0), DK_C(0.0), DK_C(0.0)}, x[3], y[3];
            e[c] = DK_C(1.0);
            SP_CROSS(dwl, e, x);
            SP_CROSS(wl, e, y);
            SP_CROSS(wl, y, t);
            for (int j = 0; j < 3; j++) Fh[c][j] = x[j] + t[j];
            SP_CROSS(e, al, Nh[c]);
        }
        /* J's six entries: J dw + w x J w for J = E_rc + E_cr */
        static const int rows[6] = {0, 0, 1, 0, 1, 2}, cols[6] = {0, 1, 1, 2, 2, 2};
        for (int p = 0; p < 6; p++) {
            DK_T Jd[3] = {DK_C(0.0), DK_C(0.0), DK_C(0.0)}, Jw[3] = {DK_C(0.0), DK_C(0.0), DK_C(0.0)};
            const int r = rows[p], c = cols[p];
            Jd[r] += dwl[c]; Jw[r] += wl[c];
            if (r != c) { Jd[c] += dwl[r]; Jw[c] += wl[r]; }
            SP_CROSS(wl, Jw, ww);
            for (int j = 0; j < 3; j++) Nj[p][j] = Jd[j] + ww[j];
        }
        for (int kk = i; kk >= tree->ff; kk = tree->parent[kk])
            DK_FN(regressor_column)(w.S[kk], tree->mult[kk], R, o, al, Fh, Nh, Nj,
                                    Y + (tree->vo + tree->coord[kk]) * width + 10 * body);
        /* a floating base's rows 0..5, the wrench on it in its axes: every body hangs from it */
        for (int c = 0; c < 6 * tree->ff; c++)
            DK_FN(regressor_column)(w.ffS[c], 1.0, R, o, al, Fh, Nh, Nj,
                                    Y + c * width + 10 * body);
    }
}
