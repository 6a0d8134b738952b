/* The joint kinds of every engine module, once (joint.h): the tree description D's layout
   (tree/description.py builds it; every joint in canonical axes, turning and sliding about its
   body's z), its reader tk_open, and each kind's placement (R, p of a body in its parent from
   its coordinates) and motion subspace S. The three modules (tree_kernel.c, reach_kernel.c,
   derivatives_kernel.c) ask only these for a joint; a new kind is a new code in description.py's
   JOINT_CODES and its branch here. Units SI.

   Kinds: 0 revolute, 1 prismatic, 2 free flyer (body 0 only: q[0:3] its origin, q[3:7] its
   quaternion x y z w; v[0:6] its twist in its own axes, linear then angular), 3 helical (turns
   and slides by its lead), 4 ball (q[QCOORD:QCOORD + 4] a unit quaternion w x y z, MuJoCo's;
   v[COORD:COORD + 3] the angular velocity in the body's axes), 5 a free flyer below the root
   (a URDF floating joint between two links, Pinocchio's JointModelFreeFlyer anywhere:
   q[QCOORD:QCOORD + 7] x y z in the parent's joint frame, then its quaternion x y z w, R = R0
   R(q), p = t0 + R0 (x, y, z); v[COORD:COORD + 6] its linear then angular velocity relative
   to its parent, in its own axes). Others: theta = k q[c] + offset,
   R = R0 Rot(z, theta), p = t0 + R0 e_z lead theta (lead 1 prismatic, the pitch helical).

   The part before JT_CORE_BEGIN is read once; the part after it is emitted in each module's
   core (on one state and on LG_LANES states), over the module's JT_T (its number type),
   JT_FN(name) (its function names), JT_C(x) (a constant as a JT_T) and JT_SINCOS. */

#define TK_HEADER 8     /* nb, n, gravity vector g*dir (3, world axes), mimic flag, floating
                           flag, quaternion tolerance */
#define TK_STRIDE 64    /* numbers per body record */
/* a body record's fields */
#define TK_PARENT 0
#define TK_KIND 1       /* 0 revolute, 1 prismatic, 2 free flyer (body 0 only), 3 helical,
                           4 ball, 5 free flyer below the root */
