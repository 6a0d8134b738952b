/* J_dot q_dot of a frame, the centroidal momentum matrix and a wrench's generalized forces,
 * over the tree tables that reach_c.py writes above this text (rk_* arrays, RK_NB bodies,
 * RK_N coordinates, RK_NF frames). The same formulas as centroidal.py and wrenches.py:
 * spatial velocities at the world's origin in world axes, [v; w]. */

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

/* each body's rotation (body -> world) and origin (m, world) */
static void rk_bodies(const double *q, double (*R)[9], double (*o)[3])
{
    for (int i = 0; i < RK_NB; i++) {
        double th = rk_mult[i] * q[rk_coord[i]] + rk_off[i];
        double Rl[9], pl[3] = {rk_t0[i][0], rk_t0[i][1], rk_t0[i][2]};
        const double *u = rk_u[i];
        if (rk_turns[i]) {
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
    rk_bodies(q, R, o);
    for (int i = 0; i <= b; i++) {
        double S[6], c[6], rate = rk_mult[i] * qd[rk_coord[i]];
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
    for (int j = 0; j < 6 * RK_N; j++) out[j] = 0.0;
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
        double S[6], l[3], k[3], t[3];
        rk_subspace(i, R, o, S);
        rk_cross(S + 3, h[i], l);
        rk_cross(h[i], S, k);
        rk_apply(Ic[i], S + 3, t);
        for (int j = 0; j < 3; j++) { l[j] += M[i] * S[j]; k[j] += t[j]; }
        int c = rk_coord[i];
        for (int j = 0; j < 3; j++) {
            out[j * RK_N + c] += rk_mult[i] * l[j];
            out[(3 + j) * RK_N + c] += rk_mult[i] * k[j];
        }
    }
    for (int c = 0; c < RK_N; c++) {  /* k_G = k_O - G x l */
        double l[3] = {out[c], out[RK_N + c], out[2 * RK_N + c]}, t[3];
        rk_cross(G, l, t);
        for (int j = 0; j < 3; j++) out[(3 + j) * RK_N + c] -= t[j];
    }
}

/* tau (RK_N) of the wrench w = [f; m] at frame f's origin, world axes: sum k S^T [f; m + p x f] */
static void rk_wrench(const double *q, int f, const double *w, double *out)
{
    double R[RK_NB][9], o[RK_NB][3], Rf[9], p[3], m[3];
    for (int j = 0; j < RK_N; j++) out[j] = 0.0;
    int b = rk_fbody[f];
    if (b < 0) return;
    rk_bodies(q, R, o);
    rk_frame(f, R, o, Rf, p);
    rk_cross(p, w, m);
    for (int j = 0; j < 3; j++) m[j] += w[3 + j];
    for (int i = b; i >= 0; i = rk_parent[i]) {
        double S[6];
        rk_subspace(i, R, o, S);
        out[rk_coord[i]] += rk_mult[i] * (S[0] * w[0] + S[1] * w[1] + S[2] * w[2]
                                          + S[3] * m[0] + S[4] * m[1] + S[5] * m[2]);
    }
}

/* -- Python bindings: arrays (..., n) of float64, one output row per state ------------------ */

static PyArrayObject *rk_input(PyObject *x, int last, const char *name)
{
    PyArrayObject *a;
    if (PyArray_CheckExact(x) && PyArray_TYPE((PyArrayObject *)x) == NPY_DOUBLE
            && PyArray_IS_C_CONTIGUOUS((PyArrayObject *)x) && PyArray_ISALIGNED((PyArrayObject *)x)
            && PyArray_NDIM((PyArrayObject *)x) >= 1) {
        a = (PyArrayObject *)x;  /* the usual case: taken as it is, no conversion */
        Py_INCREF(a);
    } else {
        a = (PyArrayObject *)PyArray_FROMANY(x, NPY_DOUBLE, 1, 0, NPY_ARRAY_IN_ARRAY);
    }
    if (!a) return NULL;
    int nd = PyArray_NDIM(a);
    if (PyArray_DIMS(a)[nd - 1] != last) {
        PyErr_Format(PyExc_ValueError, "%s: expected %d values along the last axis", name, last);
        Py_DECREF(a);
        return NULL;
    }
    return a;
}

static PyObject *rk_output(PyArrayObject *like, int tail0, int tail1)
{
    npy_intp dims[NPY_MAXDIMS];
    int nd = PyArray_NDIM(like) - 1;
    for (int k = 0; k < nd; k++) dims[k] = PyArray_DIMS(like)[k];
    dims[nd++] = tail0;
    if (tail1) dims[nd++] = tail1;
    return PyArray_SimpleNew(nd, dims, NPY_DOUBLE);
}

static int rk_same_batch(PyArrayObject *a, PyArrayObject *b, const char *name)
{
    int nd = PyArray_NDIM(a);
    if (PyArray_NDIM(b) != nd) goto bad;
    for (int k = 0; k < nd - 1; k++)
        if (PyArray_DIMS(a)[k] != PyArray_DIMS(b)[k]) goto bad;
    return 1;
bad:
    PyErr_Format(PyExc_ValueError, "%s: batch shapes differ", name);
    return 0;
}

static PyObject *rk_py_drift(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 4) { PyErr_SetString(PyExc_TypeError, "drift(Q, V, frame, ref)"); return NULL; }
    int f = (int)PyLong_AsLong(args[2]), ref = (int)PyLong_AsLong(args[3]);
    if (PyErr_Occurred()) return NULL;
    if (f < 0 || f >= RK_NF) { PyErr_SetString(PyExc_ValueError, "frame: out of range"); return NULL; }
    PyArrayObject *Q = rk_input(args[0], RK_N, "q");
    if (!Q) return NULL;
    PyArrayObject *V = rk_input(args[1], RK_N, "v");
    if (!V || !rk_same_batch(Q, V, "v")) { Py_DECREF(Q); Py_XDECREF(V); return NULL; }
    PyObject *out = rk_output(Q, 6, 0);
    if (out) {
        npy_intp count = PyArray_SIZE(Q) / RK_N;
        const double *q = PyArray_DATA(Q), *v = PyArray_DATA(V);
        double *y = PyArray_DATA((PyArrayObject *)out);
        for (npy_intp k = 0; k < count; k++) rk_drift(q + k * RK_N, v + k * RK_N, f, ref, y + 6 * k);
    }
    Py_DECREF(Q); Py_DECREF(V);
    return out;
}

static PyObject *rk_py_centroidal(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 1) { PyErr_SetString(PyExc_TypeError, "centroidal(Q)"); return NULL; }
    PyArrayObject *Q = rk_input(args[0], RK_N, "q");
    if (!Q) return NULL;
    PyObject *out = rk_output(Q, 6, RK_N);
    if (out) {
        npy_intp count = PyArray_SIZE(Q) / RK_N;
        const double *q = PyArray_DATA(Q);
        double *y = PyArray_DATA((PyArrayObject *)out);
        for (npy_intp k = 0; k < count; k++) rk_centroidal(q + k * RK_N, y + 6 * RK_N * k);
    }
    Py_DECREF(Q);
    return out;
}

