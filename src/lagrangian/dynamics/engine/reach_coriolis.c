/* C(q, v) of the tree by Pinocchio's spatial factorization (coriolis_tree.py's formulas),
 * after reach_kernel.c (its tables and helpers: bodies, subspace, free_columns). Spatial
 * inertias at the world's origin in world axes kept by their ten numbers I = [[m 1, -[h]x],
 * [[h]x, J]] (mass kg, first moment h kg m, J kg m^2 about the origin) and Pinocchio's
 * B = 1/2 (V x* I - I V x + (I V) x-bar) by its twelve: with I V = [l; n],
 * B = [[0, -[l]x], [0, A]], A = (v.h) 1 - (h v^T + v h^T)/2 + ([w]x J - J [w]x)/2 - [n]x/2;
 * both additive over a subtree. */

/* V x s for motions [v; w]: [w x s_v + v x s_w; w x s_w] */
static inline void RK_FN(motion_cross)(const RK_T *V, const RK_T *s, RK_T *out)
{
    RK_T a[3], b[3], c[3];
    SP_CROSS(V + 3, s, a);
    SP_CROSS(V, s + 3, b);
    SP_CROSS(V + 3, s + 3, c);
    for (int j = 0; j < 3; j++) { out[j] = a[j] + b[j]; out[3 + j] = c[j]; }
}

/* a body's workspace: its world column S and its rate V x S, V, and (summed over the subtree
 * going up) its inertia m, h, J and B's l, A; a free flyer's six columns apart (S0, dS0), and
 * a ball's three or a flyer's below the root six in a pool after the bodies (pool: where,
 * else -1), so that eight lanes' workspace of a quadruped stays within a core's first-level
 * cache (with six columns a body, Solo12's was 85 kB) */
typedef struct {
    RK_T S[6], dS[6], V[6], h[3], J[9], l[3], A[9];
    double m;
    int columns, first, pool;
} RK_FN(cbody);

typedef struct {
    RK_T S0[6][6], dS0[6][6];
    RK_FN(cbody) b[];  /* nb of them, then the pool's columns and their rates */
} RK_FN(cwork);

static size_t RK_FN(cwork_size)(const rk_model *md)
{
    const size_t pooled = 3 * (size_t)md->t.balls + 6 * (size_t)md->t.flyers;
    return sizeof(RK_FN(cwork)) + (size_t)md->nb * sizeof(RK_FN(cbody))
           + 2 * pooled * 6 * sizeof(RK_T);
}

/* body i's columns and their rates, (RK_T (*)[6]): the free flyer's six, a ball's or a flyer's
   in the pool, or the joint's one */
#define RK_POOL(w, md) ((RK_T (*)[6])((w)->b + (md)->nb))
#define RK_COLUMNS(w, i)                                                                    \
    (RK_FREE(i) ? (w)->S0                                                                   \
     : (w)->b[i].pool >= 0 ? RK_POOL(w, md) + (w)->b[i].pool : (RK_T (*)[6])(w)->b[i].S)
#define RK_RATES(w, i)                                                                      \
    (RK_FREE(i) ? (w)->dS0                                                                  \
     : (w)->b[i].pool >= 0 ? RK_POOL(w, md) + (w)->b[i].pool + (w)->b[i].columns            \
                           : (RK_T (*)[6])(w)->b[i].dS)

/* I x = [m x_v - h x x_w; h x x_v + J x_w] */
static inline void RK_FN(inertia_times)(const RK_FN(cbody) *b, const RK_T *x, RK_T *out)
{
    RK_T s[3], t[3];
    SP_CROSS(b->h, x + 3, s);
    SP_CROSS(b->h, x, t);
    for (int j = 0; j < 3; j++) {
        out[j] = b->m * x[j] - s[j];
        out[3 + j] = t[j] + b->J[3 * j] * x[3] + b->J[3 * j + 1] * x[4] + b->J[3 * j + 2] * x[5];
    }
}

