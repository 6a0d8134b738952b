/* C(q, v) of the tree by Pinocchio's spatial factorization (coriolis_tree.py's formulas),
 * after reach_kernel.c (its tables and helpers: rk_bodies, rk_subspace, rk_free_columns). */

/* V x s for motions [v; w]: [w x s_v + v x s_w; w x s_w] */
static inline void RK_FN(motion_cross)(const RK_T *V, const RK_T *s, RK_T *out)
{
    RK_T a[3], b[3], c[3];
    RK_FN(cross)(V + 3, s, a);
    RK_FN(cross)(V, s + 3, b);
    RK_FN(cross)(V + 3, s + 3, c);
    for (int j = 0; j < 3; j++) { out[j] = a[j] + b[j]; out[3 + j] = c[j]; }
}

/* a body's workspace: its world columns S and their rates V x S (column-major, up to six),
 * its spatial inertia In and Bm (6 x 6 row-major; summed over the subtree going up), V */
typedef struct { RK_T S[6][6], dS[6][6], In[36], Bm[36], V[6]; int columns, first; } RK_FN(cbody);

static void RK_FN(coriolis)(const RK_T *restrict q, const RK_T *restrict qd, RK_T *restrict C,
                            RK_FN(cbody) *restrict body)
{
    RK_T R[RK_NB][9], o[RK_NB][3];
    RK_FN(bodies)(q, R, o);
    for (int j = 0; j < RK_NV * RK_NV; j++) C[j] = RK_C(0.0);
    for (int i = 0; i < RK_NB; i++) {
        RK_FN(cbody) *bi = body + i;
        int p = rk_parent[i];
        if (RK_FREE(i)) {
            RK_FN(free_columns)(R[0], o[0], bi->S);
            bi->columns = 6, bi->first = 0;
        } else {
            RK_FN(subspace)(i, R, o, bi->S[0]);
            for (int j = 0; j < 6; j++) bi->S[0][j] *= rk_mult[i];
            bi->columns = 1, bi->first = RK_BV + rk_coord[i];
        }
        for (int j = 0; j < 6; j++) bi->V[j] = p < 0 ? RK_C(0.0) : body[p].V[j];
        for (int c = 0; c < bi->columns; c++)
            for (int j = 0; j < 6; j++) bi->V[j] += bi->S[c][j] * qd[bi->first + c];
        for (int c = 0; c < bi->columns; c++) RK_FN(motion_cross)(bi->V, bi->S[c], bi->dS[c]);
        /* In: the inertia at the world's origin: [[m 1, -[h]x], [[h]x, J_O]] (as rk_centroidal's) */
        RK_T hr[3], RJ[9], h[3], *In = bi->In;
        const double m = rk_m[i];
        const RK_T *x = o[i];
        RK_FN(apply_v)(R[i], rk_h[i], hr);
        RK_FN(matmul_v)(R[i], rk_J[i], RJ);
        RK_T pp = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
        RK_T ph = x[0] * hr[0] + x[1] * hr[1] + x[2] * hr[2];
        for (int j = 0; j < 3; j++) h[j] = hr[j] + m * x[j];
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++)
                In[6 * (3 + a) + 3 + c] = RJ[3 * a] * R[i][3 * c] + RJ[3 * a + 1] * R[i][3 * c + 1]
                                         + RJ[3 * a + 2] * R[i][3 * c + 2] - m * x[a] * x[c]
                                         - x[a] * hr[c] - hr[a] * x[c]
                                         + (a == c ? m * pp + 2.0 * ph : RK_C(0.0));
        RK_T H[9] = {RK_C(0.0), -h[2], h[1], h[2], RK_C(0.0), -h[0], -h[1], h[0], RK_C(0.0)};
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++) {
                In[6 * a + c] = RK_C(a == c ? m : 0.0);
                In[6 * a + 3 + c] = -H[3 * a + c];
                In[6 * (3 + a) + c] = H[3 * a + c];
            }
        /* Bm = 1/2 (V x* I - I V x) + 1/2 (I V) x-bar, V x* = -(V x)^T = [[[w]x, 0], [[v]x, [w]x]];
         * I symmetric, so I V x = -(V x* I)^T: one product, XI = V x* I, column by column */
        RK_T XI[36], f[6];
        const RK_T *v = bi->V, *w = bi->V + 3;
        for (int c = 0; c < 6; c++) {
            RK_T top[3] = {In[c], In[6 + c], In[12 + c]}, bottom[3] = {In[18 + c], In[24 + c],
                                                                            In[30 + c]};
            RK_T a1[3], a2[3], a3[3];
            RK_FN(cross)(w, top, a1);
            RK_FN(cross)(v, top, a2);
            RK_FN(cross)(w, bottom, a3);
            for (int j = 0; j < 3; j++) { XI[6 * j + c] = a1[j]; XI[6 * (3 + j) + c] = a2[j] + a3[j]; }
        }
        for (int a = 0; a < 6; a++) {
            f[a] = RK_C(0.0);
            for (int c = 0; c < 6; c++) f[a] += In[6 * a + c] * v[c];
        }
        for (int a = 0; a < 6; a++)
            for (int c = 0; c < 6; c++) bi->Bm[6 * a + c] = 0.5 * (XI[6 * a + c] + XI[6 * c + a]);
        /* (f x-bar) = [[0, -[f]x], [-[f]x, -[n]x]] */
        RK_T Fx[9] = {RK_C(0.0), -f[2], f[1], f[2], RK_C(0.0), -f[0], -f[1], f[0], RK_C(0.0)};
        RK_T Nx[9] = {RK_C(0.0), -f[5], f[4], f[5], RK_C(0.0), -f[3], -f[4], f[3], RK_C(0.0)};
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++) {
                bi->Bm[6 * a + 3 + c] -= 0.5 * Fx[3 * a + c];
                bi->Bm[6 * (3 + a) + c] -= 0.5 * Fx[3 * a + c];
                bi->Bm[6 * (3 + a) + 3 + c] -= 0.5 * Nx[3 * a + c];
            }
    }
    for (int i = RK_NB - 1; i >= 0; i--) {
        RK_FN(cbody) *bi = body + i;
        RK_T own[6][6], rowI[6][6], rowB[6][6];  /* I S_dot + B S; S^T I, S^T B per column */
        for (int c = 0; c < bi->columns; c++)
            for (int a = 0; a < 6; a++) {
                RK_T t = RK_C(0.0), u = RK_C(0.0), z = RK_C(0.0);
                for (int k = 0; k < 6; k++) {
                    t += bi->In[6 * a + k] * bi->dS[c][k] + bi->Bm[6 * a + k] * bi->S[c][k];
                    u += bi->S[c][k] * bi->In[6 * k + a];
                    z += bi->S[c][k] * bi->Bm[6 * k + a];
                }
                own[c][a] = t, rowI[c][a] = u, rowB[c][a] = z;
            }
        for (int a = i; a >= 0; a = rk_parent[a]) {
            const RK_FN(cbody) *ba = body + a;
            for (int ca = 0; ca < ba->columns; ca++)
                for (int ci = 0; ci < bi->columns; ci++) {
                    RK_T t = RK_C(0.0);  /* C[a, i] = S_a^T (I^c_i S_dot_i + B^c_i S_i) */
                    for (int k = 0; k < 6; k++) t += ba->S[ca][k] * own[ci][k];
                    C[(ba->first + ca) * RK_NV + bi->first + ci] += t;
                    if (a == i) continue;
                    t = RK_C(0.0);  /* C[i, a] = S_i^T (I^c_i S_dot_a + B^c_i S_a) */
                    for (int k = 0; k < 6; k++)
                        t += rowI[ci][k] * ba->dS[ca][k] + rowB[ci][k] * ba->S[ca][k];
                    C[(bi->first + ci) * RK_NV + ba->first + ca] += t;
                }
        }
        int p = rk_parent[i];
        if (p >= 0)
            for (int j = 0; j < 36; j++) { body[p].In[j] += bi->In[j]; body[p].Bm[j] += bi->Bm[j]; }
    }
}
