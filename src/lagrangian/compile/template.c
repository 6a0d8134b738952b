/* ---- lagrangian numerics template: linear solve, kernels, DOP853, Python bindings ----
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

/* ---- Python bindings (METH_FASTCALL: a call costs well under a microsecond) ---- */

static PyObject *lg_LinAlgError = NULL;

static PyArrayObject *lg_doubles(PyObject *obj, npy_intp size, const char *what)
{
    PyArrayObject *a = (PyArrayObject *)PyArray_FROMANY(obj, NPY_DOUBLE, 0, 0, NPY_ARRAY_CARRAY_RO);
    if (a && PyArray_SIZE(a) != size) {
        PyErr_Format(PyExc_ValueError, "%s must hold %zd numbers, not %zd", what, (Py_ssize_t)size,
                     (Py_ssize_t)PyArray_SIZE(a));
        Py_DECREF(a);
        return NULL;
    }
    return a;
}

static PyObject *lg_new(int nd, npy_intp d0, npy_intp d1, npy_intp d2)
{
    npy_intp dims[3] = {d0, d1, d2};
    return PyArray_SimpleNew(nd, dims, NPY_DOUBLE);
}

/* Batch arguments (Q, V, T, P): Q and V hold N x n numbers, T holds N, P the parameters. */
typedef struct { PyArrayObject *Q, *V, *T, *P; npy_intp N; } lg_batch;

static int lg_batch_open(PyObject *const *args, Py_ssize_t nargs, lg_batch *b)
{
    memset(b, 0, sizeof *b);
    if (nargs != 4) {
        PyErr_SetString(PyExc_TypeError, "expected (Q, V, T, P)");
        return 1;
    }
    b->T = (PyArrayObject *)PyArray_FROMANY(args[2], NPY_DOUBLE, 0, 0, NPY_ARRAY_CARRAY_RO);
    if (!b->T) return 1;
    b->N = PyArray_SIZE(b->T);
    b->Q = lg_doubles(args[0], b->N * LG_N, "q");
    b->V = b->Q ? lg_doubles(args[1], b->N * LG_N, "q_dot") : NULL;
    b->P = b->V ? lg_doubles(args[3], LG_NP, "parameters") : NULL;
    return b->P == NULL;
}

static void lg_batch_close(lg_batch *b)
{
    Py_XDECREF(b->Q); Py_XDECREF(b->V); Py_XDECREF(b->T); Py_XDECREF(b->P);
}

#define LG_BATCH_PTRS(b) \
    const double *Q = (const double *)PyArray_DATA((b).Q), *V = (const double *)PyArray_DATA((b).V); \
    const double *T = (const double *)PyArray_DATA((b).T), *P = (const double *)PyArray_DATA((b).P);

static PyObject *py_parts(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    lg_batch b;
    if (lg_batch_open(args, nargs, &b)) { lg_batch_close(&b); return NULL; }
    LG_BATCH_PTRS(b)
    PyObject *M = lg_new(3, b.N, LG_N, LG_N), *f = lg_new(2, b.N, LG_N, 0);
    PyObject *J = lg_new(3, b.N, LG_M, LG_N), *g = lg_new(2, b.N, LG_M, 0);
    if (!M || !f || !J || !g) {
        Py_XDECREF(M); Py_XDECREF(f); Py_XDECREF(J); Py_XDECREF(g);
        lg_batch_close(&b);
        return NULL;
    }
    double *pM = (double *)PyArray_DATA((PyArrayObject *)M), *pf = (double *)PyArray_DATA((PyArrayObject *)f);
    double *pJ = (double *)PyArray_DATA((PyArrayObject *)J), *pg = (double *)PyArray_DATA((PyArrayObject *)g);
    double Jscratch[LG_MA * LG_N], gscratch[LG_MA];
    Py_BEGIN_ALLOW_THREADS
    for (npy_intp k = 0; k < b.N; k++)
        lg_parts(Q + k * LG_N, V + k * LG_N, T[k], P, pM + k * LG_N * LG_N, pf + k * LG_N,
                 LG_M ? pJ + k * LG_M * LG_N : Jscratch, LG_M ? pg + k * LG_M : gscratch);
    Py_END_ALLOW_THREADS
    lg_batch_close(&b);
    return Py_BuildValue("(NNNN)", M, f, J, g);
}