static void RK_FN(coriolis)(const rk_model *md, RK_FN(work) *space, const RK_T *restrict q,
                            const RK_T *restrict qd, RK_T *restrict C)
{
    RK_FN(cwork) *restrict work = (RK_FN(cwork) *)space->x;
    RK_FN(cbody) *restrict body = work->b;
    RK_T (*R)[9] = space->R, (*o)[3] = space->o;
    RK_FN(bodies)(md, q, R, o);
    if (md->cset)  /* each entry set once below: zero only those between branches (reach_c.py) */
        for (int j = 0; j < md->nczero; j++) C[md->czero[j]] = RK_C(0.0);
    else  /* a mimic joint's coordinate is another joint's too: its entries add up */
        for (int j = 0; j < md->nv * md->nv; j++) C[j] = RK_C(0.0);
    int pooled = 0;  /* the pool's columns taken so far */
    for (int i = 0; i < md->nb; i++) {
        RK_FN(cbody) *bi = body + i;
        int p = md->parent[i];
        bi->pool = -1;
        if (RK_MANY(md, i)) {  /* its columns (and then their rates) in the pool */
            double mult;
            bi->pool = pooled;
            bi->columns = RK_FN(columns)(md, i, R, o, RK_POOL(work, md) + pooled, &bi->first,
                                         &mult);
            pooled += 2 * bi->columns;
        }
        RK_T (*S)[6] = RK_COLUMNS(work, i), (*dS)[6] = RK_RATES(work, i);
        if (RK_FREE(i)) {
            RK_FREE_COLUMNS(md, R[0], o[0], S);
            bi->columns = 6, bi->first = 0;
        } else if (RK_MANY(md, i)) {
            /* set above */
        } else {
            RK_SUBSPACE(md, i, R, o, S[0]);
            for (int j = 0; j < 6; j++) S[0][j] *= md->mult[i];
            bi->columns = 1, bi->first = md->bv + md->coord[i];
        }
        for (int j = 0; j < 6; j++) bi->V[j] = p < 0 ? RK_C(0.0) : body[p].V[j];
        for (int c = 0; c < bi->columns; c++)
            for (int j = 0; j < 6; j++) bi->V[j] += S[c][j] * qd[bi->first + c];
        for (int c = 0; c < bi->columns; c++) RK_FN(motion_cross)(bi->V, S[c], dS[c]);
        /* the inertia at the world's origin (as centroidal's): h = R h_i + m x, J_O */
        RK_T hr[3], RJ[9];
        const double m = md->m[i];
        const RK_T *x = o[i];
        SP_APPLY(R[i], md->h + 3 * i, hr);
        SP_MATMUL(R[i], md->J + 9 * i, RJ);
        RK_T pp = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
        RK_T ph = x[0] * hr[0] + x[1] * hr[1] + x[2] * hr[2];
        bi->m = m;
        for (int j = 0; j < 3; j++) bi->h[j] = hr[j] + m * x[j];
        for (int a = 0; a < 3; a++)  /* R J R^T - m x x^T - x hr^T - hr x^T + (m x.x + 2 x.hr) 1 */
            for (int c = a; c < 3; c++)
                bi->J[3 * c + a] = bi->J[3 * a + c] =
                    RJ[3 * a] * R[i][3 * c] + RJ[3 * a + 1] * R[i][3 * c + 1]
                    + RJ[3 * a + 2] * R[i][3 * c + 2] - m * x[a] * x[c] - x[a] * hr[c]
                    - hr[a] * x[c] + (a == c ? m * pp + 2.0 * ph : RK_C(0.0));
        /* I V = [l; n], then A (its symmetric part and -[n]x/2) */
        RK_T f[6], WJ[9];
        const RK_T *v = bi->V, *w = bi->V + 3, *h = bi->h, *J = bi->J;
        RK_FN(inertia_times)(bi, bi->V, f);
        for (int j = 0; j < 3; j++) bi->l[j] = f[j];
        for (int c = 0; c < 3; c++) {  /* [w]x J, column by column */
            RK_T col[3] = {J[c], J[3 + c], J[6 + c]}, t[3];
            SP_CROSS(w, col, t);
            for (int j = 0; j < 3; j++) WJ[3 * j + c] = t[j];
        }
        RK_T vh = v[0] * h[0] + v[1] * h[1] + v[2] * h[2];
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++)
                bi->A[3 * a + c] = 0.5 * (WJ[3 * a + c] + WJ[3 * c + a] - h[a] * v[c] - v[a] * h[c])
                                   + (a == c ? vh : RK_C(0.0));
        /* -[n]x / 2 */
        bi->A[1] += 0.5 * f[5]; bi->A[2] -= 0.5 * f[4]; bi->A[5] += 0.5 * f[3];
        bi->A[3] -= 0.5 * f[5]; bi->A[6] += 0.5 * f[4]; bi->A[7] -= 0.5 * f[3];
    }
    for (int i = md->nb - 1; i >= 0; i--) {
        RK_FN(cbody) *bi = body + i;
        RK_T (*Si)[6] = RK_COLUMNS(work, i), (*dSi)[6] = RK_RATES(work, i);
        /* per column: own = I S_dot + B S, rowI = (I S)^T, rowB = (B^T S)^T's angular half
           (B^T x = [0; l x x_v + A^T x_w]) */
        RK_T own[6][6], rowI[6][6], rowB[6][3];
        for (int c = 0; c < bi->columns; c++) {
            const RK_T *s = Si[c];
            RK_T t[3], u[3];
            RK_FN(inertia_times)(bi, dSi[c], own[c]);
            RK_FN(inertia_times)(bi, s, rowI[c]);
            SP_CROSS(bi->l, s + 3, t);  /* B s = [-l x s_w; A s_w] */
            SP_CROSS(bi->l, s, u);
            for (int j = 0; j < 3; j++) {
                own[c][j] -= t[j];
                own[c][3 + j] += bi->A[3 * j] * s[3] + bi->A[3 * j + 1] * s[4]
                                 + bi->A[3 * j + 2] * s[5];
                rowB[c][j] = u[j] + bi->A[j] * s[3] + bi->A[3 + j] * s[4] + bi->A[6 + j] * s[5];
            }
        }
        for (int a = i; a >= 0; a = md->parent[a]) {
            const RK_FN(cbody) *ba = body + a;
            RK_T (*Sa)[6] = RK_COLUMNS(work, a), (*dSa)[6] = RK_RATES(work, a);
            /* (a, i) with a an ancestor of i or i itself, (i, a) with a strict ancestor:
               never the same entry twice but where a coordinate drives two joints */
            for (int ca = 0; ca < ba->columns; ca++)
                for (int ci = 0; ci < bi->columns; ci++) {
                    RK_T t = RK_C(0.0);  /* C[a, i] = S_a^T (I^c_i S_dot_i + B^c_i S_i) */
                    for (int k = 0; k < 6; k++) t += Sa[ca][k] * own[ci][k];
                    RK_CPUT(C[(ba->first + ca) * md->nv + bi->first + ci], t);
                    if (a == i) continue;
                    t = RK_C(0.0);  /* C[i, a] = S_i^T (I^c_i S_dot_a + B^c_i S_a) */
                    for (int k = 0; k < 6; k++) t += rowI[ci][k] * dSa[ca][k];
                    for (int k = 0; k < 3; k++) t += rowB[ci][k] * Sa[ca][3 + k];
                    RK_CPUT(C[(bi->first + ci) * md->nv + ba->first + ca], t);
                }
        }
        int p = md->parent[i];
        if (p >= 0) {
            RK_FN(cbody) *bp = body + p;
            bp->m += bi->m;
            for (int j = 0; j < 3; j++) { bp->h[j] += bi->h[j]; bp->l[j] += bi->l[j]; }
            for (int j = 0; j < 9; j++) { bp->J[j] += bi->J[j]; bp->A[j] += bi->A[j]; }
        }
    }
}
