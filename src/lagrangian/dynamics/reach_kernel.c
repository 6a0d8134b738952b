/* J_dot q_dot of a frame, the centroidal momentum matrix, a wrench's generalized forces and
 * C(q, v), over the tree tables that reach_c.py writes above this text (rk_* arrays, RK_NB
 * bodies, RK_N joint coordinates, RK_NF frames; RK_FB 1 for a floating base: body 0 on a free
 * flyer, q of RK_NQ = 7 + RK_N numbers and v of RK_NV = 6 + RK_N). The same formulas as
 * centroidal.py, wrenches.py and coriolis_tree.py: spatial velocities at the world's origin in
 * world axes, [v; w]. */

#define RK_BQ (RK_FB ? 7 : 0)
#define RK_BV (RK_FB ? 6 : 0)
#define RK_NQ (RK_BQ + RK_N)
#define RK_NV (RK_BV + RK_N)
#define RK_FREE(i) (RK_FB && (i) == 0)

#define RK_STR_(x) #x
#define RK_STR(x) RK_STR_(x)
#define RK_PASTE_(a, b) a##b
#define RK_PASTE(a, b) RK_PASTE_(a, b)

static inline void rk_cross(const double *a, const double *b, double *out)
{
    double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2],
           z = a[0] * b[1] - a[1] * b[0];
    out[0] = x; out[1] = y; out[2] = z;
}

static inline void rk_apply(const double *R, const double *x, double *out)
{
    double a = R[0] * x[0] + R[1] * x[1] + R[2] * x[2], b = R[3] * x[0] + R[4] * x[1] + R[5] * x[2],
           c = R[6] * x[0] + R[7] * x[1] + R[8] * x[2];
    out[0] = a; out[1] = b; out[2] = c;
}

static inline void rk_apply_t(const double *R, const double *x, double *out)
{
    double a = R[0] * x[0] + R[3] * x[1] + R[6] * x[2], b = R[1] * x[0] + R[4] * x[1] + R[7] * x[2],
           c = R[2] * x[0] + R[5] * x[1] + R[8] * x[2];
    out[0] = a; out[1] = b; out[2] = c;
}

static inline void rk_matmul(const double *A, const double *B, double *out)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}

/* body i's rotation (body -> world) and origin (m, world), its parent's already known */
static inline void rk_body(const double *q, int i, double (*R)[9], double (*o)[3])
{
    double th = RK_FREE(i) ? 0.0 : rk_mult[i] * q[RK_BQ + rk_coord[i]] + rk_off[i];
    double Rl[9], pl[3] = {rk_t0[i][0], rk_t0[i][1], rk_t0[i][2]};
    const double *u = rk_u[i];
    if (RK_FREE(i)) {  /* R0 R(quaternion x y z w, normalized), t0 + R0 x */
        double x = q[3], y = q[4], z = q[5], w = q[6], Rq[9], d[3];
        double k = 1.0 / (x * x + y * y + z * z + w * w);
        Rq[0] = 1 - 2 * k * (y * y + z * z); Rq[1] = 2 * k * (x * y - z * w);
        Rq[2] = 2 * k * (x * z + y * w); Rq[3] = 2 * k * (x * y + z * w);
        Rq[4] = 1 - 2 * k * (x * x + z * z); Rq[5] = 2 * k * (y * z - x * w);
        Rq[6] = 2 * k * (x * z - y * w); Rq[7] = 2 * k * (y * z + x * w);
        Rq[8] = 1 - 2 * k * (x * x + y * y);
        rk_matmul(rk_R0[i], Rq, Rl);
        rk_apply(rk_R0[i], q, d);
        for (int j = 0; j < 3; j++) pl[j] += d[j];
    } else if (rk_turns[i]) {
        /* R0 Rot(u, th) = R0 u u^T + cos th R0 (1 - u u^T) + sin th R0 [u]x (tables) */
        double c, s;
        lg_sincos(th, &s, &c);  /* inline (tree_c.py): a libm call costs a body's work */
        for (int j = 0; j < 9; j++) Rl[j] = rk_P[i][j] + c * rk_C[i][j] + s * rk_S[i][j];
    } else {
        for (int j = 0; j < 9; j++) Rl[j] = rk_R0[i][j];
    }
    if (rk_slides[i]) {
        double d[3];
        rk_apply(rk_R0[i], u, d);
        for (int j = 0; j < 3; j++) pl[j] += th * d[j];
    }
    int p = rk_parent[i];
    if (p < 0) {
        for (int j = 0; j < 9; j++) R[i][j] = Rl[j];
        for (int j = 0; j < 3; j++) o[i][j] = pl[j];
    } else {
        double d[3];
        rk_matmul(R[p], Rl, R[i]);
        rk_apply(R[p], pl, d);
        for (int j = 0; j < 3; j++) o[i][j] = o[p][j] + d[j];
    }
}