#define TK_COORD 2      /* its (first) number in v, after the base's */
#define TK_MULT 3
#define TK_OFFSET 4
#define TK_R0 5         /* 9, row-major */
#define TK_T0 14        /* 3 */
#define TK_AXIS 17      /* 3 */
#define TK_MASS 20
#define TK_H 21         /* 3: first moment m c about the body origin */
#define TK_J 24         /* 9: inertia about the body origin */
#define TK_PERM 33      /* 3: where R0 is a signed permutation, each row's nonzero column */
#define TK_SIGN 36      /* 3: that entry, +-1 */
#define TK_PERMUTED 39  /* 1 where R0 is a signed permutation (description.py) */
#define TK_QCOORD 40    /* its (first) number in q, after the base's */
#define TK_ROW 41       /* 3: where R0 is a signed permutation, each column's nonzero row */
#define TK_ROWSIGN 44   /* 3: that entry, +-1 */
#define TK_AXES 47      /* 9: A, the canonical axes -> the body's own (its link's), row-major */
#define TK_IDENTITY 56  /* 1 where R0 is exactly the identity */
#define TK_COLUMN 57    /* a ball's or a free flyer below the root's record made one per column
                           (derivatives_c.py's description): 1, 2, ... the column, one velocity
                           number each; 0 the whole joint */
#define TK_LEAD 61      /* the slide along u per unit theta: 1 prismatic, pitch (m/rad) helical */
#define TK_FLAGS 62     /* a module's own copy only (tk_open_marked): the record's kind and
                           whether R0 is a signed permutation, as an int64's bits */
/* the kinds as the description gives them: what checks a description (tk_open) reads */
#define TK_KIND_TURNS(b) ((b)[TK_KIND] == 0.0 || (b)[TK_KIND] == 3.0)
#define TK_KIND_SLIDES(b) ((b)[TK_KIND] == 1.0 || (b)[TK_KIND] == 3.0)
#define TK_KIND_FREE(b) ((b)[TK_KIND] == 2.0)
#define TK_KIND_BALL(b) ((b)[TK_KIND] == 4.0)
#define TK_KIND_FLYER(b) ((b)[TK_KIND] == 5.0)
/* the same, and R0's form, as one integer's bits in a module's marked copy: what the
   algorithms read (a kind test each a double comparison or two, a tenth of a call's time) */
enum { TK_F_TURNS = 1, TK_F_SLIDES = 2, TK_F_FREE = 4, TK_F_BALL = 8, TK_F_FLYER = 16,
       TK_F_PERMUTED = 32 };
static inline long long tk_flags(const double *b)
{
    long long flags;
    memcpy(&flags, b + TK_FLAGS, sizeof flags);
    return flags;
}
#define TK_TURNS(b) (tk_flags(b) & TK_F_TURNS)
#define TK_SLIDES(b) (tk_flags(b) & TK_F_SLIDES)
#define TK_FREE(b) (tk_flags(b) & TK_F_FREE)
#define TK_BALL(b) (tk_flags(b) & TK_F_BALL)
#define TK_FLYER(b) (tk_flags(b) & TK_F_FLYER)
#define TK_IS_PERMUTED(b) (tk_flags(b) & TK_F_PERMUTED)

typedef struct {
    int nb, n, mimic, fb, bq, bv, nq, nv;  /* bq, bv: the base's numbers before the joints' */
    int balls;  /* ball joints: each one more number in q than in v */
    int flyers;  /* free flyers below the root: each 7 numbers in q, 6 in v */
    double qtol;
    const double *g, *tau0, *body;
} tk_tree;

/* t from the description d of size numbers; -1 where d is not a tree's (sizes, a parent before
   its child, coordinates in range, a known kind) */
static int tk_open(const double *d, Py_ssize_t size, tk_tree *t)
{
    if (size < TK_HEADER) return -1;
    t->nb = (int)d[0];
    t->n = (int)d[1];
    t->mimic = d[5] != 0.0;
    t->fb = d[6] != 0.0;
    t->qtol = d[7];
    t->bq = t->fb ? 7 : 0;
    t->bv = t->fb ? 6 : 0;
    t->g = d + 2;
    t->tau0 = d + TK_HEADER;
    t->body = d + TK_HEADER + t->n;
    if (t->nb < 1 || t->n < (t->fb ? 0 : 1)
        || size != TK_HEADER + t->n + (Py_ssize_t)t->nb * TK_STRIDE)
        return -1;
    t->balls = t->flyers = 0;
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        if (TK_KIND_BALL(b) && b[TK_COLUMN] <= 1.0) t->balls++;  /* a ball's columns: one ball */
        if (TK_KIND_FLYER(b) && b[TK_COLUMN] <= 1.0) t->flyers++;
    }
    t->nq = t->bq + t->n + t->balls + t->flyers;
    t->nv = t->bv + t->n;
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        if (!(b[TK_PARENT] >= -1 && b[TK_PARENT] < i))
            return -1;
        if (t->fb && i == 0) {  /* the free flyer, and only it, on the ground */
            if (!TK_KIND_FREE(b) || b[TK_PARENT] != -1) return -1;
        } else if (TK_KIND_BALL(b)) {
            const double column = b[TK_COLUMN];  /* a whole ball's three numbers, or one */
            if (!(column == 0.0 || column == 1.0 || column == 2.0 || column == 3.0)
                || !(b[TK_COORD] >= 0 && b[TK_COORD] + (column > 0.0 ? 4.0 - column : 3.0) <= t->n
                     && b[TK_QCOORD] >= 0
                  && b[TK_QCOORD] + 4 <= t->nq - t->bq))
                return -1;
        } else if (TK_KIND_FLYER(b)) {
            const double column = b[TK_COLUMN];  /* a whole flyer's six numbers, or one */
            if (!(column >= 0.0 && column <= 6.0 && column == (int)column)
                || !(b[TK_COORD] >= 0 && b[TK_COORD] + (column > 0.0 ? 7.0 - column : 6.0) <= t->n
                     && b[TK_QCOORD] >= 0
                  && b[TK_QCOORD] + 7 <= t->nq - t->bq))
                return -1;
        } else if (!(b[TK_COORD] >= 0 && b[TK_COORD] < t->n)
                   || !(b[TK_QCOORD] >= 0 && b[TK_QCOORD] < t->nq - t->bq)
                   || !(TK_KIND_TURNS(b) || TK_KIND_SLIDES(b))) {
            return -1;
        }
    }
    return 0;
}

