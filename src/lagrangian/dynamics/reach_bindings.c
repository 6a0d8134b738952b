/* Python bindings of reach_kernel.c and reach_coriolis.c: arrays (..., n) of float64, one
 * output row per state. */

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

/* a floating base's quaternions (entries 3..6 of each state) of norm within the tolerance (or
 * not finite: that row's NaN is the caller's); else ValueError, and numpy names the state */
static int rk_unit_quaternions(PyArrayObject *Q)
{
#if RK_FB
    npy_intp count = PyArray_SIZE(Q) / RK_NQ;
    const double *q = PyArray_DATA(Q);
    for (npy_intp k = 0; k < count; k++, q += RK_NQ) {
        double n2 = q[3] * q[3] + q[4] * q[4] + q[5] * q[5] + q[6] * q[6];
        if (n2 < RK_QLOW || n2 > RK_QHIGH) {
            PyErr_SetString(PyExc_ValueError, "q: the base quaternion is not of unit norm");
            return 0;
        }
    }
#else
    (void)Q;
#endif
    return 1;
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
    PyArrayObject *Q = rk_input(args[0], RK_NQ, "q");
    if (!Q) return NULL;
    if (!rk_unit_quaternions(Q)) { Py_DECREF(Q); return NULL; }
    PyArrayObject *V = rk_input(args[1], RK_NV, "v");
    if (!V || !rk_same_batch(Q, V, "v")) { Py_DECREF(Q); Py_XDECREF(V); return NULL; }
    PyObject *out = rk_output(Q, 6, 0);
    if (out) {
        npy_intp count = PyArray_SIZE(Q) / RK_NQ;
        const double *q = PyArray_DATA(Q), *v = PyArray_DATA(V);
        double *y = PyArray_DATA((PyArrayObject *)out);
        for (npy_intp k = 0; k < count; k++)
            rk_drift(q + k * RK_NQ, v + k * RK_NV, f, ref, y + 6 * k);
    }
    Py_DECREF(Q); Py_DECREF(V);
    return out;
}

static PyObject *rk_py_centroidal(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 1) { PyErr_SetString(PyExc_TypeError, "centroidal(Q)"); return NULL; }
    PyArrayObject *Q = rk_input(args[0], RK_NQ, "q");
    if (!Q) return NULL;
    if (!rk_unit_quaternions(Q)) { Py_DECREF(Q); return NULL; }
    PyObject *out = rk_output(Q, 6, RK_NV);
    if (out) {
        npy_intp count = PyArray_SIZE(Q) / RK_NQ;
        const double *q = PyArray_DATA(Q);
        double *y = PyArray_DATA((PyArrayObject *)out);
        for (npy_intp k = 0; k < count; k++) rk_centroidal(q + k * RK_NQ, y + 6 * RK_NV * k);
    }
    Py_DECREF(Q);
    return out;
}

/* wrench(Q, frame, W, OUT, sign): OUT += sign J^T w, in place (OUT float64, contiguous, of
 * Q's batch and RK_NV wide); W (6,) for every state or one row per state */
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
    PyArrayObject *Q = rk_input(args[0], RK_NQ, "q");
    if (!Q) return NULL;
    if (!rk_unit_quaternions(Q)) { Py_DECREF(Q); return NULL; }
    PyArrayObject *W = rk_input(args[2], 6, "f_ext");
    if (!W) { Py_DECREF(Q); return NULL; }
    int shared = PyArray_NDIM(W) == 1;
    if ((!shared && !rk_same_batch(Q, W, "f_ext"))
            || PyArray_TYPE(out) != NPY_DOUBLE || !PyArray_ISCARRAY(out)
            || PyArray_NDIM(out) != PyArray_NDIM(Q)
            || !PyArray_CompareLists(PyArray_DIMS(out), PyArray_DIMS(Q), PyArray_NDIM(Q) - 1)
            || PyArray_DIMS(out)[PyArray_NDIM(Q) - 1] != RK_NV) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "out: not of q's batch, nv wide");
        Py_DECREF(Q); Py_DECREF(W);
        return NULL;
    }
    npy_intp count = PyArray_SIZE(Q) / RK_NQ;
    const double *q = PyArray_DATA(Q), *w = PyArray_DATA(W);
    double *y = PyArray_DATA(out), tau[RK_NV];
    for (npy_intp k = 0; k < count; k++) {
        rk_wrench(q + k * RK_NQ, f, w + (shared ? 0 : 6 * k), tau);
        for (int j = 0; j < RK_NV; j++) y[RK_NV * k + j] += sign * tau[j];
    }
    Py_DECREF(Q); Py_DECREF(W);
    Py_RETURN_NONE;
}

static PyObject *rk_py_coriolis(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 2) { PyErr_SetString(PyExc_TypeError, "coriolis(Q, V)"); return NULL; }
    PyArrayObject *Q = rk_input(args[0], RK_NQ, "q");
    if (!Q) return NULL;
    if (!rk_unit_quaternions(Q)) { Py_DECREF(Q); return NULL; }
    PyArrayObject *V = rk_input(args[1], RK_NV, "v");
    if (!V || !rk_same_batch(Q, V, "v")) { Py_DECREF(Q); Py_XDECREF(V); return NULL; }
    rk_cbody *work = PyMem_Malloc(sizeof(rk_cbody) * RK_NB);
    PyObject *out = work ? rk_output(Q, RK_NV, RK_NV) : PyErr_NoMemory();
    if (out) {
        npy_intp count = PyArray_SIZE(Q) / RK_NQ;
        const double *q = PyArray_DATA(Q), *v = PyArray_DATA(V);
        double *y = PyArray_DATA((PyArrayObject *)out);
        for (npy_intp k = 0; k < count; k++)
            rk_coriolis(q + k * RK_NQ, v + k * RK_NV, y + RK_NV * RK_NV * k, work);
    }
    PyMem_Free(work);
    Py_DECREF(Q); Py_DECREF(V);
    return out;
}

static PyMethodDef rk_methods[] = {
    {"drift", (PyCFunction)(void (*)(void))rk_py_drift, METH_FASTCALL, "(Q, V, frame, ref) -> [a; w_dot]"},
    {"centroidal", (PyCFunction)(void (*)(void))rk_py_centroidal, METH_FASTCALL, "(Q) -> A_g"},
    {"wrench", (PyCFunction)(void (*)(void))rk_py_wrench, METH_FASTCALL, "(Q, frame, W, OUT, sign): OUT += sign J^T w"},
    {"coriolis", (PyCFunction)(void (*)(void))rk_py_coriolis, METH_FASTCALL, "(Q, V) -> C(q, v)"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef rk_module = {PyModuleDef_HEAD_INIT, RK_STR(LG_MODULE), NULL, -1, rk_methods};

PyMODINIT_FUNC RK_PASTE(PyInit_, LG_MODULE)(void)
{
    import_array();
    return PyModule_Create(&rk_module);
}