/* every body's rotation and origin */
static void rk_bodies(const double *q, double (*R)[9], double (*o)[3])
{
    for (int i = 0; i < RK_NB; i++) rk_body(q, i, R, o);
}

/* the bodies from the root out to body b (b itself last) into path, their number returned;
 * only theirs are placed: a frame's J_dot v and J^T w need no other body */
static int rk_path(const double *q, int b, int *path, double (*R)[9], double (*o)[3])
{
    int depth = 0;
    for (int i = b; i >= 0; i = rk_parent[i]) depth++;
    int k = depth;
    for (int i = b; i >= 0; i = rk_parent[i]) path[--k] = i;
    for (k = 0; k < depth; k++) rk_body(q, path[k], R, o);
    return depth;
}

/* S of body i's joint at the world's origin, world axes: [s_v; s_w] */
static inline void rk_subspace(int i, double (*R)[9], double (*o)[3], double *S)
{
    double w[3] = {0.0, 0.0, 0.0}, v[3] = {0.0, 0.0, 0.0};
    if (rk_turns[i]) {
        rk_apply(R[i], rk_u[i], w);
        rk_cross(o[i], w, v);
    }
    if (rk_slides[i]) {
        double d[3];
        rk_apply(R[i], rk_u[i], d);
        for (int j = 0; j < 3; j++) v[j] += d[j];
    }
    for (int j = 0; j < 3; j++) { S[j] = v[j]; S[3 + j] = w[j]; }
}

/* a free flyer's six columns at the world's origin, world axes (S = 1 in the base's axes):
 * S[c] = [R e_c; 0], S[3 + c] = [o x R e_c; R e_c] */
static inline void rk_free_columns(const double *R, const double *o, double (*S)[6])
{
    for (int c = 0; c < 3; c++) {
        double w[3] = {R[c], R[3 + c], R[6 + c]}, v[3];
        rk_cross(o, w, v);
        for (int j = 0; j < 3; j++) {
            S[c][j] = w[j]; S[c][3 + j] = 0.0;
            S[3 + c][j] = v[j]; S[3 + c][3 + j] = w[j];
        }
    }
}

/* the frame's rotation (frame -> world) and origin */
static inline void rk_frame(int f, double (*R)[9], double (*o)[3], double *Rf, double *p)
{
    int b = rk_fbody[f];
    if (b < 0) {
        for (int j = 0; j < 9; j++) Rf[j] = rk_fR[f][j];
        for (int j = 0; j < 3; j++) p[j] = rk_ft[f][j];
        return;
    }
    double d[3];
    rk_matmul(R[b], rk_fR[f], Rf);
    rk_apply(R[b], rk_ft[f], d);
    for (int j = 0; j < 3; j++) p[j] = o[b][j] + d[j];
}

