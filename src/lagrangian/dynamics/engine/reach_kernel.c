/* J_dot q_dot of a frame, the centroidal momentum matrix, a wrench's generalized forces and
 * C(q, v), over a tree given at run time: an rk_model, read once from the tree's description D
 * (tree/description.py's layout, the same array as the tree kernel's: joint.h reads it and
 * places each joint) and two small tables of frames and of C's pattern that reach_c.py builds
 * (checked by reach_bindings.c's rk_model_from). nb bodies, n joint coordinates, nf frames; fb 1
 * for a floating base: body 0 on a free flyer, q of nq = 7 + n numbers and v of nv = 6 + n. The
 * same formulas as centroidal.py, wrenches.py and coriolis_tree.py: spatial velocities at the
 * world's origin in world axes, [v; w]. Each body's axes are its canonical ones (its joint about
 * z), in which D holds its inertia and the tables its frames. */

#include "spatial.h"
#include "joint.h"

#define RK_MAX_WRENCHES 16  /* more: the bindings refuse, the caller adds J^T w one by one */
#define RK_MAX_BODIES 40000  /* a bound only so that no size below overflows an int (C's
                                 nv x nv numbers a state) */

typedef struct {
    int nb, n, fb, nf, cset, nczero;  /* cset 0 where a mimic joint shares a coordinate */
    int bq, bv, nq, nv;               /* the base's 7 and 6 numbers of q and v (else 0) */
    tk_tree t;                        /* the description (joint.h), body records at t.body */
    /* per body, read out of D once: parent (-1: the ground, always before it), coordinate
       (its number in v after the base's), multiplier, mass (kg), first moment h (kg m, 3)
       and inertia J (kg m^2, 9, about its origin), in its canonical axes */
    const int *parent, *coord;
    const double *mult, *m, *h, *J;
    int nquat;                        /* the quaternions in q: the base's, each ball's */
    const int *quat;                  /* where each begins in q */
    const int *fbody;                 /* per frame: its body (-1: the ground) */
    const int *czero;                 /* the entries of C that no body's pass sets (cset) */
    const double *fR, *ft;            /* per frame: rotation (9) and translation (3) in its body */
    double qlow, qhigh;               /* |quaternion|^2 within these, else numpy names it */
    size_t work1;                     /* one state's workspace, bytes (rk_work_size) */
} rk_model;

#define RK_FREE(i) (md->fb && (i) == 0)
#define RK_BODY(i) (md->t.body + (size_t)(i) * TK_STRIDE)  /* body i's record in D */

/* An output entry that one joint's column fills: set where no two joints share a coordinate
 * (cset), added to where a mimic joint's coordinate is another's (the output zeroed first) */
#define RK_CPUT(entry, value)                  \
    do {                                       \
        if (md->cset) (entry) = (value);       \
        else (entry) += (value);               \
    } while (0)

#define RK_STR_(x) #x
#define RK_STR(x) RK_STR_(x)
#define RK_PASTE_(a, b) a##b
#define RK_PASTE(a, b) RK_PASTE_(a, b)
#define RK_ROUND(bytes) (((bytes) + 63) / 64 * 64)  /* a workspace's parts 64-byte aligned */

/* joint.h's and spatial.h's number type and names: the core's (RK_T, RK_FN) */
#define SP_T RK_T
#define JT_T RK_T
#define JT_FN(name) RK_FN(jt_##name)
#define JT_C(x) RK_C(x)
#define JT_SINCOS RK_SINCOS

/* The core below (to the end of reach_inverse.c) is emitted twice by reach_c.py: on one state
 * (rk_*, RK_T double) and on LG_LANES states at once (rk4_*, RK_T lg_v4, GCC/Clang vector
 * extensions). RK_FN(name) names a function, RK_C(x) a number as an RK_T, RK_SINCOS the sine
 * and cosine of an RK_T. Every branch depends on the tree alone, never on a state: the lanes
 * take the same path. Helpers with a suffix take a table's doubles: _k a constant matrix,
 * _v a constant vector. Each function works in an RK_FN(work), sized from the model
 * (RK_FN(work_size)): on its thread's stack where it fits (reach_batch.c's RK_STACK_BYTES),
 * else on the heap. */