static PyObject *py_energy(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    lg_batch b;
    if (lg_batch_open(args, nargs, &b)) { lg_batch_close(&b); return NULL; }
    LG_BATCH_PTRS(b)
    PyObject *E = lg_new(1, b.N, 0, 0);
    if (!E) { lg_batch_close(&b); return NULL; }
    double *pE = (double *)PyArray_DATA((PyArrayObject *)E);
    for (npy_intp k = 0; k < b.N; k++) pE[k] = lg_energy(Q + k * LG_N, V + k * LG_N, T[k], P);
    lg_batch_close(&b);
    return E;
}

static PyObject *py_residual(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    lg_batch b;
    if (lg_batch_open(args, nargs, &b)) { lg_batch_close(&b); return NULL; }
    LG_BATCH_PTRS(b)
    PyObject *R = lg_new(2, b.N, LG_M, 0);
    if (!R) { lg_batch_close(&b); return NULL; }
    double *pR = (double *)PyArray_DATA((PyArrayObject *)R), scratch[LG_MA];
    for (npy_intp k = 0; k < b.N; k++)
        lg_residual(Q + k * LG_N, V + k * LG_N, T[k], P, LG_M ? pR + k * LG_M : scratch);
    lg_batch_close(&b);
    return R;
}

static PyObject *py_accelerations(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    lg_batch b;
    if (lg_batch_open(args, nargs, &b)) { lg_batch_close(&b); return NULL; }
    LG_BATCH_PTRS(b)
    PyObject *A = lg_new(2, b.N, LG_N, 0), *L = lg_new(2, b.N, LG_M, 0);
    if (!A || !L) { Py_XDECREF(A); Py_XDECREF(L); lg_batch_close(&b); return NULL; }
    double *pA = (double *)PyArray_DATA((PyArrayObject *)A), *pL = (double *)PyArray_DATA((PyArrayObject *)L);
    double scratch[LG_MA];
    int singular = 0;
    Py_BEGIN_ALLOW_THREADS
    for (npy_intp k = 0; k < b.N; k++)
        singular |= lg_accel(Q + k * LG_N, V + k * LG_N, T[k], P, pA + k * LG_N,
                             LG_M ? pL + k * LG_M : scratch);
    Py_END_ALLOW_THREADS
    lg_batch_close(&b);
    if (singular) {
        Py_DECREF(A); Py_DECREF(L);
        PyErr_SetString(lg_LinAlgError, "Singular matrix");
        return NULL;
    }
    return Py_BuildValue("(NN)", A, L);
}

/* rhs(P, t, y) -> a fresh array [q_dot, q_ddot] on every call. */
static PyObject *py_rhs(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 3) {
        PyErr_SetString(PyExc_TypeError, "expected (P, t, y)");
        return NULL;
    }
    double t = PyFloat_AsDouble(args[1]);
    if (t == -1.0 && PyErr_Occurred()) return NULL;
    PyArrayObject *P = lg_doubles(args[0], LG_NP, "parameters");
    if (!P) return NULL;
    PyArrayObject *y = lg_doubles(args[2], LG_S, "y");
    if (!y) { Py_DECREF(P); return NULL; }
    PyObject *dy = lg_new(1, LG_S, 0, 0);
    if (dy && lg_rhs(t, (const double *)PyArray_DATA(y), (const double *)PyArray_DATA(P),
                     (double *)PyArray_DATA((PyArrayObject *)dy))) {
        Py_CLEAR(dy);
        PyErr_SetString(lg_LinAlgError, "Singular matrix");
    }
    Py_DECREF(y);
    Py_DECREF(P);
    return dy;
}

/* dop853(P, t0, t1, y0, rtol, atol, t_eval or None, max_steps)
 *   -> (t, y, nfev, accepted steps, status, t_reached) */