/* tk_open on a module's own copy d of a description it has checked (tk_open), each record's
   kind marked first in its TK_FLAGS (the algorithms' reads) */
static int tk_open_marked(double *d, Py_ssize_t size, tk_tree *t)
{
    if (tk_open(d, size, t)) return -1;
    for (int i = 0; i < t->nb; i++) {
        double *b = d + TK_HEADER + t->n + (size_t)i * TK_STRIDE;
        long long flags = (TK_KIND_TURNS(b) ? TK_F_TURNS : 0)
                          | (TK_KIND_SLIDES(b) ? TK_F_SLIDES : 0)
                          | (TK_KIND_FREE(b) ? TK_F_FREE : 0) | (TK_KIND_BALL(b) ? TK_F_BALL : 0)
                          | (TK_KIND_FLYER(b) ? TK_F_FLYER : 0)
                          | (b[TK_PERMUTED] != 0.0 ? TK_F_PERMUTED : 0);
        memcpy(b + TK_FLAGS, &flags, sizeof flags);
    }
    return 0;
}

/* Whether every ball joint and free flyer below the root of t is one record (TK_COLUMN 0): the
   algorithms that take them whole (all but the derivatives kernel, which takes their columns) */
static int tk_whole_balls(const tk_tree *t)
{
    for (int i = 0; i < t->nb; i++) {
        const double *b = t->body + i * TK_STRIDE;
        if ((TK_KIND_BALL(b) || TK_KIND_FLYER(b)) && b[TK_COLUMN] != 0.0) return 0;
    }
    return 1;
}

/* Whether every finite state's ball-joint and below-the-root flyer quaternions are unit within
   the tolerance (``states`` states of q, ``step`` apart; a split joint's on its first record),
   else 0 and the front names the joint, the state and its norm (tree/spherical.py). */
static int tk_unit_balls(const tk_tree *t, const double *q, Py_ssize_t states, Py_ssize_t step)
{
    for (Py_ssize_t k = 0; k < states; k++) {
        const double *x = q + k * step;
        int finite = 1;
        for (int i = 0; i < t->nq; i++) finite &= isfinite(x[i]) != 0;
        if (!finite) continue;
        for (int i = 0; i < t->nb; i++) {
            const double *b = t->body + i * TK_STRIDE;
            if (!(TK_KIND_BALL(b) || TK_KIND_FLYER(b)) || b[TK_COLUMN] > 1.0) continue;
            /* a ball's w x y z, a flyer's x y z w after its x, y, z */
            const double *e = x + t->bq + (int)b[TK_QCOORD] + (TK_KIND_FLYER(b) ? 3 : 0);
            const double norm = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3]);
            if (!(fabs(norm - 1.0) <= t->qtol)) return 0;
        }
    }
    return 1;
}

/* S = ((0, 0, s_w), (0, 0, s_v)) per unit rate of q (the multiplier k included), about the
   joint's z, of a joint of one number (not a free flyer's, not a ball's): the tree's numbers
   alone. */
static inline void tk_subspace(const double *b, double *sw, double *sv)
{
    *sw = TK_TURNS(b) ? b[TK_MULT] : 0.0;
    *sv = TK_SLIDES(b) ? b[TK_MULT] * b[TK_LEAD] : 0.0;
}

/* JT_CORE_BEGIN */
/* R = R0 E(x, y, z, s): E the rotation of the quaternion (x, y, z, s = its scalar part), made
   unit here (a free flyer's, a ball joint's); R0 NULL: the identity, R = E */
