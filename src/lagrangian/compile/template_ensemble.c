/* ---- lagrangian numerics template, part 2 (after template.c): ensembles, many members in
   one call, one by one or on vector lanes ---- */

/* ---- Ensembles: many members (parameters and initial state each) in one call ---- */

/* What a study keeps of one member integrated onto the grid te[0..ne) (ys: ne x LG_S samples):
 * final state, extremes, end time and the energy drift max|E - E0| / |E0| (relative to the
 * largest kinetic energy when E0 = 0), as simulation/invariants.py's energy_drift. */
static void lg_summary(const double *p, const double *te, npy_intp ne, const double *ys,
                       double *final, double *lo, double *hi, double *t_final, double *drift)
{
    static const double zero[LG_N > 0 ? LG_N : 1] = {0.0};
    memcpy(final, ys + (ne - 1) * LG_S, LG_S * sizeof(double));
    memcpy(lo, ys, LG_S * sizeof(double));
    memcpy(hi, ys, LG_S * sizeof(double));
    double e0 = 0.0, change = 0.0, largest_t = 0.0;
    for (npy_intp k = 0; k < ne; k++) {
        const double *y = ys + k * LG_S;
        for (int i = 0; i < LG_S; i++) {
            if (y[i] < lo[i]) lo[i] = y[i];
            if (y[i] > hi[i]) hi[i] = y[i];
        }
        double e = lg_energy(y, y + LG_N, te[k], p);
        double kinetic = e - lg_energy(y, zero, te[k], p);
        if (k == 0) e0 = e;
        change = fmax(change, fabs(e - e0));
        largest_t = fmax(largest_t, fabs(kinetic));
    }
    double scale = fabs(e0);
    if (scale <= 1e-9 * largest_t) scale = largest_t;
    *t_final = te[ne - 1];
    *drift = scale > 0 ? change / scale : 0.0;
}

static void lg_missing(double *final, double *lo, double *hi, double *t_final, double *drift,
                       double *traj, npy_intp ne)
{
    for (int i = 0; i < LG_S; i++) final[i] = lo[i] = hi[i] = NAN;
    *t_final = *drift = NAN;
    if (traj)
        for (npy_intp k = 0; k < ne * LG_S; k++) traj[k] = NAN;
}

/* Outputs of an ensemble call, one row per member. */
typedef struct {
    double *final, *lo, *hi, *t_final, *drift, *t_reached, *traj;
    int *status;
} lg_ensemble_out;

/* Members [0, N) one by one through lg_dop853 (the single-point loop itself). Returns
 * LG_INTERRUPTED on Ctrl-C, LG_NOMEM, else LG_DONE (each member's own status in out). */
static int lg_ensemble_scalar(const double *P, const double *Y0, npy_intp N, const double *te,
                              npy_intp ne, double rtol, double atol, long long max_steps,
                              lg_ensemble_out *o, PyThreadState **save)
{
    double *scratch_t = (double *)malloc((size_t)ne * sizeof(double));
    double *scratch_y = o->traj ? NULL : (double *)malloc((size_t)ne * LG_S * sizeof(double));
    if (!scratch_t || (!o->traj && !scratch_y)) { free(scratch_t); free(scratch_y); return LG_NOMEM; }
    int result = LG_DONE;
    for (npy_intp k = 0; k < N; k++) {
        if ((k & 63) == 63) {
            PyEval_RestoreThread(*save);
            int interrupted = PyErr_CheckSignals();
            *save = PyEval_SaveThread();
            if (interrupted) { result = LG_INTERRUPTED; break; }
        }
        const double *p = P + k * LG_NP;
        double *ys = o->traj ? o->traj + k * ne * LG_S : scratch_y;
        lg_trace out = {scratch_t, ys, 0, ne};  /* room for every sample: never reallocated */
        long long nfev, accepted;
        int status = lg_dop853(p, te[0], te[ne - 1], Y0 + k * LG_S, rtol, atol, te, ne, max_steps,
                               &out, &nfev, &accepted, o->t_reached + k, save);
        if (status == LG_INTERRUPTED) { result = status; break; }
        o->status[k] = status;
        if (status == LG_DONE && out.len == ne)
            lg_summary(p, te, ne, ys, o->final + k * LG_S, o->lo + k * LG_S, o->hi + k * LG_S,
                       o->t_final + k, o->drift + k);
        else
            lg_missing(o->final + k * LG_S, o->lo + k * LG_S, o->hi + k * LG_S, o->t_final + k,
                       o->drift + k, o->traj ? ys : NULL, ne);
    }
    free(scratch_t);
    free(scratch_y);
    return result;
}

