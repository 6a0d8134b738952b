/* A frame's placement and Jacobian, the centre of mass and its Jacobian, on one state (RK_FN:
 * in the core reach_c.py emits twice, on one state and on LG_LANES states at once), from
 * reach_kernel.c's walks: the same numbers as frames.py's numpy, as Pinocchio's
 * updateFramePlacement, getFrameJacobian, centerOfMass and jacobianCenterOfMass. */

/* frame f's placement [[R, p], [0, 1]] (4 x 4, row-major; R frame -> world, p its origin) */
static void RK_FN(placement)(const rk_model *md, RK_FN(work) *work, const RK_T *q, int f,
                             RK_T *out)
{
    RK_T (*R)[9] = work->R, (*o)[3] = work->o, Rf[9], p[3];
    if (md->fbody[f] >= 0) RK_FN(path)(md, q, md->fbody[f], work->path, R, o);
    RK_FN(frame)(md, f, R, o, Rf, p);
    for (int a = 0; a < 3; a++) {
        for (int c = 0; c < 3; c++) out[4 * a + c] = Rf[3 * a + c];
        out[4 * a + 3] = p[a];
        out[12 + a] = RK_C(0.0);
    }
    out[15] = RK_C(1.0);
}

/* frame f's Jacobian (6 x nv, row-major, linear rows first): a joint's column [s_v; s_w]
 * at the world's origin is the velocity of the point there (ref 0, world); the frame origin's
 * is s_v + s_w x p (ref 2, local_world_aligned), in the frame's axes for ref 1 (local). The
 * columns of the joints on the frame's path are set (RK_CPUT) and only the others zeroed:
 * zeroing all first was a seventh of a batch. */
static void RK_FN(jacobian)(const rk_model *md, RK_FN(work) *work, const RK_T *q, int f, int ref,
                            RK_T *out)
{
    RK_T (*R)[9] = work->R, (*o)[3] = work->o, Rf[9], p[3];
    const int b = md->fbody[f], marks = md->cset && !RK_ONE_STATE;
    unsigned char *set = work->set;
    if (b < 0) {  /* a frame on the ground: no joint moves it */
        for (int j = 0; j < 6 * md->nv; j++) out[j] = RK_C(0.0);
        return;
    }
    if (marks) __builtin_memset(set, 0, (size_t)md->nv);
    else for (int j = 0; j < 6 * md->nv; j++) out[j] = RK_C(0.0);
    int *path = work->path, depth = RK_FN(path)(md, q, b, path, R, o);
    if (ref == 1) RK_FN(frame)(md, f, R, o, Rf, p);
    else RK_FN(frame_origin)(md, f, R, o, p);
    for (int k = 0; k < depth; k++) {
        RK_T F[6][6];
        int first;
        double mult;
        const int columns = RK_FN(columns)(md, path[k], R, o, F, &first, &mult);
        for (int col = 0; col < columns; col++) {
            const RK_T *S = F[col];
            RK_T v[3], w[3], t[3];
            for (int j = 0; j < 3; j++) { v[j] = S[j]; w[j] = S[3 + j]; }
            if (ref != 0) {
                SP_CROSS(w, p, t);
                for (int j = 0; j < 3; j++) v[j] += t[j];
            }
            if (ref == 1) {
                SP_APPLY_T(Rf, v, t);
                for (int j = 0; j < 3; j++) v[j] = t[j];
                SP_APPLY_T(Rf, w, t);
                for (int j = 0; j < 3; j++) w[j] = t[j];
            }
            const int c = first + col;
            for (int j = 0; j < 3; j++) {
                RK_CPUT(out[j * md->nv + c], mult * v[j]);
                RK_CPUT(out[(3 + j) * md->nv + c], mult * w[j]);
            }
            if (marks) set[c] = 1;
        }
    }
    if (marks)
        for (int c = 0; c < md->nv; c++)
            if (!set[c])
                for (int j = 0; j < 6; j++) out[j * md->nv + c] = RK_C(0.0);
}

/* each body's mass and first moment about the world's origin (kg, kg m; world axes), summed
 * over its subtree when ``subtrees``; the total mass (the bodies welded to the ground not
 * among them) */
static double RK_FN(moments)(const rk_model *md, const RK_T *q, RK_T (*R)[9], RK_T (*o)[3],
                             double *mass, RK_T (*H)[3], int subtrees)
{
    RK_FN(bodies)(md, q, R, o);
    double total = 0.0;
    for (int i = 0; i < md->nb; i++) {
        RK_T hr[3];
        SP_APPLY(R[i], md->h + 3 * i, hr);
        for (int j = 0; j < 3; j++) H[i][j] = md->m[i] * o[i][j] + hr[j];
        mass[i] = md->m[i];
        total += md->m[i];
    }
    if (subtrees)
        for (int i = md->nb - 1; i >= 0; i--) {
            const int p = md->parent[i];
            if (p < 0) continue;
            mass[p] += mass[i];
            for (int j = 0; j < 3; j++) H[p][j] += H[i][j];
        }
    return total;
}

/* the centre of mass (m, world): sum m_i c_i / sum m_i */
static void RK_FN(com)(const rk_model *md, RK_FN(work) *work, const RK_T *q, RK_T *out)
{
    RK_T (*R)[9] = work->R, (*o)[3] = work->o, (*H)[3] = (RK_T (*)[3])work->x;
    double *mass = work->mass;
    const double total = RK_FN(moments)(md, q, R, o, mass, H, 0);
    for (int j = 0; j < 3; j++) {
        RK_T s = RK_C(0.0);
        for (int i = 0; i < md->nb; i++) s += H[i][j];
        out[j] = s / total;
    }
}

/* J_c (3 x nv, row-major): a joint's column moves its subtree, mass M_k and first moment
 * H_k, rigidly: M J_c's column is M_k s_v + s_w x H_k (O(n), not a point Jacobian per body) */
static void RK_FN(com_jacobian)(const rk_model *md, RK_FN(work) *work, const RK_T *q, RK_T *out)
{
    RK_T (*R)[9] = work->R, (*o)[3] = work->o, (*H)[3] = (RK_T (*)[3])work->x;
    double *mass = work->mass;
    const double total = RK_FN(moments)(md, q, R, o, mass, H, 1);
    if (!md->cset)  /* else every column is one joint's, set once below */
        for (int j = 0; j < 3 * md->nv; j++) out[j] = RK_C(0.0);
    for (int i = 0; i < md->nb; i++) {
        RK_T F[6][6];
        int first;
        double mult;
        const int columns = RK_FN(columns)(md, i, R, o, F, &first, &mult);
        for (int col = 0; col < columns; col++) {
            RK_T l[3];
            SP_CROSS(F[col] + 3, H[i], l);
            for (int j = 0; j < 3; j++)
                RK_CPUT(out[j * md->nv + first + col], mult * (mass[i] * F[col][j] + l[j]) / total);
        }
    }
}