static inline void JT_FN(turned)(const double *R0, JT_T x, JT_T y, JT_T z, JT_T s, JT_T *R)
{
    const JT_T k = 2.0 / (x * x + y * y + z * z + s * s);
    const JT_T E[9] = {1.0 - k * (y * y + z * z), k * (x * y - z * s), k * (x * z + y * s),
                       k * (x * y + z * s), 1.0 - k * (x * x + z * z), k * (y * z - x * s),
                       k * (x * z - y * s), k * (y * z + x * s), 1.0 - k * (x * x + y * y)};
    if (!R0) {
        for (int r = 0; r < 9; r++) R[r] = E[r];
        return;
    }
    for (int r = 0; r < 3; r++)
        for (int col = 0; col < 3; col++)
            R[3 * r + col] = R0[3 * r] * E[col] + R0[3 * r + 1] * E[3 + col]
                             + R0[3 * r + 2] * E[6 + col];
}

/* theta = k q[c] + offset of body b's joint of one number at the configuration q */
static inline __attribute__((always_inline)) JT_T JT_FN(angle)(const tk_tree *t, const double *b,
                                                               const JT_T *restrict q)
{
    return b[TK_MULT] * q[t->bq + (int)b[TK_QCOORD]] + b[TK_OFFSET];
}

/* Body b's R (body -> parent axes) and p (its origin in the parent) at the configuration q
   (the whole state's, the base's numbers first), and theta's cos, sin (1, 0 for a joint that
   does not turn about z); ``given`` (a constant): a turning joint's cos, sin already in
   *cos_, *sin_ (computed with the other joints' on the vector unit). */
static inline __attribute__((always_inline)) void JT_FN(place_sines)(const tk_tree *t,
                                                                     const double *b,
                                                                     const JT_T *restrict q,
                                                                     JT_T *R, JT_T *p,
                                                                     JT_T *cos_, JT_T *sin_,
                                                                     const int given)
{
    const double *R0 = b + TK_R0;
    if (TK_FREE(b) || TK_FLYER(b)) {  /* R0 R(quaternion x y z w, normalized), t0 + R0 x */
        /* the base's numbers first in q, or one below the root's among the joints' */
        const JT_T *x = TK_FREE(b) ? q : q + t->bq + (int)b[TK_QCOORD];
        if (b[TK_IDENTITY] != 0.0) {  /* the usual free flyer, at the root link's own axes */
            JT_FN(turned)(NULL, x[3], x[4], x[5], x[6], R);
            for (int r = 0; r < 3; r++) p[r] = x[r] + b[TK_T0 + r];
        } else {
            JT_FN(turned)(R0, x[3], x[4], x[5], x[6], R);
            for (int r = 0; r < 3; r++)
                p[r] = R0[3 * r] * x[0] + R0[3 * r + 1] * x[1] + R0[3 * r + 2] * x[2];
            for (int r = 0; r < 3; r++) p[r] += b[TK_T0 + r];
        }
        *cos_ = JT_C(1.0);
        *sin_ = JT_C(0.0);
        return;
    }
    if (TK_BALL(b)) {  /* R0 R(quaternion w x y z, normalized), p = t0 */
        const JT_T *e = q + t->bq + (int)b[TK_QCOORD];
        JT_FN(turned)(b[TK_IDENTITY] != 0.0 ? NULL : R0, e[1], e[2], e[3], e[0], R);
        for (int r = 0; r < 3; r++) p[r] = JT_C(b[TK_T0 + r]);
        *cos_ = JT_C(1.0);
        *sin_ = JT_C(0.0);
        return;
    }
    const JT_T theta = JT_FN(angle)(t, b, q);
    if (TK_TURNS(b)) {
        /* sine and cosine written out here: a libm call cost as much as the rest of an
           arm's mass matrix */
        JT_T sn, cs;
        if (given) {
            cs = *cos_;
            sn = *sin_;
        } else {
            JT_SINCOS(theta, &sn, &cs);
            *cos_ = cs;
            *sin_ = sn;
        }
        if (TK_IS_PERMUTED(b)) {  /* row r of R0 Rot(z) is +-row PERM[r] of Rot(z) */
            for (int r = 0; r < 3; r++) {
                const int k = (int)b[TK_PERM + r];
                const double e = b[TK_SIGN + r];
                JT_T *row = R + 3 * r;
                if (k == 0) { row[0] = e * cs; row[1] = -e * sn; row[2] = JT_C(0.0); }
                else if (k == 1) { row[0] = e * sn; row[1] = e * cs; row[2] = JT_C(0.0); }
                else { row[0] = JT_C(0.0); row[1] = JT_C(0.0); row[2] = JT_C(e); }
            }
        } else {  /* columns: cos R0 e_x + sin R0 e_y, cos R0 e_y - sin R0 e_x, R0 e_z */
            for (int r = 0; r < 3; r++) {
                R[3 * r] = cs * R0[3 * r] + sn * R0[3 * r + 1];
                R[3 * r + 1] = cs * R0[3 * r + 1] - sn * R0[3 * r];
                R[3 * r + 2] = JT_C(R0[3 * r + 2]);
            }
        }
    } else {
        *cos_ = JT_C(1.0);
        *sin_ = JT_C(0.0);
        for (int r = 0; r < 9; r++) R[r] = JT_C(R0[r]);
    }
    for (int r = 0; r < 3; r++) p[r] = JT_C(b[TK_T0 + r]);
    if (TK_SLIDES(b)) {  /* along R0 e_z by lead theta (a prismatic joint's lead 1) */
        const JT_T slide = TK_TURNS(b) ? b[TK_LEAD] * theta : theta;
        for (int r = 0; r < 3; r++) p[r] += R0[3 * r + 2] * slide;
    }
}