#ifdef LG_VECTOR
/* ---- The same DOP853 on LG_LANES members at once, each lane with its own t, h, accept/reject
 * and dense output; a lane whose member ends takes the next member of the queue. Per lane the
 * arithmetic is lg_dop853's, in the same order. ---- */

static inline lg_vd lg_vmax(lg_vd a, lg_vd b)  /* fmax lane by lane (a NaN loses) */
{
    return lg_vsel((b > a) | (a != a), b, a);
}

/* LU with partial pivoting on every lane (lg_solve's steps; rows swapped lane by lane).
 * Returns the lanes where a pivot is exactly zero. */
static lg_vi lg_vsolve(lg_vd *A, lg_vd *b)
{
    const int k = LG_N;
    lg_vi singular = {0};
    for (int c = 0; c < k; c++) {
        lg_vd best = lg_vabs(A[c * k + c]);
        lg_vi piv = (lg_vi){0} + c;
        for (int r = c + 1; r < k; r++) {
            lg_vd a = lg_vabs(A[r * k + c]);
            lg_vi larger = a > best;
            best = lg_vsel(larger, a, best);
            piv = (lg_vi)lg_vsel(larger, (lg_vd)((lg_vi){0} + r), (lg_vd)piv);
        }
        singular |= best == 0.0;
        for (int r = c + 1; r < k; r++) {
            lg_vi swap = piv == r;
            for (int j = c; j < k; j++) {
                lg_vd x = A[c * k + j], y = A[r * k + j];
                A[c * k + j] = lg_vsel(swap, y, x);
                A[r * k + j] = lg_vsel(swap, x, y);
            }
            lg_vd x = b[c], y = b[r];
            b[c] = lg_vsel(swap, y, x);
            b[r] = lg_vsel(swap, x, y);
        }
        lg_vd inv = 1.0 / A[c * k + c];
        for (int r = c + 1; r < k; r++) {
            lg_vd l = A[r * k + c] * inv;
            for (int j = c + 1; j < k; j++) A[r * k + j] -= l * A[c * k + j];
            b[r] -= l * b[c];
        }
    }
    for (int r = k - 1; r >= 0; r--) {
        lg_vd s = b[r];
        for (int j = r + 1; j < k; j++) s -= A[r * k + j] * b[j];
        b[r] = s / A[r * k + r];
    }
    return singular;
}

static lg_vi lg_vrhs(lg_vd t, const lg_vd *y, const lg_vd *p, lg_vd *dy)
{
    lg_vd M[LG_N * LG_N], f[LG_N];
    for (int i = 0; i < LG_N; i++) dy[i] = y[LG_N + i];
    lg_vparts(y, y + LG_N, t, p, M, f);
    lg_vi singular = lg_vsolve(M, f);
    for (int i = 0; i < LG_N; i++) dy[LG_N + i] = f[i];
    return singular;
}

static lg_vi lg_vstages(int first, int last, lg_vd t, lg_vd h, const lg_vd *y, const lg_vd *p,
                        lg_vd K[16][LG_S], lg_vd *tmp)
{
    lg_vi singular = {0};
    for (int s = first; s < last; s++) {
        for (int i = 0; i < LG_S; i++) {
            lg_vd acc = LG_VD(0.0);
            for (int j = 0; j < s; j++) acc += DOP_A[s][j] * K[j][i];
            tmp[i] = y[i] + h * acc;
        }
        singular |= lg_vrhs(t + DOP_C[s] * h, tmp, p, K[s]);
    }
    return singular;
}

/* One lane: its member, where it stands, and the step control of lg_dop853. */
typedef struct {
    npy_intp member;   /* -1: idle */
    npy_intp ie;       /* next sample */
    long long steps;
    double h_abs, min_step;
    int rejected, retry;
    double *ys;        /* the member's samples */
} lg_lane;

static void lg_vfinish(lg_ensemble_out *o, const double *P, const double *te, npy_intp ne,
                       lg_lane *lane, int status, double t_reached)
{
    npy_intp k = lane->member;
    o->status[k] = status;
    o->t_reached[k] = t_reached;
    if (status == LG_DONE)
        lg_summary(P + k * LG_NP, te, ne, lane->ys, o->final + k * LG_S, o->lo + k * LG_S,
                   o->hi + k * LG_S, o->t_final + k, o->drift + k);
    else
        lg_missing(o->final + k * LG_S, o->lo + k * LG_S, o->hi + k * LG_S, o->t_final + k,
                   o->drift + k, o->traj ? lane->ys : NULL, ne);
    lane->member = -1;
}