/* wrench(Q, frame, W, OUT, sign): OUT += sign J^T w, in place (OUT float64, contiguous, of
 * Q's shape); W (6,) for every state or one row per state */
static PyObject *rk_py_wrench(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 5) { PyErr_SetString(PyExc_TypeError, "wrench(Q, frame, W, OUT, sign)"); return NULL; }
    int f = (int)PyLong_AsLong(args[1]);
    double sign = PyFloat_AsDouble(args[4]);
    if (PyErr_Occurred()) return NULL;
    if (f < 0 || f >= RK_NF) { PyErr_SetString(PyExc_ValueError, "frame: out of range"); return NULL; }
    if (!PyArray_Check(args[3])) { PyErr_SetString(PyExc_ValueError, "out: not an array"); return NULL; }
    PyArrayObject *out = (PyArrayObject *)args[3];
    PyArrayObject *Q = rk_input(args[0], RK_N, "q");
    if (!Q) return NULL;
    PyArrayObject *W = rk_input(args[2], 6, "f_ext");
    if (!W) { Py_DECREF(Q); return NULL; }
    int shared = PyArray_NDIM(W) == 1;
    if ((!shared && !rk_same_batch(Q, W, "f_ext"))
            || PyArray_TYPE(out) != NPY_DOUBLE || !PyArray_ISCARRAY(out)
            || PyArray_NDIM(out) != PyArray_NDIM(Q)
            || !PyArray_CompareLists(PyArray_DIMS(out), PyArray_DIMS(Q), PyArray_NDIM(Q))) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "out: not of q's shape");
        Py_DECREF(Q); Py_DECREF(W);
        return NULL;
    }
    npy_intp count = PyArray_SIZE(Q) / RK_N;
    const double *q = PyArray_DATA(Q), *w = PyArray_DATA(W);
    double *y = PyArray_DATA(out), tau[RK_N];
    for (npy_intp k = 0; k < count; k++) {
        rk_wrench(q + k * RK_N, f, w + (shared ? 0 : 6 * k), tau);
        for (int j = 0; j < RK_N; j++) y[RK_N * k + j] += sign * tau[j];
    }
    Py_DECREF(Q); Py_DECREF(W);
    Py_RETURN_NONE;
}

static PyMethodDef rk_methods[] = {
    {"drift", (PyCFunction)(void (*)(void))rk_py_drift, METH_FASTCALL, "(Q, V, frame, ref) -> [a; w_dot]"},
    {"centroidal", (PyCFunction)(void (*)(void))rk_py_centroidal, METH_FASTCALL, "(Q) -> A_g"},
    {"wrench", (PyCFunction)(void (*)(void))rk_py_wrench, METH_FASTCALL, "(Q, frame, W, OUT, sign): OUT += sign J^T w"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef rk_module = {PyModuleDef_HEAD_INIT, RK_STR(LG_MODULE), NULL, -1, rk_methods};

PyMODINIT_FUNC RK_PASTE(PyInit_, LG_MODULE)(void)
{
    import_array();
    return PyModule_Create(&rk_module);
}