static inline __attribute__((always_inline)) void JT_FN(place)(const tk_tree *t,
                                                               const double *b,
                                                               const JT_T *restrict q,
                                                               JT_T *R, JT_T *p, JT_T *cos_,
                                                               JT_T *sin_)
{
    JT_FN(place_sines)(t, b, q, R, p, cos_, sin_, 0);
}

/* Body b's rotation Rw (body -> world) and origin ow in the world from its parent's (Rp, op)
   and its own R, p, cos, sin (JT_FN(place)): where R0 is a signed permutation, column k of
   Rp R0 is +-column ROW[k] of Rp, two of them then turned (12 products, not 27; R unread). */
static inline __attribute__((always_inline)) void JT_FN(world)(const double *b, const JT_T *Rp,
                                                               const JT_T *op, const JT_T *R,
                                                               const JT_T *p, JT_T cs, JT_T sn,
                                                               JT_T *restrict Rw,
                                                               JT_T *restrict ow)
{
    JT_T d[3];
    if (TK_IS_PERMUTED(b) && !TK_BALL(b) && !TK_FREE(b)) {
        const int r0 = (int)b[TK_ROW], r1 = (int)b[TK_ROW + 1], r2 = (int)b[TK_ROW + 2];
        const double e0 = b[TK_ROWSIGN], e1 = b[TK_ROWSIGN + 1], e2 = b[TK_ROWSIGN + 2];
        if (TK_TURNS(b)) {  /* the signs exact: (e cos) x = cos (e x) bit for bit */
            const JT_T c0 = e0 * cs, s0 = e0 * sn, c1 = e1 * cs, s1 = e1 * sn;
            for (int x = 0; x < 3; x++) {
                const JT_T a0 = Rp[3 * x + r0], a1 = Rp[3 * x + r1];
                Rw[3 * x] = c0 * a0 + s1 * a1;
                Rw[3 * x + 1] = c1 * a1 - s0 * a0;
                Rw[3 * x + 2] = e2 * Rp[3 * x + r2];
            }
        } else {
            for (int x = 0; x < 3; x++) {
                Rw[3 * x] = e0 * Rp[3 * x + r0];
                Rw[3 * x + 1] = e1 * Rp[3 * x + r1];
                Rw[3 * x + 2] = e2 * Rp[3 * x + r2];
            }
        }
    } else {
        for (int r = 0; r < 3; r++)
            for (int col = 0; col < 3; col++)
                Rw[3 * r + col] = Rp[3 * r] * R[col] + Rp[3 * r + 1] * R[3 + col]
                                  + Rp[3 * r + 2] * R[6 + col];
    }
    for (int r = 0; r < 3; r++)
        d[r] = Rp[3 * r] * p[0] + Rp[3 * r + 1] * p[1] + Rp[3 * r + 2] * p[2];
    for (int r = 0; r < 3; r++) ow[r] = op[r] + d[r];
}