static PyObject *py_dop853(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 8) {
        PyErr_SetString(PyExc_TypeError, "expected (P, t0, t1, y0, rtol, atol, t_eval, max_steps)");
        return NULL;
    }
    double t0 = PyFloat_AsDouble(args[1]), t1 = PyFloat_AsDouble(args[2]);
    double rtol = PyFloat_AsDouble(args[4]), atol = PyFloat_AsDouble(args[5]);
    long long max_steps = PyLong_AsLongLong(args[7]);
    if (PyErr_Occurred()) return NULL;
    PyArrayObject *P = lg_doubles(args[0], LG_NP, "parameters");
    if (!P) return NULL;
    PyArrayObject *y0 = lg_doubles(args[3], LG_S, "y0");
    if (!y0) { Py_DECREF(P); return NULL; }
    PyArrayObject *te = NULL;
    if (args[6] != Py_None) {
        te = (PyArrayObject *)PyArray_FROMANY(args[6], NPY_DOUBLE, 1, 1, NPY_ARRAY_CARRAY_RO);
        if (!te) { Py_DECREF(P); Py_DECREF(y0); return NULL; }
    }
    lg_trace out = {NULL, NULL, 0, 0};
    long long nfev = 0, accepted = 0;
    double t_reached = t0;
    int status;
    PyThreadState *save = PyEval_SaveThread();
    status = lg_dop853((const double *)PyArray_DATA(P), t0, t1, (const double *)PyArray_DATA(y0), rtol, atol,
                       te ? (const double *)PyArray_DATA(te) : NULL, te ? PyArray_SIZE(te) : 0,
                       max_steps, &out, &nfev, &accepted, &t_reached, &save);
    PyEval_RestoreThread(save);
    if (status == LG_INTERRUPTED) PyErr_Clear();  /* Ctrl-C: keep what was computed */
    Py_DECREF(P); Py_DECREF(y0); Py_XDECREF(te);
    PyObject *T = lg_new(1, out.len, 0, 0), *Y = lg_new(2, out.len, LG_S, 0);
    if (T && Y && out.len) {
        memcpy(PyArray_DATA((PyArrayObject *)T), out.t, (size_t)out.len * sizeof(double));
        memcpy(PyArray_DATA((PyArrayObject *)Y), out.y, (size_t)out.len * LG_S * sizeof(double));
    }
    free(out.t);
    free(out.y);
    if (!T || !Y) { Py_XDECREF(T); Py_XDECREF(Y); return NULL; }
    return Py_BuildValue("(NNLLid)", T, Y, nfev, accepted, status, t_reached);
}

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

/* ensemble(P, Y0, t_eval, rtol, atol, max_steps, trajectories, vector)
 *   -> (final, minimum, maximum, t_final, drift, status, t_reached, trajectory or None)
 * P: N x n_parameters, Y0: N x 2n, t_eval: the common grid (first = start, last = end). */
static PyObject *py_ensemble(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 8) {
        PyErr_SetString(PyExc_TypeError,
                        "expected (P, Y0, t_eval, rtol, atol, max_steps, trajectories, vector)");
        return NULL;
    }
    double rtol = PyFloat_AsDouble(args[3]), atol = PyFloat_AsDouble(args[4]);
    long long max_steps = PyLong_AsLongLong(args[5]);
    int trajectories = PyObject_IsTrue(args[6]), vector = PyObject_IsTrue(args[7]);
    if (PyErr_Occurred()) return NULL;
    PyArrayObject *Y0 = (PyArrayObject *)PyArray_FROMANY(args[1], NPY_DOUBLE, 0, 0, NPY_ARRAY_CARRAY_RO);
    if (!Y0) return NULL;
    npy_intp N = PyArray_SIZE(Y0) / LG_S;
    PyArrayObject *P = lg_doubles(args[0], N * LG_NP, "parameters");
    if (!P) { Py_DECREF(Y0); return NULL; }
    PyArrayObject *te = (PyArrayObject *)PyArray_FROMANY(args[2], NPY_DOUBLE, 1, 1, NPY_ARRAY_CARRAY_RO);
    if (!te) { Py_DECREF(Y0); Py_DECREF(P); return NULL; }
    npy_intp ne = PyArray_SIZE(te);
    if (ne < 1 || PyArray_SIZE(Y0) != N * LG_S) {
        PyErr_SetString(PyExc_ValueError, "Y0 must be N x 2n and t_eval hold at least one time");
        Py_DECREF(Y0); Py_DECREF(P); Py_DECREF(te);
        return NULL;
    }
    PyObject *final = lg_new(2, N, LG_S, 0), *lo = lg_new(2, N, LG_S, 0), *hi = lg_new(2, N, LG_S, 0);
    PyObject *t_final = lg_new(1, N, 0, 0), *drift = lg_new(1, N, 0, 0), *reached = lg_new(1, N, 0, 0);
    npy_intp one = N;
    PyObject *status = PyArray_SimpleNew(1, &one, NPY_INT);
    PyObject *traj = trajectories ? lg_new(3, N, ne, LG_S) : (Py_INCREF(Py_None), Py_None);
    PyObject *result = NULL;
    if (final && lo && hi && t_final && drift && reached && status && traj) {
        lg_ensemble_out o = {
            (double *)PyArray_DATA((PyArrayObject *)final), (double *)PyArray_DATA((PyArrayObject *)lo),
            (double *)PyArray_DATA((PyArrayObject *)hi), (double *)PyArray_DATA((PyArrayObject *)t_final),
            (double *)PyArray_DATA((PyArrayObject *)drift), (double *)PyArray_DATA((PyArrayObject *)reached),
            trajectories ? (double *)PyArray_DATA((PyArrayObject *)traj) : NULL,
            (int *)PyArray_DATA((PyArrayObject *)status)};
        const double *pP = (const double *)PyArray_DATA(P), *pY = (const double *)PyArray_DATA(Y0);
        const double *pt = (const double *)PyArray_DATA(te);
        PyThreadState *save = PyEval_SaveThread();
        int done;
#ifdef LG_VECTOR
        if (vector)
            done = lg_ensemble_vector(pP, pY, N, pt, ne, rtol, atol, max_steps, &o, &save);
        else
#endif
            done = lg_ensemble_scalar(pP, pY, N, pt, ne, rtol, atol, max_steps, &o, &save);
        PyEval_RestoreThread(save);
        if (done == LG_NOMEM) PyErr_NoMemory();
        else if (done == LG_INTERRUPTED) { if (!PyErr_Occurred()) PyErr_SetNone(PyExc_KeyboardInterrupt); }
        else result = Py_BuildValue("(OOOOOOOO)", final, lo, hi, t_final, drift, status, reached, traj);
    }
    Py_XDECREF(final); Py_XDECREF(lo); Py_XDECREF(hi); Py_XDECREF(t_final); Py_XDECREF(drift);
    Py_XDECREF(reached); Py_XDECREF(status); Py_XDECREF(traj);
    Py_DECREF(Y0); Py_DECREF(P); Py_DECREF(te);
    return result;
}

