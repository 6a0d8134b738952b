/* ---- lagrangian numerics template: linear solve, kernels, DOP853 (then template_ensemble.c,
 * template_bindings.c: the ensembles, the Python bindings; codegen.template_text) ----
 * Appended to the generated functions lg_parts / lg_energy / lg_residual (see codegen.py).
 * Convention: M q_ddot + Phi_q^T lambda = f; Phi_q q_ddot = gamma.
 */
#include <string.h>
#include <stdlib.h>

#define LG_K (LG_N + LG_M)
#define LG_MA (LG_M > 0 ? LG_M : 1)
#define LG_S (2 * LG_N)
#define LG_PASTE2(a, b) a##b
#define LG_PASTE(a, b) LG_PASTE2(a, b)
#define LG_STR2(a) #a
#define LG_STR(a) LG_STR2(a)

/* Solve A x = b in place by LU with partial pivoting (A: k x k row-major, destroyed; b becomes x).
 * Returns 1 when a pivot is exactly zero (singular matrix), else 0. */
static int lg_solve(double *A, double *b, int k)
{
    for (int c = 0; c < k; c++) {
        int piv = c;
        double best = fabs(A[c * k + c]);
        for (int r = c + 1; r < k; r++) {
            double a = fabs(A[r * k + c]);
            if (a > best) { best = a; piv = r; }
        }
        if (best == 0.0) return 1;
        if (piv != c) {
            for (int j = c; j < k; j++) {
                double s = A[c * k + j]; A[c * k + j] = A[piv * k + j]; A[piv * k + j] = s;
            }
            double s = b[c]; b[c] = b[piv]; b[piv] = s;
        }
        double inv = 1.0 / A[c * k + c];
        for (int r = c + 1; r < k; r++) {
            double l = A[r * k + c] * inv;
            if (l != 0.0) {
                for (int j = c + 1; j < k; j++) A[r * k + j] -= l * A[c * k + j];
                b[r] -= l * b[c];
            }
        }
    }
    for (int r = k - 1; r >= 0; r--) {
        double s = b[r];
        for (int j = r + 1; j < k; j++) s -= A[r * k + j] * b[j];
        b[r] = s / A[r * k + r];
    }
    return 0;
}

/* [[M, Phi_q^T], [Phi_q, 0]] [q_ddot; lambda] = [f; gamma]. Returns 1 if singular. */
static int lg_accel(const double *q, const double *v, double t, const double *p, double *qdd, double *lam)
{
    double M[LG_N * LG_N], f[LG_N], J[LG_MA * LG_N], g[LG_MA];
    lg_parts(q, v, t, p, M, f, J, g);
#if LG_M == 0
    (void)lam;
    if (lg_solve(M, f, LG_N)) return 1;
    memcpy(qdd, f, sizeof f);
#else
    double A[LG_K * LG_K], b[LG_K];
    for (int i = 0; i < LG_N; i++) {
        for (int j = 0; j < LG_N; j++) A[i * LG_K + j] = M[i * LG_N + j];
        for (int c = 0; c < LG_M; c++) A[i * LG_K + LG_N + c] = J[c * LG_N + i];
        b[i] = f[i];
    }
    for (int c = 0; c < LG_M; c++) {
        for (int j = 0; j < LG_N; j++) A[(LG_N + c) * LG_K + j] = J[c * LG_N + j];
        for (int d = 0; d < LG_M; d++) A[(LG_N + c) * LG_K + LG_N + d] = 0.0;
        b[LG_N + c] = g[c];
    }
    if (lg_solve(A, b, LG_K)) return 1;
    memcpy(qdd, b, LG_N * sizeof(double));
    memcpy(lam, b + LG_N, LG_M * sizeof(double));
#endif
    return 0;
}

/* y = [q, q_dot] -> dy = [q_dot, q_ddot]. Returns 1 if the mass (KKT) matrix is singular. */
static int lg_rhs(double t, const double *y, const double *p, double *dy)
{
    double lam[LG_MA];
    memcpy(dy, y + LG_N, LG_N * sizeof(double));
    return lg_accel(y, y + LG_N, t, p, dy + LG_N, lam);
}