/* RK_CORE_BEGIN */
/* JT_CORE: joint.h's core, here */

/* a function's workspace: every body's rotation and origin, the path to a body, and x, the
 * function's own arrays (one function at a time on a workspace, so they share it: a drift's
 * V and A, A_g's h and I_c, the centre of mass's H, C's rk_cwork, inverse dynamics' V, A, F, S
 * and a wrench's tau); mass nb doubles, set nv flags (the lanes' Jacobian) */
typedef struct {
    RK_T (*R)[9], (*o)[3], *x;
    double *mass;
    int *path;
    unsigned char *set;
} RK_FN(work);

static size_t RK_FN(cwork_size)(const rk_model *md);

/* the RK_Ts of x: the largest of the functions' own arrays */
static size_t RK_FN(work_x)(const rk_model *md)
{
    size_t x = 24 * (size_t)md->nb, c = (RK_FN(cwork_size)(md) + sizeof(RK_T) - 1) / sizeof(RK_T);
    if (x < c) x = c;
    return x < (size_t)md->nv ? (size_t)md->nv : x;
}

/* the bytes of a workspace, each part 64-byte aligned */
static size_t RK_FN(work_size)(const rk_model *md)
{
    const size_t nb = (size_t)md->nb;
    return RK_ROUND(12 * nb * sizeof(RK_T)) + RK_ROUND(RK_FN(work_x)(md) * sizeof(RK_T))
           + RK_ROUND(nb * sizeof(double)) + RK_ROUND(nb * sizeof(int)) + RK_ROUND((size_t)md->nv);
}

/* the workspace's parts in ``block`` (64-byte aligned, RK_FN(work_size) bytes) */
static inline void RK_FN(work_at)(const rk_model *md, void *block, RK_FN(work) *w)
{
    const size_t nb = (size_t)md->nb;
    char *at = (char *)block;
    w->R = (RK_T (*)[9])at;
    w->o = (RK_T (*)[3])(at + 9 * nb * sizeof(RK_T));
    at += RK_ROUND(12 * nb * sizeof(RK_T));
    w->x = (RK_T *)at;
    at += RK_ROUND(RK_FN(work_x)(md) * sizeof(RK_T));
    w->mass = (double *)at;
    at += RK_ROUND(nb * sizeof(double));
    w->path = (int *)at;
    at += RK_ROUND(nb * sizeof(int));
    w->set = (unsigned char *)at;
}

/* body i's rotation (body -> world) and origin (m, world), its parent's already known */
static inline __attribute__((always_inline)) void RK_FN(body)(const rk_model *md, const RK_T *q,
                                                              int i, RK_T (*R)[9], RK_T (*o)[3])
{
    const int p = md->parent[i];
    RK_FN(jt_placed)(&md->t, RK_BODY(i), q, p < 0 ? NULL : R[p], p < 0 ? NULL : o[p], R[i],
                     o[i]);
}

/* every body's rotation and origin */
static void RK_FN(bodies)(const rk_model *md, const RK_T *q, RK_T (*R)[9], RK_T (*o)[3])
{
    for (int i = 0; i < md->nb; i++) RK_FN(body)(md, q, i, R, o);
}

/* the bodies from the root out to body b (b itself last) into path, their number returned;
 * only theirs are placed: a frame's J_dot v and J^T w need no other body */
static int RK_FN(path)(const rk_model *md, const RK_T *q, int b, int *path, RK_T (*R)[9],
                       RK_T (*o)[3])
{
    int depth = 0;
    for (int i = b; i >= 0; i = md->parent[i]) depth++;
    int k = depth;
    for (int i = b; i >= 0; i = md->parent[i]) path[--k] = i;
    for (k = 0; k < depth; k++) RK_FN(body)(md, q, path[k], R, o);
    return depth;
}

/* S of body i's joint of one number per unit theta at the world's origin, world axes:
 * [s_v; s_w] (joint.h's columns) */
#define RK_SUBSPACE(md, i, R, o, S) \
    ((void)RK_FN(jt_columns)(RK_BODY(i), (R)[i], (o)[i], (RK_T (*)[6])(S)))