/* Body b's rotation Rw and origin ow in the world from its parent's (Rp, op; NULL: the
   ground's, the world's axes) at the configuration q, for the modules that work in world
   axes: where R0 is a signed permutation, from theta alone (no R in the parent's axes). */
static inline __attribute__((always_inline)) void JT_FN(placed)(const tk_tree *t,
                                                                const double *b,
                                                                const JT_T *restrict q,
                                                                const JT_T *Rp, const JT_T *op,
                                                                JT_T *restrict Rw,
                                                                JT_T *restrict ow)
{
    JT_T cs, sn;
    if (!Rp) {
        JT_FN(place)(t, b, q, Rw, ow, &cs, &sn);
        return;
    }
    if (TK_IS_PERMUTED(b) && !TK_BALL(b) && !TK_FREE(b)) {
        const JT_T theta = b[TK_MULT] * q[t->bq + (int)b[TK_QCOORD]] + b[TK_OFFSET];
        JT_T p[3];
        cs = JT_C(1.0);
        sn = JT_C(0.0);
        if (TK_TURNS(b)) JT_SINCOS(theta, &sn, &cs);
        for (int r = 0; r < 3; r++) p[r] = JT_C(b[TK_T0 + r]);
        if (TK_SLIDES(b)) {  /* as JT_FN(place) */
            const JT_T slide = TK_TURNS(b) ? b[TK_LEAD] * theta : theta;
            for (int r = 0; r < 3; r++) p[r] += b[TK_R0 + 3 * r + 2] * slide;
        }
        JT_FN(world)(b, Rp, op, NULL, p, cs, sn, Rw, ow);
        return;
    }
    JT_T R[9], p[3];
    JT_FN(place)(t, b, q, R, p, &cs, &sn);
    JT_FN(world)(b, Rp, op, R, p, cs, sn, Rw, ow);
}

/* Body b's joint's motion per unit rate at the world's origin in world axes, [s_v; s_w] a
   column, from its rotation R (body -> world) and origin o: a free flyer's six (its twist in
   its own axes: [R e_c; 0], then [o x R e_c; R e_c]; one below the root's the same), a ball's three (its angular velocity in
   its own axes: [o x R e_c; R e_c]), else one about the world axis a = R e_z: [o x a (+ lead
   a, helical); a] where it turns, [a; 0] where it only slides; their count. */
static inline __attribute__((always_inline)) int JT_FN(columns)(const double *b, const JT_T *R,
                                                                const JT_T *o, JT_T (*S)[6])
{
    if (TK_FREE(b) || TK_FLYER(b)) {
        for (int c = 0; c < 3; c++) {
            JT_T w[3] = {R[c], R[3 + c], R[6 + c]}, v[3];
            SP_CROSS(o, w, v);
            for (int j = 0; j < 3; j++) {
                S[c][j] = w[j]; S[c][3 + j] = JT_C(0.0);
                S[3 + c][j] = v[j]; S[3 + c][3 + j] = w[j];
            }
        }
        return 6;
    }
    if (TK_BALL(b)) {
        for (int c = 0; c < 3; c++) {
            JT_T w[3] = {R[c], R[3 + c], R[6 + c]}, v[3];
            SP_CROSS(o, w, v);
            for (int j = 0; j < 3; j++) { S[c][j] = v[j]; S[c][3 + j] = w[j]; }
        }
        return 3;
    }
    const JT_T d[3] = {R[2], R[5], R[8]};
    JT_T *s = S[0];
    if (TK_TURNS(b)) {
        SP_CROSS(o, d, s);
        for (int j = 0; j < 3; j++) s[3 + j] = d[j];
        if (TK_SLIDES(b))  /* a helical joint: and along the axis by its lead */
            for (int j = 0; j < 3; j++) s[j] += b[TK_LEAD] * d[j];
    } else {
        for (int j = 0; j < 3; j++) { s[j] = d[j]; s[3 + j] = JT_C(0.0); }
    }
    return 1;
}