/* [a; w_dot] of frame f at q_ddot = 0; ref 0 world, 1 local, 2 local_world_aligned */
static void rk_drift(const double *q, const double *qd, int f, int ref, double *out)
{
    double R[RK_NB][9], o[RK_NB][3], V[RK_NB][6], A[RK_NB][6];
    int b = rk_fbody[f];
    for (int j = 0; j < 6; j++) out[j] = 0.0;
    if (b < 0) return;
    int path[RK_NB], depth = rk_path(q, b, path, R, o);
    for (int k = 0; k < depth; k++) {
        const int i = path[k];
        if (RK_FREE(i)) {  /* V = S v_base; no drift of its own (V x V = 0) */
            double F[6][6];
            rk_free_columns(R[0], o[0], F);
            for (int j = 0; j < 6; j++) {
                V[0][j] = 0.0;
                A[0][j] = 0.0;
                for (int c = 0; c < 6; c++) V[0][j] += F[c][j] * qd[c];
            }
            continue;
        }
        double S[6], c[6], rate = rk_mult[i] * qd[RK_BV + rk_coord[i]];
        int p = rk_parent[i];
        rk_subspace(i, R, o, S);
        for (int j = 0; j < 6; j++) {
            V[i][j] = (p < 0 ? 0.0 : V[p][j]) + S[j] * rate;
            A[i][j] = p < 0 ? 0.0 : A[p][j];
        }
        /* [v; w] x [s_v; s_w] = [w x s_v + v x s_w; w x s_w] */
        double t1[3], t2[3];
        rk_cross(V[i] + 3, S, t1);
        rk_cross(V[i], S + 3, t2);
        rk_cross(V[i] + 3, S + 3, c + 3);
        for (int j = 0; j < 3; j++) c[j] = t1[j] + t2[j];
        for (int j = 0; j < 6; j++) A[i][j] += c[j] * rate;
    }
    double Rf[9], p[3], pd[3], pdd[3], t[3];
    rk_frame(f, R, o, Rf, p);
    const double *w = V[b] + 3, *wd = A[b] + 3;
    rk_cross(w, p, t);
    for (int j = 0; j < 3; j++) pd[j] = V[b][j] + t[j];
    rk_cross(wd, p, t);
    for (int j = 0; j < 3; j++) pdd[j] = A[b][j] + t[j];
    rk_cross(w, pd, t);
    for (int j = 0; j < 3; j++) pdd[j] += t[j];
    if (ref == 0) {  /* the point at the world's origin: p_ddot - w_dot x p - w x (w x p) */
        double wp[3], wwp[3];
        rk_cross(wd, p, t);
        rk_cross(w, p, wp);
        rk_cross(w, wp, wwp);
        for (int j = 0; j < 3; j++) { out[j] = pdd[j] - t[j] - wwp[j]; out[3 + j] = wd[j]; }
    } else if (ref == 1) {
        rk_apply_t(Rf, pdd, out);
        rk_apply_t(Rf, wd, out + 3);
    } else {
        for (int j = 0; j < 3; j++) { out[j] = pdd[j]; out[3 + j] = wd[j]; }
    }
}