/* ---- DOP853 (Hairer's coefficients, scipy's solve_ivp error control and step-size rules) ---- */
static const double DOP_A[16][16] = {
    {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.05260015195876773, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.0197250569845379, 0.0591751709536137, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.02958758547680685, 0.0, 0.08876275643042054, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.2413651341592667, 0.0, -0.8845494793282861, 0.924834003261792, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.037037037037037035, 0.0, 0.0, 0.17082860872947386, 0.12546768756682242, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.037109375, 0.0, 0.0, 0.17025221101954405, 0.06021653898045596, -0.017578125, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.03709200011850479, 0.0, 0.0, 0.17038392571223998, 0.10726203044637328, -0.015319437748624402, 0.008273789163814023, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.6241109587160757, 0.0, 0.0, -3.3608926294469414, -0.868219346841726, 27.59209969944671, 20.154067550477894, -43.48988418106996, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.47766253643826434, 0.0, 0.0, -2.4881146199716677, -0.590290826836843, 21.230051448181193, 15.279233632882423, -33.28821096898486, -0.020331201708508627, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {-0.9371424300859873, 0.0, 0.0, 5.186372428844064, 1.0914373489967295, -8.149787010746927, -18.52006565999696, 22.739487099350505, 2.4936055526796523, -3.0467644718982196, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {2.273310147516538, 0.0, 0.0, -10.53449546673725, -2.0008720582248625, -17.9589318631188, 27.94888452941996, -2.8589982771350235, -8.87285693353063, 12.360567175794303, 0.6433927460157636, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.054293734116568765, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003, -5.801203960010585, 0.3111643669578199, -0.1521609496625161, 0.20136540080403034, 0.04471061572777259, 0.0, 0.0, 0.0, 0.0},
    {0.056167502283047954, 0.0, 0.0, 0.0, 0.0, 0.0, 0.25350021021662483, -0.2462390374708025, -0.12419142326381637, 0.15329179827876568, 0.00820105229563469, 0.007567897660545699, -0.008298, 0.0, 0.0, 0.0},
    {0.03183464816350214, 0.0, 0.0, 0.0, 0.0, 0.028300909672366776, 0.053541988307438566, -0.05492374857139099, 0.0, 0.0, -0.00010834732869724932, 0.0003825710908356584, -0.00034046500868740456, 0.1413124436746325, 0.0, 0.0},
    {-0.42889630158379194, 0.0, 0.0, 0.0, 0.0, -4.697621415361164, 7.683421196062599, 4.06898981839711, 0.3567271874552811, 0.0, 0.0, 0.0, -0.0013990241651590145, 2.9475147891527724, -9.15095847217987, 0.0}
};
static const double DOP_B[12] = {0.054293734116568765, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003, -5.801203960010585, 0.3111643669578199, -0.1521609496625161, 0.20136540080403034, 0.04471061572777259};
static const double DOP_C[16] = {0.0, 0.05260015195876773, 0.0789002279381516, 0.1183503419072274, 0.2816496580927726, 0.3333333333333333, 0.25, 0.3076923076923077, 0.6512820512820513, 0.6, 0.8571428571428571, 1.0, 1.0, 0.1, 0.2, 0.7777777777777778};
static const double DOP_E3[13] = {-0.18980075407240762, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003, -5.801203960010585, -0.4226823213237919, -0.1521609496625161, 0.20136540080403034, 0.02265179219836082, 0.0};
static const double DOP_E5[13] = {0.01312004499419488, 0.0, 0.0, 0.0, 0.0, -1.2251564463762044, -0.4957589496572502, 1.6643771824549864, -0.35032884874997366, 0.3341791187130175, 0.08192320648511571, -0.022355307863886294, 0.0};
static const double DOP_D[4][16] = {
    {-8.428938276109013, 0.0, 0.0, 0.0, 0.0, 0.5667149535193777, -3.0689499459498917, 2.38466765651207, 2.117034582445028, -0.871391583777973, 2.2404374302607883, 0.6315787787694688, -0.08899033645133331, 18.148505520854727, -9.194632392478356, -4.436036387594894},
    {10.427508642579134, 0.0, 0.0, 0.0, 0.0, 242.28349177525817, 165.20045171727028, -374.5467547226902, -22.113666853125306, 7.733432668472264, -30.674084731089398, -9.332130526430229, 15.697238121770845, -31.139403219565178, -9.35292435884448, 35.81684148639408},
    {19.985053242002433, 0.0, 0.0, 0.0, 0.0, -387.0373087493518, -189.17813819516758, 527.8081592054236, -11.57390253995963, 6.8812326946963, -1.0006050966910838, 0.7777137798053443, -2.778205752353508, -60.19669523126412, 84.32040550667716, 11.99229113618279},
    {-25.69393346270375, 0.0, 0.0, 0.0, 0.0, -154.18974869023643, -231.5293791760455, 357.6391179106141, 93.40532418362432, -37.45832313645163, 104.0996495089623, 29.8402934266605, -43.53345659001114, 96.32455395918828, -39.17726167561544, -149.72683625798564}
};


enum { LG_DONE = 0, LG_MAX_STEPS = 1, LG_TOO_SMALL = 2, LG_SINGULAR = 3, LG_NOMEM = 4, LG_INTERRUPTED = 5 };

typedef struct { double *t; double *y; npy_intp len, cap; } lg_trace;

static int lg_push(lg_trace *o, double t, const double *y)
{
    if (o->len == o->cap) {
        npy_intp cap = o->cap ? 2 * o->cap : 256;
        double *nt = (double *)realloc(o->t, (size_t)cap * sizeof(double));
        if (!nt) return 1;
        o->t = nt;
        double *ny = (double *)realloc(o->y, (size_t)cap * LG_S * sizeof(double));
        if (!ny) return 1;
        o->y = ny;
        o->cap = cap;
    }
    o->t[o->len] = t;
    memcpy(o->y + o->len * LG_S, y, LG_S * sizeof(double));
    o->len++;
    return 0;
}

/* Runge-Kutta stages first..last-1 of a DOP853 step from (t, y) with step h: K[s] = f(t + c_s h,
 * y + h sum_j a_sj K[j]). Nonzero when the mass matrix is singular on the way. */
static int lg_stages(int first, int last, double t, double h, const double *y, const double *p,
                     double K[16][LG_S], double *tmp, long long *nfev)
{
    for (int s = first; s < last; s++) {
        for (int i = 0; i < LG_S; i++) {
            double acc = 0.0;
            for (int j = 0; j < s; j++) acc += DOP_A[s][j] * K[j][i];
            tmp[i] = y[i] + h * acc;
        }
        (*nfev)++;
        if (lg_rhs(t + DOP_C[s] * h, tmp, p, K[s])) return 1;
    }
    return 0;
}

/* scipy's select_initial_step (Hairer, Norsett, Wanner II.4): the first step's size from y and
 * f = y' at t0, heading for t1; -1 where the right-hand side is singular at the trial point. */
static double lg_initial_step(const double *p, double t0, double t1, const double *y,
                              const double *f, double rtol, double atol)
{
    const double dir = (t1 >= t0) ? 1.0 : -1.0;
    double d0 = 0.0, d1 = 0.0, d2 = 0.0, len = fabs(t1 - t0), tmp[LG_S], k1[LG_S];
    for (int i = 0; i < LG_S; i++) {
        double sc = atol + fabs(y[i]) * rtol;
        d0 += (y[i] / sc) * (y[i] / sc);
        d1 += (f[i] / sc) * (f[i] / sc);
    }
    d0 = sqrt(d0 / LG_S);
    d1 = sqrt(d1 / LG_S);
    double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    if (h0 > len) h0 = len;
    for (int i = 0; i < LG_S; i++) tmp[i] = y[i] + h0 * dir * f[i];
    if (lg_rhs(t0 + h0 * dir, tmp, p, k1)) return -1.0;
    for (int i = 0; i < LG_S; i++) {
        double sc = atol + fabs(y[i]) * rtol, d = (k1[i] - f[i]) / sc;
        d2 += d * d;
    }
    d2 = sqrt(d2 / LG_S) / h0;
    double h1 = (d1 <= 1e-15 && d2 <= 1e-15) ? fmax(1e-6, h0 * 1e-3)
                                             : pow(0.01 / fmax(d1, d2), 1.0 / 8.0);
    return fmin(fmin(100.0 * h0, h1), len);
}

/* Integrate from t0 to t1; records every step (te == NULL) or the dense output at te[0..ne).
 * Called without the GIL; takes it back every 256 steps to notice Ctrl-C. */
static int lg_dop853(const double *p, double t0, double t1, const double *y0, double rtol, double atol,
                     const double *te, npy_intp ne, long long max_steps, lg_trace *out,
                     long long *nfev, long long *accepted, double *t_reached, PyThreadState **save)
{
    double K[16][LG_S], y[LG_S], ynew[LG_S], tmp[LG_S], f[LG_S], F[7][LG_S];
    const double dir = (t1 >= t0) ? 1.0 : -1.0;
    const double exponent = -1.0 / 8.0;  /* -1 / (error estimator order + 1) */
    double t = t0, h_abs;
    npy_intp ie = 0;
    memcpy(y, y0, sizeof y);
    *nfev = 0;
    *accepted = 0;
    *t_reached = t0;
    (*nfev)++;
    if (lg_rhs(t, y, p, f)) return LG_SINGULAR;
    if (!te) {
        if (lg_push(out, t, y)) return LG_NOMEM;
    }
    if (t1 == t0) {
        for (; ie < ne; ie++)
            if (lg_push(out, te[ie], y)) return LG_NOMEM;
        return LG_DONE;
    }
    (*nfev)++;
    h_abs = lg_initial_step(p, t0, t1, y, f, rtol, atol);
    if (h_abs < 0.0) return LG_SINGULAR;
    for (long long steps = 0;; steps++) {
        if (steps >= max_steps) return LG_MAX_STEPS;
        if ((steps & 255) == 255) {
            PyEval_RestoreThread(*save);
            int interrupted = PyErr_CheckSignals();
            *save = PyEval_SaveThread();
            if (interrupted) return LG_INTERRUPTED;
        }
        const double min_step = 10.0 * fabs(nextafter(t, dir * INFINITY) - t);
        if (h_abs < min_step) h_abs = min_step;
        int rejected = 0;
        double h, t_new;
        for (;;) {
            if (h_abs < min_step) return LG_TOO_SMALL;
            h = h_abs * dir;
            t_new = t + h;
            if (dir * (t_new - t1) > 0) t_new = t1;
            h = t_new - t;
            h_abs = fabs(h);
            memcpy(K[0], f, sizeof f);
            if (lg_stages(1, 12, t, h, y, p, K, tmp, nfev)) return LG_SINGULAR;
            for (int i = 0; i < LG_S; i++) {
                double acc = 0.0;
                for (int j = 0; j < 12; j++) acc += DOP_B[j] * K[j][i];
                ynew[i] = y[i] + h * acc;
            }
            (*nfev)++;
            if (lg_rhs(t + h, ynew, p, K[12])) return LG_SINGULAR;
            double e5 = 0.0, e3 = 0.0;
            for (int i = 0; i < LG_S; i++) {
                double sc = atol + fmax(fabs(y[i]), fabs(ynew[i])) * rtol, a5 = 0.0, a3 = 0.0;
                for (int j = 0; j < 13; j++) {
                    a5 += K[j][i] * DOP_E5[j];
                    a3 += K[j][i] * DOP_E3[j];
                }
                a5 /= sc;
                a3 /= sc;
                e5 += a5 * a5;
                e3 += a3 * a3;
            }
            double err = (e5 == 0.0 && e3 == 0.0) ? 0.0 : h_abs * e5 / sqrt((e5 + 0.01 * e3) * LG_S);
            if (err < 1.0) {
                double factor = (err == 0.0) ? 10.0 : fmin(10.0, 0.9 * pow(err, exponent));
                if (rejected) factor = fmin(1.0, factor);
                h_abs *= factor;
                break;
            }
            h_abs *= fmax(0.2, 0.9 * pow(err, exponent));
            rejected = 1;
        }
        if (te) {
            int dense = 0;
            while (ie < ne && dir * (te[ie] - t_new) <= 0) {
                if (!dense) {  /* three extra stages and the 7th-order interpolant, as scipy */
                    if (lg_stages(13, 16, t, h, y, p, K, tmp, nfev)) return LG_SINGULAR;
                    for (int i = 0; i < LG_S; i++) {
                        double dy = ynew[i] - y[i];
                        F[0][i] = dy;
                        F[1][i] = h * K[0][i] - dy;
                        F[2][i] = 2.0 * dy - h * (K[12][i] + K[0][i]);
                        for (int r = 0; r < 4; r++) {
                            double acc = 0.0;
                            for (int j = 0; j < 16; j++) acc += DOP_D[r][j] * K[j][i];
                            F[3 + r][i] = h * acc;
                        }
                    }
                    dense = 1;
                }
                double x = (te[ie] - t) / h;
                for (int i = 0; i < LG_S; i++) {
                    double acc = 0.0;
                    for (int k = 0; k < 7; k++) {
                        acc += F[6 - k][i];
                        acc *= (k % 2 == 0) ? x : 1.0 - x;
                    }
                    tmp[i] = acc + y[i];
                }
                if (lg_push(out, te[ie], tmp)) return LG_NOMEM;
                ie++;
            }
        } else if (lg_push(out, t_new, ynew)) {
            return LG_NOMEM;
        }
        t = t_new;
        memcpy(y, ynew, sizeof y);
        memcpy(f, K[12], sizeof f);
        *t_reached = t;
        (*accepted)++;
        if (dir * (t - t1) >= 0) return LG_DONE;
    }
}
