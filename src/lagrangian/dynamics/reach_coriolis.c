/* C(q, v) of the tree by Pinocchio's spatial factorization (coriolis_tree.py's formulas),
 * after reach_kernel.c (its tables and helpers: rk_bodies, rk_subspace, rk_free_columns). */

/* V x s for motions [v; w]: [w x s_v + v x s_w; w x s_w] */
static inline void rk_motion_cross(const double *V, const double *s, double *out)
{
    double a[3], b[3], c[3];
    rk_cross(V + 3, s, a);
    rk_cross(V, s + 3, b);
    rk_cross(V + 3, s + 3, c);
    for (int j = 0; j < 3; j++) { out[j] = a[j] + b[j]; out[3 + j] = c[j]; }
}

/* a body's workspace: its world columns S and their rates V x S (column-major, up to six),
 * its spatial inertia In and Bm (6 x 6 row-major; summed over the subtree going up), V */
typedef struct { double S[6][6], dS[6][6], In[36], Bm[36], V[6]; int columns, first; } rk_cbody;

static void rk_coriolis(const double *restrict q, const double *restrict qd, double *restrict C,
                        rk_cbody *restrict body)
{
    double R[RK_NB][9], o[RK_NB][3];
    rk_bodies(q, R, o);
    for (int j = 0; j < RK_NV * RK_NV; j++) C[j] = 0.0;
    for (int i = 0; i < RK_NB; i++) {
        rk_cbody *bi = body + i;
        int p = rk_parent[i];
        if (RK_FREE(i)) {
            rk_free_columns(R[0], o[0], bi->S);
            bi->columns = 6, bi->first = 0;
        } else {
            rk_subspace(i, R, o, bi->S[0]);
            for (int j = 0; j < 6; j++) bi->S[0][j] *= rk_mult[i];
            bi->columns = 1, bi->first = RK_BV + rk_coord[i];
        }
        for (int j = 0; j < 6; j++) bi->V[j] = p < 0 ? 0.0 : body[p].V[j];
        for (int c = 0; c < bi->columns; c++)
            for (int j = 0; j < 6; j++) bi->V[j] += bi->S[c][j] * qd[bi->first + c];
        for (int c = 0; c < bi->columns; c++) rk_motion_cross(bi->V, bi->S[c], bi->dS[c]);
        /* In: the inertia at the world's origin: [[m 1, -[h]x], [[h]x, J_O]] (as rk_centroidal's) */
        double hr[3], RJ[9], h[3], m = rk_m[i], *In = bi->In;
        const double *x = o[i];
        rk_apply(R[i], rk_h[i], hr);
        rk_matmul(R[i], rk_J[i], RJ);
        double pp = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
        double ph = x[0] * hr[0] + x[1] * hr[1] + x[2] * hr[2];
        for (int j = 0; j < 3; j++) h[j] = hr[j] + m * x[j];
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++)
                In[6 * (3 + a) + 3 + c] = RJ[3 * a] * R[i][3 * c] + RJ[3 * a + 1] * R[i][3 * c + 1]
                                         + RJ[3 * a + 2] * R[i][3 * c + 2] - m * x[a] * x[c]
                                         - x[a] * hr[c] - hr[a] * x[c]
                                         + (a == c ? m * pp + 2.0 * ph : 0.0);
        double H[9] = {0.0, -h[2], h[1], h[2], 0.0, -h[0], -h[1], h[0], 0.0};
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++) {
                In[6 * a + c] = a == c ? m : 0.0;
                In[6 * a + 3 + c] = -H[3 * a + c];
                In[6 * (3 + a) + c] = H[3 * a + c];
            }
        /* Bm = 1/2 (V x* I - I V x) + 1/2 (I V) x-bar, V x* = -(V x)^T = [[[w]x, 0], [[v]x, [w]x]];
         * I symmetric, so I V x = -(V x* I)^T: one product, XI = V x* I, column by column */
        double XI[36], f[6];
        const double *v = bi->V, *w = bi->V + 3;
        for (int c = 0; c < 6; c++) {
            double top[3] = {In[c], In[6 + c], In[12 + c]}, bottom[3] = {In[18 + c], In[24 + c],
                                                                            In[30 + c]};
            double a1[3], a2[3], a3[3];
            rk_cross(w, top, a1);
            rk_cross(v, top, a2);
            rk_cross(w, bottom, a3);
            for (int j = 0; j < 3; j++) { XI[6 * j + c] = a1[j]; XI[6 * (3 + j) + c] = a2[j] + a3[j]; }
        }
        for (int a = 0; a < 6; a++) {
            f[a] = 0.0;
            for (int c = 0; c < 6; c++) f[a] += In[6 * a + c] * v[c];
        }
        for (int a = 0; a < 6; a++)
            for (int c = 0; c < 6; c++) bi->Bm[6 * a + c] = 0.5 * (XI[6 * a + c] + XI[6 * c + a]);
        /* (f x-bar) = [[0, -[f]x], [-[f]x, -[n]x]] */
        double Fx[9] = {0.0, -f[2], f[1], f[2], 0.0, -f[0], -f[1], f[0], 0.0};
        double Nx[9] = {0.0, -f[5], f[4], f[5], 0.0, -f[3], -f[4], f[3], 0.0};
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++) {
                bi->Bm[6 * a + 3 + c] -= 0.5 * Fx[3 * a + c];
                bi->Bm[6 * (3 + a) + c] -= 0.5 * Fx[3 * a + c];
                bi->Bm[6 * (3 + a) + 3 + c] -= 0.5 * Nx[3 * a + c];
            }
    }
    for (int i = RK_NB - 1; i >= 0; i--) {
        rk_cbody *bi = body + i;
        double own[6][6], rowI[6][6], rowB[6][6];  /* I S_dot + B S; S^T I, S^T B per column */
        for (int c = 0; c < bi->columns; c++)
            for (int a = 0; a < 6; a++) {
                double t = 0.0, u = 0.0, z = 0.0;
                for (int k = 0; k < 6; k++) {
                    t += bi->In[6 * a + k] * bi->dS[c][k] + bi->Bm[6 * a + k] * bi->S[c][k];
                    u += bi->S[c][k] * bi->In[6 * k + a];
                    z += bi->S[c][k] * bi->Bm[6 * k + a];
                }
                own[c][a] = t, rowI[c][a] = u, rowB[c][a] = z;
            }
        for (int a = i; a >= 0; a = rk_parent[a]) {
            const rk_cbody *ba = body + a;
            for (int ca = 0; ca < ba->columns; ca++)
                for (int ci = 0; ci < bi->columns; ci++) {
                    double t = 0.0;  /* C[a, i] = S_a^T (I^c_i S_dot_i + B^c_i S_i) */
                    for (int k = 0; k < 6; k++) t += ba->S[ca][k] * own[ci][k];
                    C[(ba->first + ca) * RK_NV + bi->first + ci] += t;
                    if (a == i) continue;
                    t = 0.0;  /* C[i, a] = S_i^T (I^c_i S_dot_a + B^c_i S_a) */
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
