/* ---- lagrangian numerics template, part 3 (after template_ensemble.c): the Python
   bindings and the module ---- */

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