/* whether body i's joint (not the floating base) has several columns: a ball, a free flyer
   below the root */
#define RK_MANY(md, i) (TK_BALL(RK_BODY(i)) || TK_FLYER(RK_BODY(i)))

/* a free flyer's six columns at the world's origin, world axes (S = 1 in the base's axes) */
#define RK_FREE_COLUMNS(md, R, o, S) ((void)RK_FN(jt_columns)(RK_BODY(0), (R), (o), (S)))

/* a joint's columns at the world's origin, world axes (joint.h), and the first coordinate
 * they fill: a free flyer's six (at the root or below it), a ball's three, else one (times the
 * joint's multiplier) */
static inline __attribute__((always_inline)) int RK_FN(columns)(const rk_model *md, int i,
                                                                RK_T (*R)[9], RK_T (*o)[3],
                                                                RK_T (*F)[6], int *first,
                                                                double *mult)
{
    const double *b = RK_BODY(i);
    *first = RK_FREE(i) ? 0 : md->bv + md->coord[i];
    *mult = TK_FREE(b) || TK_BALL(b) || TK_FLYER(b) ? 1.0 : md->mult[i];
    return RK_FN(jt_columns)(b, R[i], o[i], F);
}

/* the frame's rotation (frame -> world) and origin */
static inline void RK_FN(frame)(const rk_model *md, int f, RK_T (*R)[9], RK_T (*o)[3], RK_T *Rf,
                                RK_T *p)
{
    int b = md->fbody[f];
    if (b < 0) {
        for (int j = 0; j < 9; j++) Rf[j] = RK_C(md->fR[9 * f + j]);
        for (int j = 0; j < 3; j++) p[j] = RK_C(md->ft[3 * f + j]);
        return;
    }
    RK_T d[3];
    SP_MATMUL(R[b], md->fR + 9 * f, Rf);
    SP_APPLY(R[b], md->ft + 3 * f, d);
    for (int j = 0; j < 3; j++) p[j] = o[b][j] + d[j];
}

/* the frame's origin alone (J^T w and inverse dynamics need no frame rotation) */
static inline void RK_FN(frame_origin)(const rk_model *md, int f, RK_T (*R)[9], RK_T (*o)[3],
                                       RK_T *p)
{
    int b = md->fbody[f];
    RK_T d[3];
    SP_APPLY(R[b], md->ft + 3 * f, d);
    for (int j = 0; j < 3; j++) p[j] = o[b][j] + d[j];
}