static PyMethodDef lg_methods[] = {
    {"parts", (PyCFunction)(void (*)(void))py_parts, METH_FASTCALL, "(Q, V, T, P) -> (M, f, Phi_q, gamma)"},
    {"energy", (PyCFunction)(void (*)(void))py_energy, METH_FASTCALL, "(Q, V, T, P) -> T + V"},
    {"residual", (PyCFunction)(void (*)(void))py_residual, METH_FASTCALL, "(Q, V, T, P) -> Phi"},
    {"accelerations", (PyCFunction)(void (*)(void))py_accelerations, METH_FASTCALL,
     "(Q, V, T, P) -> (q_ddot, lambda)"},
    {"rhs", (PyCFunction)(void (*)(void))py_rhs, METH_FASTCALL, "(P, t, y) -> [q_dot, q_ddot]"},
    {"dop853", (PyCFunction)(void (*)(void))py_dop853, METH_FASTCALL,
     "(P, t0, t1, y0, rtol, atol, t_eval, max_steps) -> (t, y, nfev, steps, status, t_reached)"},
    {"ensemble", (PyCFunction)(void (*)(void))py_ensemble, METH_FASTCALL,
     "(P, Y0, t_eval, rtol, atol, max_steps, trajectories, vector) -> (final, minimum, maximum, "
     "t_final, drift, status, t_reached, trajectory)"},
#ifdef LG_EXTRA_METHODS
    LG_EXTRA_METHODS /* more functions of a generated module (recursive.py) */
#endif
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef lg_module = {PyModuleDef_HEAD_INIT, LG_STR(LG_MODULE), NULL, -1, lg_methods};

PyMODINIT_FUNC LG_PASTE(PyInit_, LG_MODULE)(void)
{
    import_array();
    PyObject *linalg = PyImport_ImportModule("numpy.linalg");
    if (!linalg) return NULL;
    lg_LinAlgError = PyObject_GetAttrString(linalg, "LinAlgError");
    Py_DECREF(linalg);
    if (!lg_LinAlgError) return NULL;
    PyObject *m = PyModule_Create(&lg_module);
    if (m) {
        PyModule_AddIntConstant(m, "n", LG_N);
        PyModule_AddIntConstant(m, "m", LG_M);
        PyModule_AddIntConstant(m, "n_parameters", LG_NP);
#ifdef LG_VECTOR
        PyModule_AddIntConstant(m, "lanes", LG_LANES);
#else
        PyModule_AddIntConstant(m, "lanes", 1);
#endif
    }
    return m;
}