/* A_g (6 x RK_N, row-major): composite bodies about the world's origin, then moved to G */
static void rk_centroidal(const double *q, double *out)
{
    double R[RK_NB][9], o[RK_NB][3], M[RK_NB], h[RK_NB][3], Ic[RK_NB][9];
    rk_bodies(q, R, o);
    for (int j = 0; j < 6 * RK_NV; j++) out[j] = 0.0;
    for (int i = 0; i < RK_NB; i++) {
        double hr[3], T[9], RJ[9];
        const double *p = o[i];
        double m = rk_m[i];
        rk_apply(R[i], rk_h[i], hr);
        rk_matmul(R[i], rk_J[i], RJ);
        for (int a = 0; a < 3; a++)  /* R J R^T, symmetric: the upper triangle, mirrored */
            for (int c = a; c < 3; c++)
                T[3 * c + a] = T[3 * a + c] = RJ[3 * a] * R[i][3 * c]
                                              + RJ[3 * a + 1] * R[i][3 * c + 1]
                                              + RJ[3 * a + 2] * R[i][3 * c + 2];
        double pp = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
        double ph = p[0] * hr[0] + p[1] * hr[1] + p[2] * hr[2];
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++)
                Ic[i][3 * a + c] = T[3 * a + c] - m * p[a] * p[c] - p[a] * hr[c] - hr[a] * p[c]
                                  + (a == c ? m * pp + 2.0 * ph : 0.0);
        for (int j = 0; j < 3; j++) h[i][j] = hr[j] + m * p[j];
        M[i] = m;
    }
    for (int i = RK_NB - 1; i >= 0; i--) {
        int p = rk_parent[i];
        if (p < 0) continue;
        M[p] += M[i];
        for (int j = 0; j < 3; j++) h[p][j] += h[i][j];
        for (int j = 0; j < 9; j++) Ic[p][j] += Ic[i][j];
    }
    double total = 0.0, G[3] = {0.0, 0.0, 0.0};
    for (int i = 0; i < RK_NB; i++) {
        if (rk_parent[i] >= 0) continue;
        total += M[i];
        for (int j = 0; j < 3; j++) G[j] += h[i][j];
    }
    for (int j = 0; j < 3; j++) G[j] /= total;
    for (int i = 0; i < RK_NB; i++) {
        double F[6][6], l[3], k[3], t[3];
        int columns = 1, first = RK_BV + rk_coord[i];
        double mult = rk_mult[i];
        if (RK_FREE(i)) {
            rk_free_columns(R[0], o[0], F);
            columns = 6, first = 0, mult = 1.0;
        } else {
            rk_subspace(i, R, o, F[0]);
        }
        for (int col = 0; col < columns; col++) {
            const double *S = F[col];
            rk_cross(S + 3, h[i], l);
            rk_cross(h[i], S, k);
            rk_apply(Ic[i], S + 3, t);
            for (int j = 0; j < 3; j++) { l[j] += M[i] * S[j]; k[j] += t[j]; }
            int c = first + col;
            for (int j = 0; j < 3; j++) {
                out[j * RK_NV + c] += mult * l[j];
                out[(3 + j) * RK_NV + c] += mult * k[j];
            }
        }
    }
    for (int c = 0; c < RK_NV; c++) {  /* k_G = k_O - G x l */
        double l[3] = {out[c], out[RK_NV + c], out[2 * RK_NV + c]}, t[3];
        rk_cross(G, l, t);
        for (int j = 0; j < 3; j++) out[(3 + j) * RK_NV + c] -= t[j];
    }
}

/* tau (RK_NV) of the wrench w = [f; m] at frame f's origin, world axes: sum k S^T [f; m + p x f]
 * (a free flyer's six: the force and the moment about the base's origin, base axes) */
static void rk_wrench(const double *q, int f, const double *w, double *out)
{
    double R[RK_NB][9], o[RK_NB][3], Rf[9], p[3], m[3];
    for (int j = 0; j < RK_NV; j++) out[j] = 0.0;
    int b = rk_fbody[f];
    if (b < 0) return;
    int path[RK_NB];
    rk_path(q, b, path, R, o);
    rk_frame(f, R, o, Rf, p);
    rk_cross(p, w, m);
    for (int j = 0; j < 3; j++) m[j] += w[3 + j];
    for (int i = b; i >= 0; i = rk_parent[i]) {
        double S[6];
        if (RK_FREE(i)) {  /* R^T f and R^T (m_O - o x f) */
            double t[3], n[3];
            rk_cross(o[0], w, t);
            for (int j = 0; j < 3; j++) n[j] = m[j] - t[j];
            rk_apply_t(R[0], w, out);
            rk_apply_t(R[0], n, out + 3);
            continue;
        }
        rk_subspace(i, R, o, S);
        out[RK_BV + rk_coord[i]] += rk_mult[i] * (S[0] * w[0] + S[1] * w[1] + S[2] * w[2]
                                                  + S[3] * m[0] + S[4] * m[1] + S[5] * m[2]);
    }
}