static int lg_ensemble_vector(const double *P, const double *Y0, npy_intp N, const double *te,
                              npy_intp ne, double rtol, double atol, long long max_steps,
                              lg_ensemble_out *o, PyThreadState **save)
{
    const double t0 = te[0], t1 = te[ne - 1];
    if (t1 == t0) return lg_ensemble_scalar(P, Y0, N, te, ne, rtol, atol, max_steps, o, save);
    const double dir = (t1 >= t0) ? 1.0 : -1.0;
    const double exponent = -1.0 / 8.0;
    double *scratch = o->traj ? NULL : (double *)malloc((size_t)LG_LANES * ne * LG_S * sizeof(double));
    if (!o->traj && !scratch) return LG_NOMEM;
    lg_lane lanes[LG_LANES];
    lg_vd K[16][LG_S], y[LG_S], ynew[LG_S], tmp[LG_S], f[LG_S], F[7][LG_S], p[LG_NP > 0 ? LG_NP : 1];
    lg_vd t = LG_VD(t0);
    memset(K, 0, sizeof K);
    memset(y, 0, sizeof y);
    memset(f, 0, sizeof f);
    memset(p, 0, sizeof p);
    npy_intp next = 0;
    int result = LG_DONE;
    for (int l = 0; l < LG_LANES; l++) lanes[l].member = -1;
    for (long long round = 0;; round++) {
        /* idle lanes take the next members: the first derivative and initial step in scalar
         * code (lg_dop853's own lines) */
        for (int l = 0; l < LG_LANES; l++) {
            lg_lane *lane = lanes + l;
            while (lane->member < 0 && next < N) {
                npy_intp k = next++;
                const double *pk = P + k * LG_NP, *y0 = Y0 + k * LG_S;
                double ys[LG_S], fs[LG_S];
                memcpy(ys, y0, sizeof ys);
                lane->member = k;
                lane->ie = 0;
                lane->steps = 0;
                lane->retry = 0;
                lane->ys = o->traj ? o->traj + k * ne * LG_S : scratch + (npy_intp)l * ne * LG_S;
                if (lg_rhs(t0, ys, pk, fs)) { lg_vfinish(o, P, te, ne, lane, LG_SINGULAR, t0); continue; }
                lane->h_abs = lg_initial_step(pk, t0, t1, ys, fs, rtol, atol);
                if (lane->h_abs < 0.0) { lg_vfinish(o, P, te, ne, lane, LG_SINGULAR, t0); continue; }
                t[l] = t0;
                for (int i = 0; i < LG_S; i++) { y[i][l] = ys[i]; f[i][l] = fs[i]; }
                for (int j = 0; j < LG_NP; j++) p[j][l] = pk[j];
            }
        }
        int busy = 0;
        for (int l = 0; l < LG_LANES; l++) busy |= lanes[l].member >= 0;
        if (!busy) break;
        if ((round & 255) == 255) {
            PyEval_RestoreThread(*save);
            int interrupted = PyErr_CheckSignals();
            *save = PyEval_SaveThread();
            if (interrupted) { result = LG_INTERRUPTED; break; }
        }
        /* per lane: the start of a step (lg_dop853's checks; `retry` from here until the step is
         * accepted, so that a round redone after another lane ended changes nothing) */
        int ended = 0;
        for (int l = 0; l < LG_LANES; l++) {
            lg_lane *lane = lanes + l;
            if (lane->member < 0) continue;
            if (!lane->retry) {
                if (lane->steps >= max_steps) { lg_vfinish(o, P, te, ne, lane, LG_MAX_STEPS, t[l]); ended = 1; continue; }
                lane->min_step = 10.0 * fabs(nextafter(t[l], dir * INFINITY) - t[l]);
                if (lane->h_abs < lane->min_step) lane->h_abs = lane->min_step;
                lane->rejected = 0;
                lane->retry = 1;
            }
            if (lane->h_abs < lane->min_step) { lg_vfinish(o, P, te, ne, lane, LG_TOO_SMALL, t[l]); ended = 1; }
        }
        if (ended) continue;  /* refill the lanes that ended before stepping */
        lg_vd h = LG_VD(0.0), t_new = t, hv_abs = LG_VD(0.0);
        for (int l = 0; l < LG_LANES; l++) {
            lg_lane *lane = lanes + l;
            if (lane->member < 0) continue;
            double hl = lane->h_abs * dir, tn = t[l] + hl;
            if (dir * (tn - t1) > 0) tn = t1;
            hl = tn - t[l];
            lane->h_abs = fabs(hl);
            h[l] = hl;
            t_new[l] = tn;
            hv_abs[l] = lane->h_abs;
        }
        for (int i = 0; i < LG_S; i++) K[0][i] = f[i];
        lg_vi singular = lg_vstages(1, 12, t, h, y, p, K, tmp);
        for (int i = 0; i < LG_S; i++) {
            lg_vd acc = LG_VD(0.0);
            for (int j = 0; j < 12; j++) acc += DOP_B[j] * K[j][i];
            ynew[i] = y[i] + h * acc;
        }
        singular |= lg_vrhs(t + h, ynew, p, K[12]);
        lg_vd e5 = LG_VD(0.0), e3 = LG_VD(0.0);
        for (int i = 0; i < LG_S; i++) {
            lg_vd sc = atol + lg_vmax(lg_vabs(y[i]), lg_vabs(ynew[i])) * rtol;
            lg_vd a5 = LG_VD(0.0), a3 = LG_VD(0.0);
            for (int j = 0; j < 13; j++) {
                a5 += K[j][i] * DOP_E5[j];
                a3 += K[j][i] * DOP_E3[j];
            }
            a5 /= sc;
            a3 /= sc;
            e5 += a5 * a5;
            e3 += a3 * a3;
        }
        /* accept or reject, lane by lane */
        int accepted[LG_LANES], dense_wanted = 0;
        for (int l = 0; l < LG_LANES; l++) {
            lg_lane *lane = lanes + l;
            accepted[l] = 0;
            if (lane->member < 0) continue;
            if (singular[l]) { lg_vfinish(o, P, te, ne, lane, LG_SINGULAR, t[l]); continue; }
            double err = (e5[l] == 0.0 && e3[l] == 0.0)
                             ? 0.0 : hv_abs[l] * e5[l] / sqrt((e5[l] + 0.01 * e3[l]) * LG_S);
            if (err < 1.0) {
                double factor = (err == 0.0) ? 10.0 : fmin(10.0, 0.9 * pow(err, exponent));
                if (lane->rejected) factor = fmin(1.0, factor);
                lane->h_abs *= factor;
                lane->retry = 0;
                accepted[l] = 1;
                dense_wanted |= lane->ie < ne && dir * (te[lane->ie] - t_new[l]) <= 0;
            } else {
                lane->h_abs *= fmax(0.2, 0.9 * pow(err, exponent));
                lane->rejected = 1;
            }
        }
        if (dense_wanted) {  /* three extra stages and the 7th-order interpolant, as lg_dop853 */
            lg_vi dense_singular = lg_vstages(13, 16, t, h, y, p, K, tmp);
            for (int i = 0; i < LG_S; i++) {
                lg_vd dy = ynew[i] - y[i];
                F[0][i] = dy;
                F[1][i] = h * K[0][i] - dy;
                F[2][i] = 2.0 * dy - h * (K[12][i] + K[0][i]);
                for (int r = 0; r < 4; r++) {
                    lg_vd acc = LG_VD(0.0);
                    for (int j = 0; j < 16; j++) acc += DOP_D[r][j] * K[j][i];
                    F[3 + r][i] = h * acc;
                }
            }
            for (int l = 0; l < LG_LANES; l++) {
                lg_lane *lane = lanes + l;
                if (!accepted[l] || !(lane->ie < ne && dir * (te[lane->ie] - t_new[l]) <= 0)) continue;
                if (dense_singular[l]) {
                    accepted[l] = 0;
                    lg_vfinish(o, P, te, ne, lane, LG_SINGULAR, t[l]);
                    continue;
                }
                while (lane->ie < ne && dir * (te[lane->ie] - t_new[l]) <= 0) {
                    double x = (te[lane->ie] - t[l]) / h[l];
                    double *out = lane->ys + lane->ie * LG_S;
                    for (int i = 0; i < LG_S; i++) {
                        double acc = 0.0;
                        for (int k = 0; k < 7; k++) {
                            acc += F[6 - k][i][l];
                            acc *= (k % 2 == 0) ? x : 1.0 - x;
                        }
                        out[i] = acc + y[i][l];
                    }
                    lane->ie++;
                }
            }
        }
        for (int l = 0; l < LG_LANES; l++) {
            lg_lane *lane = lanes + l;
            if (!accepted[l]) continue;
            t[l] = t_new[l];
            for (int i = 0; i < LG_S; i++) { y[i][l] = ynew[i][l]; f[i][l] = K[12][i][l]; }
            lane->steps++;
            if (dir * (t[l] - t1) >= 0) lg_vfinish(o, P, te, ne, lane, LG_DONE, t[l]);
        }
    }
    free(scratch);
    return result;
}
#endif