/* [a; w_dot] of frame f at q_ddot = 0; ref 0 world, 1 local, 2 local_world_aligned */
static void RK_FN(drift)(const rk_model *md, RK_FN(work) *work, const RK_T *q, const RK_T *qd,
                         int f, int ref, RK_T *out)
{
    RK_T (*R)[9] = work->R, (*o)[3] = work->o, (*V)[6] = (RK_T (*)[6])work->x,
         (*A)[6] = V + md->nb;
    int b = md->fbody[f], *path = work->path;
    for (int j = 0; j < 6; j++) out[j] = RK_C(0.0);
    if (b < 0) return;
    const int depth = RK_FN(path)(md, q, b, path, R, o);
    for (int k = 0; k < depth; k++) {
        const int i = path[k];
        if (RK_FREE(i)) {  /* V = S v_base; no drift of its own (V x V = 0) */
            RK_T F[6][6];
            RK_FREE_COLUMNS(md, R[0], o[0], F);
            for (int j = 0; j < 6; j++) {
                V[0][j] = RK_C(0.0);
                A[0][j] = RK_C(0.0);
                for (int c = 0; c < 6; c++) V[0][j] += F[c][j] * qd[c];
            }
            continue;
        }
        /* V = V_p + sum S theta_dot, A = A_p + sum (V x S) theta_dot: each column fixed in
           its body (a ball's three, a flyer's six) moves with it */
        RK_T F[6][6];
        int first, p = md->parent[i];
        double mult;
        const int columns = RK_FN(columns)(md, i, R, o, F, &first, &mult);
        for (int j = 0; j < 6; j++) {
            V[i][j] = p < 0 ? RK_C(0.0) : V[p][j];
            A[i][j] = p < 0 ? RK_C(0.0) : A[p][j];
        }
        for (int col = 0; col < columns; col++)
            for (int j = 0; j < 6; j++) V[i][j] += F[col][j] * (mult * qd[first + col]);
        for (int col = 0; col < columns; col++) {
            /* [v; w] x [s_v; s_w] = [w x s_v + v x s_w; w x s_w] */
            const RK_T *S = F[col], rate = mult * qd[first + col];
            RK_T c[6], t1[3], t2[3];
            SP_CROSS(V[i] + 3, S, t1);
            SP_CROSS(V[i], S + 3, t2);
            SP_CROSS(V[i] + 3, S + 3, c + 3);
            for (int j = 0; j < 3; j++) c[j] = t1[j] + t2[j];
            for (int j = 0; j < 6; j++) A[i][j] += c[j] * rate;
        }
    }
    RK_T Rf[9], p[3], pd[3], pdd[3], t[3];
    RK_FN(frame)(md, f, R, o, Rf, p);
    const RK_T *w = V[b] + 3, *wd = A[b] + 3;
    SP_CROSS(w, p, t);
    for (int j = 0; j < 3; j++) pd[j] = V[b][j] + t[j];
    SP_CROSS(wd, p, t);
    for (int j = 0; j < 3; j++) pdd[j] = A[b][j] + t[j];
    SP_CROSS(w, pd, t);
    for (int j = 0; j < 3; j++) pdd[j] += t[j];
    if (ref == 0) {  /* the point at the world's origin: p_ddot - w_dot x p - w x (w x p) */
        RK_T wp[3], wwp[3];
        SP_CROSS(wd, p, t);
        SP_CROSS(w, p, wp);
        SP_CROSS(w, wp, wwp);
        for (int j = 0; j < 3; j++) { out[j] = pdd[j] - t[j] - wwp[j]; out[3 + j] = wd[j]; }
    } else if (ref == 1) {
        SP_APPLY_T(Rf, pdd, out);
        SP_APPLY_T(Rf, wd, out + 3);
    } else {
        for (int j = 0; j < 3; j++) { out[j] = pdd[j]; out[3 + j] = wd[j]; }
    }
}

/* tau (nv) of the wrench w = [f; m] at frame f's origin, world axes: sum k S^T [f; m + p x f]
 * (a free flyer's six: the force and the moment about the base's origin, base axes) */
static void RK_FN(wrench)(const rk_model *md, RK_FN(work) *work, const RK_T *q, int f,
                          const RK_T *w, RK_T *out)
{
    RK_T (*R)[9] = work->R, (*o)[3] = work->o, p[3], m[3];
    for (int j = 0; j < md->nv; j++) out[j] = RK_C(0.0);
    int b = md->fbody[f];
    if (b < 0) return;
    RK_FN(path)(md, q, b, work->path, R, o);
    RK_FN(frame_origin)(md, f, R, o, p);
    SP_CROSS(p, w, m);
    for (int j = 0; j < 3; j++) m[j] += w[3 + j];
    for (int i = b; i >= 0; i = md->parent[i]) {
        if (RK_FREE(i)) {  /* R^T f and R^T (m_O - o x f) */
            RK_T t[3], n[3];
            SP_CROSS(o[0], w, t);
            for (int j = 0; j < 3; j++) n[j] = m[j] - t[j];
            SP_APPLY_T(R[0], w, out);
            SP_APPLY_T(R[0], n, out + 3);
            continue;
        }
        RK_T F[6][6];
        int first;
        double mult;
        const int columns = RK_FN(columns)(md, i, R, o, F, &first, &mult);
        for (int col = 0; col < columns; col++) {
            const RK_T *S = F[col];
            out[first + col] += mult * (S[0] * w[0] + S[1] * w[1] + S[2] * w[2]
                                        + S[3] * m[0] + S[4] * m[1] + S[5] * m[2]);
        }
    }
}

/* A_g (6 x nv, row-major): composite bodies about the world's origin (mass M, first
 * moment h, rotational inertia J_O as its six numbers xx yy zz xy xz yz), each column's
 * momentum [l; k_O] then moved to the centre of mass G: k_G = k_O - G x l */
static void RK_FN(centroidal)(const rk_model *md, RK_FN(work) *work, const RK_T *q, RK_T *out)
{
    RK_T (*R)[9] = work->R, (*o)[3] = work->o, (*h)[3] = (RK_T (*)[3])work->x,
         (*Ic)[6] = (RK_T (*)[6])(work->x + 3 * md->nb);
    double *M = work->mass;
    RK_FN(bodies)(md, q, R, o);
    if (!md->cset)  /* else every column is one joint's, set once below */
        for (int j = 0; j < 6 * md->nv; j++) out[j] = RK_C(0.0);
    for (int i = 0; i < md->nb; i++) {
        RK_T hr[3], RJ[9], T[6];
        const RK_T *p = o[i];
        const double m = md->m[i];
        SP_APPLY(R[i], md->h + 3 * i, hr);
        SP_MATMUL(R[i], md->J + 9 * i, RJ);
        static const int ra[6] = {0, 1, 2, 0, 0, 1}, rc[6] = {0, 1, 2, 1, 2, 2};
        for (int e = 0; e < 6; e++) {  /* R J R^T, symmetric */
            const int a = ra[e], c = rc[e];
            T[e] = RJ[3 * a] * R[i][3 * c] + RJ[3 * a + 1] * R[i][3 * c + 1]
                   + RJ[3 * a + 2] * R[i][3 * c + 2];
        }
        for (int j = 0; j < 3; j++) h[i][j] = hr[j] + m * p[j];
        /* J_O = R J R^T - p h^T - hr p^T + (p.h + p.hr) 1, h = hr + m p */
        RK_T diag = p[0] * (h[i][0] + hr[0]) + p[1] * (h[i][1] + hr[1]) + p[2] * (h[i][2] + hr[2]);
        for (int e = 0; e < 6; e++) {
            const int a = ra[e], c = rc[e];
            Ic[i][e] = T[e] - p[a] * h[i][c] - hr[a] * p[c] + (e < 3 ? diag : RK_C(0.0));
        }
        M[i] = m;
    }
    for (int i = md->nb - 1; i >= 0; i--) {
        int p = md->parent[i];
        if (p < 0) continue;
        M[p] += M[i];
        for (int j = 0; j < 3; j++) h[p][j] += h[i][j];
        for (int j = 0; j < 6; j++) Ic[p][j] += Ic[i][j];
    }
    double total = 0.0;
    RK_T G[3] = {RK_C(0.0), RK_C(0.0), RK_C(0.0)};
    for (int i = 0; i < md->nb; i++) {
        if (md->parent[i] >= 0) continue;
        total += M[i];
        for (int j = 0; j < 3; j++) G[j] += h[i][j];
    }
    for (int j = 0; j < 3; j++) G[j] /= total;
    for (int i = 0; i < md->nb; i++) {
        RK_T F[6][6];
        int first;
        double mult;
        const int columns = RK_FN(columns)(md, i, R, o, F, &first, &mult);
        const RK_T *J = Ic[i];
        for (int col = 0; col < columns; col++) {
            const RK_T *S = F[col];
            RK_T l[3], k[3], t[3], g[3];
            SP_CROSS(S + 3, h[i], l);  /* l = M s_v + s_w x h, k = h x s_v + J_O s_w */
            SP_CROSS(h[i], S, k);
            t[0] = J[0] * S[3] + J[3] * S[4] + J[4] * S[5];
            t[1] = J[3] * S[3] + J[1] * S[4] + J[5] * S[5];
            t[2] = J[4] * S[3] + J[5] * S[4] + J[2] * S[5];
            for (int j = 0; j < 3; j++) { l[j] += M[i] * S[j]; k[j] += t[j]; }
            SP_CROSS(G, l, g);
            const int c = first + col;
            for (int j = 0; j < 3; j++) {
                RK_CPUT(out[j * md->nv + c], mult * l[j]);
                RK_CPUT(out[(3 + j) * md->nv + c], mult * (k[j] - g[j]));
            }
        }
    }
}
